/*
 * dented.sl: dents from octaves of |noise|: each octave doubles the
 * frequency and halves the weight of |2 noise - 1| (a "turbulence" sum);
 * the surface is pushed in along the normal by Km times the sum.
 *
 * Noise is evaluated in "shader" space, so the dents stay on the object
 * when it moves. Meant for unit-size objects, Km around 0.1.
 */
displacement dented(
    float Km = 0.1;
    float frequency = 2;     /* of the first octave, per unit of shader space */
    float octaves = 4)
{
    point Pshad = transform("shader", P) * frequency;
    float sum = 0, weight = 1, i;
    for (i = 0; i < octaves; i += 1) {
        sum += weight * abs(2 * noise(Pshad) - 1);
        Pshad *= 2;
        weight *= 0.5;
    }
    P -= Km * sum * normalize(N);
    N = calculatenormal(P);
}

/*
 * rockdents.sl: dented.sl's dents (octaves of |noise|, each doubling the
 * frequency and halving the weight) taken in "object" space, so that
 * the dents of a recorded rock travel with every ObjectInstance of it
 * under one Displacement call (bench/asset_gen --rock-kinds: each
 * placement is then its rock moved, docs/renderer.md "Instances as
 * references"). Km is in camera-space units: meant for rocks about 0.1
 * across, Km around 0.02.
 */
displacement rockdents(
    float Km = 0.02;
    float frequency = 2;     /* of the first octave, per unit of object space */
    float octaves = 4)
{
    point Pobj = transform("object", P) * frequency;
    float sum = 0, weight = 1, i;
    for (i = 0; i < octaves; i += 1) {
        sum += weight * abs(2 * noise(Pobj) - 1);
        Pobj *= 2;
        weight *= 0.5;
    }
    P -= Km * sum * normalize(N);
    N = calculatenormal(P);
}

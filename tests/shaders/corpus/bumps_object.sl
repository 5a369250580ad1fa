/*
 * bumps_object.sl: bumps from noise of the object-space point, so they
 * stay on the object under any transform.
 * Idiom: bumps in object space.
 */
displacement bumps_object(float Km = 0.03, frequency = 5)
{
    point Pobj = transform("object", P);
    float h = noise(Pobj * frequency) - 0.5;
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

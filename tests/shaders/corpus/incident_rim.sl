/*
 * incident_rim.sl: ripples whose height depends on the angle between the
 * incident direction I and the normal (stronger at grazing angles).
 * Idiom: the global I in a displacement.
 */
displacement incident_rim(float Km = 0.02, frequency = 8)
{
    normal Nn = normalize(N);
    vector In = normalize(I);
    float facing = abs(In . Nn);
    float h = (0.5 + 0.5 * (1 - facing)) * sin(2 * PI * frequency * t);
    P += Km * h * Nn;
    N = calculatenormal(P);
}

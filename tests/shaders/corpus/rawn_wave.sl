/*
 * rawn_wave.sl: a radial wave in (s,t) moved along the raw N, not
 * normalised (the RI spec does not promise a unit N: under a non-uniform
 * scale the displacement is stretched with it).
 * Idiom: `P += Km * h * N` without normalize (issue 9, finding 1).
 */
displacement rawn_wave(float Km = 0.03, frequency = 12)
{
    float r = distance(point(s, t, 0), point(0.5, 0.5, 0));
    float h = sin(2 * PI * frequency * r) * exp(-2 * r);
    P += Km * h * N;
    N = calculatenormal(P);
}

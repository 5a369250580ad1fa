/*
 * early_return.sl: a shader that returns early when its amplitude is 0 or
 * outside a band of t, otherwise adds a bump in s.
 * Idiom: return from the shader body under a condition.
 */
displacement early_return(float Km = 0.03, tmin = 0.2, tmax = 0.8)
{
    if (Km == 0)
        return;
    normal Nn = normalize(N);
    if (t < tmin || t > tmax)
        return;
    float h = sin(PI * (t - tmin) / (tmax - tmin)) * (0.5 + 0.5 * cos(2 * PI * 3 * s));
    P += Km * h * Nn;
    N = calculatenormal(P);
}

/*
 * wave_sum.sl: ocean-like waves: a fixed number of sines in different
 * directions of (s,t), the direction turned each iteration.
 * Idiom: for loop with a uniform count, cos/sin directions.
 */
displacement wave_sum(float Km = 0.02, nwaves = 5, frequency = 8)
{
    float h = 0, i;
    for (i = 0; i < nwaves; i += 1) {
        float a = i * 2.39996;
        float k = frequency * (1 + 0.3 * i);
        h += sin(2 * PI * k * (cos(a) * s + sin(a) * t) + i) / (1 + i);
    }
    P += Km * 0.5 * h * normalize(N);
    N = calculatenormal(P);
}

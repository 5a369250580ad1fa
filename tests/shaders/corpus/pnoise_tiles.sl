/*
 * pnoise_tiles.sl: periodic noise bumps that tile seamlessly in (s,t)
 * (pnoise with a period), e.g. around a cylinder's seam.
 * Idiom: pnoise(float, float, period, period).
 */
displacement pnoise_tiles(float Km = 0.03, frequency = 6)
{
    float h = pnoise(s * frequency, t * frequency, frequency, frequency) - 0.5;
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

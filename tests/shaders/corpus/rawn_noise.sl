/*
 * rawn_noise.sl: noise bumps along the raw N, with N recomputed from the
 * displaced P.
 * Idiom: raw N (no normalize) with noise.
 */
displacement rawn_noise(float Km = 0.03, frequency = 4)
{
    point Psh = transform("shader", P) * frequency;
    P += Km * (noise(Psh) - 0.5) * N;
    N = calculatenormal(P);
}

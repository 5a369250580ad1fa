/*
 * orange_peel.sl: fine pits: a high-frequency noise raised to a power,
 * with a small amplitude.
 * Idiom: small-scale noise, pow, in shader space.
 */
displacement orange_peel(float Km = 0.005, frequency = 30, sharp = 4)
{
    float n = noise(transform("shader", P) * frequency);
    float pit = pow(clamp(1 - n, 0, 1), sharp);
    P -= Km * pit * normalize(N);
    N = calculatenormal(P);
}

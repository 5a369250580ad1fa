/*
 * calcnormal_after.sl: the textbook form: displace along normalize(N),
 * then N = calculatenormal(P), here of a noise of (s,t).
 * Idiom: calculatenormal after moving P.
 */
displacement calcnormal_after(float Km = 0.03, frequency = 6)
{
    float h = noise(s * frequency, t * frequency) - 0.5;
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

/*
 * while_octaves.sl: fBm written with a while loop that stops when the
 * amplitude falls below a threshold (octave count from the amplitude).
 * Idiom: while loop.
 */
displacement while_octaves(float Km = 0.03, frequency = 3, gain = 0.5, minamp = 0.05)
{
    point pp = transform("shader", P) * frequency;
    float sum = 0, amp = 1;
    while (amp > minamp) {
        sum += amp * (2 * noise(pp) - 1);
        amp *= gain;
        pp *= 2;
    }
    P += Km * sum * normalize(N);
    N = calculatenormal(P);
}

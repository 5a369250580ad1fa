/*
 * spikes_pow.sl: sharp spikes: a high power of |sin| in s and t.
 * Idiom: pow(abs(sin(...)), n) (steep but continuous).
 */
displacement spikes_pow(float Km = 0.03, frequency = 5, sharpness = 16)
{
    float a = abs(sin(PI * frequency * s)), b = abs(sin(PI * frequency * t));
    float h = pow(a * b, sharpness);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

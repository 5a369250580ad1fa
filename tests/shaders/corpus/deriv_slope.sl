/*
 * deriv_slope.sl: erosion-like: the height of a noise is reduced where it
 * changes fast along s: Deriv(h, s) and Du/Dv in the shader body.
 * Idiom: Deriv, Du, Dv of a float.
 */
displacement deriv_slope(float Km = 0.03, frequency = 4)
{
    float h = noise(s * frequency, t * frequency) - 0.5;
    float slope = abs(Deriv(h, s)) + abs(Du(h)) + abs(Dv(h));
    h *= 1 / (1 + 0.1 * slope);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

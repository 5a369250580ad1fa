/* a displacement shader with noise, a loop and a function */
#define OCTAVES 4
float fbm(point p; float oct) {
    float sum = 0, amp = 1, i;
    point q = p;
    for (i = 0; i < oct; i += 1) {
        sum += amp * (noise(q) - 0.5);
        amp *= 0.5;
        q *= 2;
    }
    return sum;
}
displacement bumps(float Km = 0.1; float freq = 4) {
    float h = Km * fbm(P * freq, OCTAVES);
    if (h > 0)
        P += h * normalize(N);
    else
        P -= 0.5 * h * N;
    N = calculatenormal(P);
}

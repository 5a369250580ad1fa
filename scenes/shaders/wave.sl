/*
 * wave.sl: a radial wave with exponential decay, the shader of Heidrich &
 * Seidel 1998, Figure 1: ripples around a centre in (s, t), their height
 * decaying with the distance r from it:
 *
 *     h(r) = Km * exp(-decay * r) * sin(2 PI frequency r + phase)
 *
 * P moves along the unit normal by h; the normal is recomputed from the
 * displaced surface. Meant for the unit square [-1,1]^2 (s, t in [0, 1]).
 */
displacement wave(
    float Km = 0.1;            /* amplitude at the centre */
    float frequency = 4;       /* ripples per unit of (s, t) */
    float decay = 2;           /* exponential falloff with r */
    float phase = 0;
    float scenter = 0.5, tcenter = 0.5)
{
    float ds = s - scenter;
    float dt = t - tcenter;
    float r = sqrt(ds * ds + dt * dt);
    float h = Km * exp(-decay * r) * sin(2 * PI * frequency * r + phase);
    P += h * normalize(N);
    N = calculatenormal(P);
}

/* noise family: pnoise repeats with its period, in each form */
displacement noise_periodic()
{
    float a = pnoise(s * 3, 4) - pnoise(s * 3 + 4, 4);
    float b = pnoise(point (s, t, 0) * 2, point (2, 3, 5)) +
              pnoise(point (s, t, 0) * 2 + point (2, 3, 5), point (2, 3, 5));
    point c = pnoise(s * 2, t * 2, 3, 3);
    P = point(a, b, zcomp(c) - zcomp(point pnoise(s * 2 + 3, t * 2 - 3, 3, 3)));
}

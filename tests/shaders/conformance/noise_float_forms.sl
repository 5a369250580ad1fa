/* noise family, float results: noise, pnoise and cellnoise of a float, two
 * floats, a point and a point and a float (4D) */
displacement noise_float_forms()
{
    point q = point (s, t, 0) * 3;
    float a = noise(s * 5) + noise(s * 3, t * 3) + noise(q) + noise(q, t * 2);
    float b = pnoise(s * 5, 4) + pnoise(s * 3, t * 3, 2, 3) + pnoise(q, point (4, 4, 4)) +
              pnoise(q, t * 2, point (2, 2, 2), 3);
    float c = cellnoise(s * 4) + cellnoise(s * 4, t * 4) + cellnoise(q) + cellnoise(q, t * 4);
    P = point(a, b, c);
}

/* spline: a marble-style lookup of a noise value, the knots shifted by a
 * parameter (knots are expressions, evaluated per shading point) */
displacement spline_noise_marble(float veining = 0.6)
{
    float n = noise(point (s, t, 0) * 3);
    float h = spline(n, 0, 0.1, veining, 0.3 * veining, 1, 0.8);
    P = point(h, n, spline("bezier", n, 0, 1, -1, 0));
}

/* rotate(Q, angle, P0, P1): a point turned about the line through P0 and
 * P1, the same turn as the matrix rotate about P1 - P0 */
displacement geom_rotate_point()
{
    point Q = point(s, t, 0), P0 = point(0.1, 0.2, 0.3), P1 = point(0.5, 1, 2);
    float a = PI / 3 * s;
    point r = rotate(Q, a, P0, P1);
    point m = transform(rotate(matrix 1, a, P1 - P0), Q - P0) + P0;
    P = r + 0.001 * (r - m) * 1000;
}

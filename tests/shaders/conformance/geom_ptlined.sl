/* ptlined: the distance from a point to a segment (inside it, beyond each
 * end, and a segment of length 0) */
displacement geom_ptlined()
{
    point Q = point(s, t, 0);
    P = point(ptlined(point(0.3, 0.2, 0), point(0.6, 0.9, 0), Q),
              ptlined(point(0.2, 0.2, 0), point(0.2, 0.2, 0), Q),
              ptlined(point(0, 0, 0), point(1, 1, 1), Q + vector(0, 0, 1)));
}

/* spline: a bezier path of points (two segments sharing a knot) */
displacement spline_bezier_point()
{
    point path = spline("bezier", s,
                        point (0, 0, 0), point (1, 2, 0), point (2, -1, 1), point (3, 0, 1),
                        point (4, 1, 1), (5, 0, 2), point (6, 3, 0));
    P = path + vector (0, 0, t);
}

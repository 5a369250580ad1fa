/* spline of vectors (catmull-rom, one segment) and of normals (linear, two
 * segments: the inner knots joined) */
displacement spline_vector_normal()
{
    vector v = spline(s, vector(0, 0, 0), vector(1, 0, 0), vector(1, 1, 0), vector(0, 1, 1));
    normal n = spline("linear", t, normal(0), normal(1, 0, 0), normal(0, 1, 0),
                      normal(0, 0, 1), normal(1));
    P = point(xcomp(v) + xcomp(n), ycomp(v) + ycomp(n), zcomp(v) + zcomp(n));
}

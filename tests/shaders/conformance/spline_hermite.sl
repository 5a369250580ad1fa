/* spline: hermite knots are value, tangent, value, tangent, ... */
displacement spline_hermite()
{
    float a = spline("hermite", s, 0, 2, 1, 0);
    vector b = spline("hermite", t, vector (0, 0, 0), vector (1, 0, 0),
                      vector (0, 1, 0), vector (0, 0, 1), vector (1, 1, 0), vector (-1, 0, 0));
    P = point(a, ycomp(b) + xcomp(b), zcomp(b));
}

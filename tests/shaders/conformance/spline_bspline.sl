/* spline: the b-spline basis, which smooths rather than interpolates */
displacement spline_bspline()
{
    float bumps = spline("b-spline", s, 0, 1, 0, 1, 0, 1, 0);
    float ramp = spline("b-spline", t * t, 0, 0, 0, 1, 1, 1);
    P = point(bumps, ramp, bumps * ramp);
}

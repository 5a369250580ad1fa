/* spline: "linear" joins the inner knots by segments, "constant" steps
 * through them (the first and last knots are not reached) */
displacement spline_linear_constant()
{
    float lin = spline("linear", s, 9, 0, 1, 0.5, 2, 9);
    float step = spline("constant", t, 9, 0, 1, 0.5, 2, 9);
    color c = spline("linear", t, color 9, color (0, 0.5, 1), color (1, 0, 0.5), color 9);
    P = point(lin, step, comp(c, 2));
}

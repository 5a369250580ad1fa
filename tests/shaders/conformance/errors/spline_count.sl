/* a bezier spline needs 4, 7, 10, ... knots */
displacement spline_count()
{
    P += spline("bezier", s, 0, 1, 2, 3, 4) * N;
}

/* an unknown spline basis */
displacement spline_basis()
{
    P += spline("cardinal", s, 0, 1, 2, 3) * N;
}

/* spline: the default basis (catmull-rom) over a value list, the first and
 * last knots only shaping the ends; and the basis named explicitly */
displacement spline_float(float Km = 0.5)
{
    float h = spline(s, 0, 0, 0.3, 0.8, 1, 1);
    float w = spline("catmull-rom", t, -1, 0, 1, 0.5, 2, 0.25, 3);
    P = point(h, w, Km * spline(0.5, 0, 1, 2, 3));
}

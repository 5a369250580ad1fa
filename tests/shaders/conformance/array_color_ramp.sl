/* arrays: a piecewise-linear ramp through knots, the classic lookup
 * before spline() */
displacement array_color_ramp()
{
    float knots[5] = {0, 0.2, 0.9, 0.4, 1};
    float x = s * 4;
    float i = floor(x);
    float f = x - i;
    P = point(mix(knots[i], knots[min(i + 1, 4)], f), knots[t * 5], 0);
}

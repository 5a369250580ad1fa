/* spline: knots passed through a helper's unsized array parameter, with
 * the basis as a string constant passed on by a macro */
#define RAMP_BASIS "catmull-rom"

float ramp(float x; float knots[]) { return spline(RAMP_BASIS, clamp(x, 0, 1), knots); }

displacement spline_unsized_param()
{
    float a[4] = {0, 1, 2, 3}, b[] = {1, 0, 0.5, 0.25, 1, 0};
    P = point(ramp(s, a), ramp(t, b), ramp(s * t, b));
}

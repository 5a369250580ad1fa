/* spline: the array forms, a float array and a colour array shader
 * parameter with its default, as a RIB would set it */
displacement spline_array(float heights[6] = {0, 0.2, 0.1, 0.7, 1, 1.2};
                          color ramp[4] = {(0, 0, 0), (0.2, 0.4, 0.6), (1, 0.8, 0.6), (1, 1, 1)})
{
    color c = spline("b-spline", t, ramp);
    P = point(spline(s, heights), spline("linear", t, heights), comp(c, 1));
}

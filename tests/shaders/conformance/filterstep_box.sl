/* filterstep: the antialiased step of the books, over the point's filter
 * width (a step where the width is 0) and over an explicit interval, with
 * the "width" and "filter" parameters */
displacement filterstep_box()
{
    float a = filterstep(0.5, s);
    float b = filterstep(0.5, s - 0.05, s + 0.05);
    float c = filterstep(0.3, t, t + 0.1, "width", 2, "filter", "box");
    P = point(a + b, c, filterstep(0.6, t + 0.1, t, "filter", "gaussian"));
}

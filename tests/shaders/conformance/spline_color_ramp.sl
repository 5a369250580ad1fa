/* spline: the marble/wood colour ramp of The RenderMan Companion, a
 * colour spline driven by a pattern value, read back as a point */
displacement spline_color_ramp(color darkwood = color (0.3, 0.12, 0.03);
                               color lightwood = color (0.69, 0.44, 0.25))
{
    float ring = mod(s * 3 + 0.5 * t, 1);
    color Ct = spline(ring, darkwood, darkwood, lightwood, color (0.8, 0.5, 0.3),
                      lightwood, darkwood, darkwood);
    P = point(comp(Ct, 0), comp(Ct, 1), comp(Ct, 2));
}

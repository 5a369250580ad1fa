/* color spaces: "hsl", lightness over t, the hue wrapping past 1 */
displacement color_hsl()
{
    color c = color "hsl" (t + 0.5, 0.6, 0.2 + 0.6 * s);
    P = point(comp(c, 0), comp(c, 1), comp(c, 2));
}

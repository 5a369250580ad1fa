/* color spaces: the hue-shift idiom, ctransform to "hsv", change the hue,
 * back to "rgb" (the sector of the largest channel changes at s = 0.5) */
displacement color_hue_shift(float shift = 0.1)
{
    color hsv = ctransform("hsv", color (s, 1 - s, 0.1));
    color back = ctransform("hsv", "rgb", hsv + color (shift, 0, 0));
    color blue = ctransform("rgb", "hsv", color (0.5 * s, 0.25 * t, 1.2));
    P = point(comp(hsv, 0), comp(back, 1) + comp(back, 2), comp(blue, 0) + comp(blue, 1));
}

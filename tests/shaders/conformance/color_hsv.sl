/* color spaces: a hue ramp built in "hsv", as shaders pick colours */
displacement color_hsv(float sat = 0.8)
{
    color c = color "hsv" (s, sat, 0.5 + 0.5 * t);
    P = point(comp(c, 0), comp(c, 1), comp(c, 2));
}

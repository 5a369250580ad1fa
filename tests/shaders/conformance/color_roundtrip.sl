/* color spaces: each conversion and its inverse give the color back */
displacement color_roundtrip()
{
    color c = color (0.2 + 0.6 * s, 0.7 - 0.5 * t, 0.3 + 0.2 * s * t);
    color a = ctransform("hsl", "rgb", ctransform("hsl", c));
    color b = ctransform("hsv", "rgb", ctransform("rgb", "hsv", c));
    color d = ctransform("YIQ", "rgb", ctransform("YIQ", c));
    color e = ctransform("xyY", "XYZ", ctransform("xyY", c));
    P = point(comp(a, 0) + comp(b, 1), comp(d, 2) + comp(a, 1), comp(e, 1) + comp(b, 2));
}

/* color spaces: the linear ones ("XYZ", "xyz", "YIQ") and "xyY", each way */
displacement color_xyz_yiq()
{
    color c = color (s, t, 0.5);
    color xyz = ctransform("XYZ", c);
    color yiq = ctransform("YIQ", c);
    color xyY = ctransform("xyY", c);
    color back = color "xyY" (comp(xyY, 0), comp(xyY, 1), comp(xyY, 2));
    color lum = ctransform("YIQ", "xyz", color (0.5, 0.1 * s, -0.1 * t));
    P = point(comp(xyz, 0) + comp(yiq, 1), comp(xyY, 0) + comp(back, 1),
              comp(lum, 2) + comp(color "xyz" (s, t, 1), 0));
}

/* stripes with mod and a smoothstep-antialiased edge, and mix between two
 * colours, as the books' first patterns do */
displacement pattern_stripes(float frequency = 5; color c0 = color(0.1, 0.2, 0.3);
                             color c1 = color(0.9, 0.7, 0.5))
{
    float ss = mod(s * frequency, 1);
    float edge = smoothstep(0.4, 0.6, ss);
    color c = mix(c0, c1, edge);
    P = point(comp(c, 0), comp(c, 1) + ss, comp(c, 2) * t);
}

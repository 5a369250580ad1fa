/* overloading: two overloads defined in the shader body */
displacement overload_nested_local()
{
    float lum(color c) { return 0.3 * comp(c, 0) + 0.59 * comp(c, 1) + 0.11 * comp(c, 2); }
    float lum(float x) { return x; }
    P = point(lum(color(s, t, 1)), lum(t), 0);
}

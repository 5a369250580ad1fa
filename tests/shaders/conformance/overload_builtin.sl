/* overloading beside built-ins: length() of a colour is added, smoothstep()
 * is replaced (same signature) */
float length(color c) { return comp(c, 0) + comp(c, 1) + comp(c, 2); }
float smoothstep(float a, b, x) { return clamp((x - a) / (b - a), 0, 1); }

displacement overload_builtin()
{
    P = point(length(color(s, t, 1)), length(vector(s, t, 0)), smoothstep(0.2, 0.8, s));
}

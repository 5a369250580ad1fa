/* nested functions: a nested noise(float) hides the built-in for floats
 * only; noise of a point is still the built-in */
displacement nested_shadows_builtin()
{
    float noise(float x) { return x * 2; }
    P = point(noise(s), noise(point(s, t, 0)), 0);
}

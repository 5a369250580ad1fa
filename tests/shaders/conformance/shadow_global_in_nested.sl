/* scopes: the body's t hides the global; a nested function has its own
 * s and t and sees the global u */
displacement shadow_global_in_nested()
{
    float t = 2;
    float f(float s) { float t = s * 3; return t + u; }
    P = point(f(t), t, v);
}

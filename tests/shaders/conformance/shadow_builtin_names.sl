/* scopes: variables named like built-in functions, which stay callable */
displacement shadow_builtin_names()
{
    float mix = 0.25, step = s, noise = 2;
    float area = mix(step, noise, mix);
    P = point(area, step(0.5, t), noise);
}

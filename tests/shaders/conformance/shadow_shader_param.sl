/* scopes: shader parameters named like a predefined variable and like PI */
displacement shadow_shader_param(float s = 2; float PI = 3)
{
    P = point(s * t, PI, u);
}

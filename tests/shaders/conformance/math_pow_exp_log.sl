/* pow, exp, log in both forms, sqrt: falloffs and gamma curves */
displacement math_pow_exp_log(float gam = 2.2)
{
    float a = pow(s + 0.1, 1 / gam);
    float falloff = exp(-2 * t) + log(1 + s);
    P = point(a, falloff, log(t + 2, 2) + sqrt(s + t));
}

/* scopes: an output parameter named P and a parameter named N; the
 * globals are untouched by the function */
void perturb(output point P; normal N; float amt)
{
    P += amt * normalize(N);
}

displacement shadow_output_param(float Km = 0.2)
{
    point p = P;
    perturb(p, N, Km * s);
    P = p + point(0, 0, t);
}

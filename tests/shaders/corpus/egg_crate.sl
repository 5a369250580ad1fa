/*
 * egg_crate.sl: the twelve-line shader of issue 9, finding 3: the product
 * of two sines of mod(s*4, 1) and mod(t*4, 1) along NN computed first, the
 * new normal from PP, and P assigned inside an `if` on a uniform
 * parameter.
 * Idiom: sin of mod (continuous across the mod seams), calculatenormal of
 * a local point, if on a uniform parameter.
 */
displacement egg_crate(float Km = 0.02; float truedisp = 1)
{
    normal NN = normalize(N);
    float h = sin(2 * PI * mod(s * 4, 1)) * sin(2 * PI * mod(t * 4, 1));
    point PP = P + Km * h * NN;
    N = calculatenormal(PP);
    if (truedisp != 0)
        P = PP;
}

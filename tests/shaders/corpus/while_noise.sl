/*
 * while_noise.sl: a while loop whose trip count depends on noise: terraces
 * counted by subtracting a step until the remainder is below it.
 * Idiom: while loop with a noise-dependent condition.
 */
displacement while_noise(float Km = 0.03, frequency = 3, stepsize = 0.2)
{
    float n = noise(transform("shader", P) * frequency);
    float level = 0, rest = n;
    while (rest > stepsize) {
        rest -= stepsize;
        level += 1;
    }
    float h = (level + smoothstep(0.7 * stepsize, stepsize, rest)) * stepsize;
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

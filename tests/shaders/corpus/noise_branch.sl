/*
 * noise_branch.sl: islands: where the noise exceeds a threshold the
 * surface is raised by a smooth plateau, elsewhere it gets small ripples.
 * Idiom: if/else on a noise value.
 */
displacement noise_branch(float Km = 0.03, frequency = 3, threshold = 0.55)
{
    point Psh = transform("shader", P) * frequency;
    float n = noise(Psh);
    float h;
    if (n > threshold)
        h = smoothstep(threshold, threshold + 0.1, n);
    else
        h = 0.1 * sin(20 * n);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

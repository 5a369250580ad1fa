/*
 * bumps_world.sl: bumps from noise of the world-space point (they swim if
 * the object moves, as in RenderMan), plus a vector-noise jitter.
 * Idiom: bumps in world space, vector noise.
 */
displacement bumps_world(float Km = 0.03, frequency = 4)
{
    point Pw = transform("world", P) * frequency;
    vector j = vector noise(Pw + point(3.1, 0, 0)) - 0.5;
    float h = noise(Pw + 0.3 * j) - 0.5;
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

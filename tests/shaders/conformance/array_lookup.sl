/* arrays: a shader parameter table of heights indexed by a varying float
 * (rounded down) */
displacement array_lookup(float heights[5] = {0, 0.1, 0.3, 0.2, 0.05})
{
    P += heights[t * 5] * normalize(N);
}

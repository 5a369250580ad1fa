/*
 * tiles_pillow.sl: square tiles, each a pillow (product of smoothsteps
 * from the tile's edges), grooves between tiles.
 * Idiom: tiles with mod, smoothstep pillows (continuous at the seams).
 */
displacement tiles_pillow(float Km = 0.02, frequency = 6, groove = 0.08)
{
    float ss = mod(s * frequency, 1), tt = mod(t * frequency, 1);
    float ps = smoothstep(0, groove, ss) * (1 - smoothstep(1 - groove, 1, ss));
    float pt = smoothstep(0, groove, tt) * (1 - smoothstep(1 - groove, 1, tt));
    P += Km * ps * pt * normalize(N);
    N = calculatenormal(P);
}

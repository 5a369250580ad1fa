/* the brick pattern of The RenderMan Companion: every other row shifted
 * by half a brick with mod(), brick and mortar from step() */
displacement pattern_bricks(float brickwidth = 0.25, brickheight = 0.125,
                            mortar = 0.02)
{
    float bw = brickwidth + mortar, bh = brickheight + mortar;
    float ss = s / bw, tt = t / bh;
    if (mod(tt * 0.5, 1) > 0.5)
        ss += 0.5;                       /* shift alternate rows */
    float sbrick = floor(ss), tbrick = floor(tt);
    ss -= sbrick;
    tt -= tbrick;
    float w = step(mortar / bw, ss) * step(mortar / bh, tt);
    P = point(ss, tt, w + 10 * sbrick + 100 * tbrick);
}

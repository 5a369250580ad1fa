/*
 * scales.sl: overlapping reptile scales: a loop over the neighbouring
 * cells in (s,t), each contributing a dome; the maximum wins.
 * Idiom: cell loop over neighbours with max, floor.
 */
displacement scales(float Km = 0.02, frequency = 8, size = 0.7)
{
    float ss = s * frequency, tt = t * frequency;
    float cs = floor(ss), ct = floor(tt);
    float h = 0, i, j;
    for (j = -1; j <= 0; j += 1) {
        for (i = -1; i <= 1; i += 1) {
            float ox = cs + i + 0.5 + 0.5 * mod(ct + j, 2), oy = ct + j + 0.5;
            float d = sqrt((ss - ox) * (ss - ox) + (tt - oy) * (tt - oy)) / size;
            float dome = max(0, 1 - d * d);
            h = max(h, dome);
        }
    }
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

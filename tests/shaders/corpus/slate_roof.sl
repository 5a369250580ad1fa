/*
 * slate_roof.sl: overlapping slates: rows in t each thickening towards
 * its lower edge, slates in a row split with mod on s, a random tilt and
 * offset per slate from cellnoise.
 * Idiom: shingles with floor/mod, cellnoise per cell, step edges.
 */
displacement slate_roof(float Km = 0.015, rows = 10, perrow = 8, gap = 0.04)
{
    float tt = t * rows;
    float row = floor(tt);
    float ss = s * perrow + 0.5 * mod(row, 2);
    float col = floor(ss);
    float fs = ss - col, ft = tt - row;
    float rnd = float cellnoise(point(col, row, 0));
    float thick = ft * (0.8 + 0.4 * rnd);
    float slot = step(gap, fs) * step(fs, 1 - gap);
    P += Km * thick * (0.3 + 0.7 * slot) * normalize(N);
    N = calculatenormal(P);
}

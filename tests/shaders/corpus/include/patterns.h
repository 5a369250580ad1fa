/*
 * patterns.h: cell patterns of the corpus shaders (issue 9): Voronoi
 * distances from jittered cellnoise feature points (loops over the
 * neighbouring cells), and the brick / tile coordinates made with floor
 * and mod, written for aafarm in the style of the public shader headers.
 */
#ifndef CORPUS_PATTERNS_H
#define CORPUS_PATTERNS_H

/* 2D Voronoi in (ss, tt): distance to the nearest (f1) and second nearest
 * (f2) jittered feature point over the 3x3 neighbouring cells; the nearest
 * point's cell in (c1s, c1t) */
void voronoi_f1f2_2d(float ss; float tt; float jitter;
                     output float f1; output float f2;
                     output float c1s; output float c1t)
{
    float cs = floor(ss) + 0.5, ct = floor(tt) + 0.5;
    float i, j;
    f1 = 1000;
    f2 = 1000;
    for (i = -1; i <= 1; i += 1) {
        for (j = -1; j <= 1; j += 1) {
            point cell = point(cs + i, ct + j, 0);
            point jit = (point cellnoise(cell) - 0.5) * jitter;
            float ps = xcomp(cell) + xcomp(jit), pt = ycomp(cell) + ycomp(jit);
            float d = (ss - ps) * (ss - ps) + (tt - pt) * (tt - pt);
            if (d < f1) {
                f2 = f1;
                f1 = d;
                c1s = xcomp(cell);
                c1t = ycomp(cell);
            } else if (d < f2) {
                f2 = d;
            }
        }
    }
    f1 = sqrt(f1);
    f2 = sqrt(f2);
}

/* brick coordinates: which brick (bs, bt) and where inside it (ss, tt) */
void brickcoords(float s0; float t0; float bwidth; float bheight;
                 output float ss; output float tt; output float bs; output float bt)
{
    tt = t0 / bheight;
    bt = floor(tt);
    ss = s0 / bwidth;
    if (mod(bt * 0.5, 1) >= 0.5)
        ss += 0.5;           /* every other row is shifted half a brick */
    bs = floor(ss);
    ss -= bs;
    tt -= bt;
}

#endif

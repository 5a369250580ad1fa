/*
 * voronoi.h: cellular (Worley) noise in 2D in the style of the widely
 * copied RenderMan helpers (written for aafarm's conformance suite): output
 * parameters, nested loops over the neighbouring cells, feature points
 * jittered by cellnoise.
 */
#ifndef CONF_VORONOI_H
#define CONF_VORONOI_H

void voronoi_f1_2d(float ss, tt; float jitter;
                   output float f1; output float spos, tpos)
{
    float sthiscell = floor(ss) + 0.5, tthiscell = floor(tt) + 0.5;
    float i, j;
    f1 = 1000;
    for (i = -1; i <= 1; i += 1) {
        float stestcell = sthiscell + i;
        for (j = -1; j <= 1; j += 1) {
            float ttestcell = tthiscell + j;
            vector jit = vector cellnoise(stestcell, ttestcell) - 0.5;
            float ps = stestcell + jitter * xcomp(jit);
            float pt = ttestcell + jitter * ycomp(jit);
            float ds = ps - ss, dt = pt - tt;
            float dist = ds * ds + dt * dt;
            if (dist < f1) {
                f1 = dist;
                spos = ps;
                tpos = pt;
            }
        }
    }
    f1 = sqrt(f1);
}

#endif

/*
 * craters.sl: one crater per cell of (s,t), with random centre and size
 * from cellnoise: a rim (smoothpulse) and a bowl (smoothstep) on the
 * distance to the centre.
 * Idiom: cellnoise per cell, smoothpulse, floor.
 */
#include "include/filterwidth.h"

displacement craters(float Km = 0.03, frequency = 4)
{
    float ss = s * frequency, tt = t * frequency;
    float cs = floor(ss), ct = floor(tt);
    point rnd = point cellnoise(point(cs, ct, 1));
    float cx = cs + 0.3 + 0.4 * xcomp(rnd), cy = ct + 0.3 + 0.4 * ycomp(rnd);
    float R = 0.15 + 0.15 * zcomp(rnd);
    float d = sqrt((ss - cx) * (ss - cx) + (tt - cy) * (tt - cy)) / R;
    float h = 0.6 * smoothpulse(0.7, 0.95, 1.0, 1.4, d) - (1 - smoothstep(0, 0.9, d));
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

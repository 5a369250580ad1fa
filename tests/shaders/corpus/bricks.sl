/*
 * bricks.sl: bricks with recessed mortar, rows shifted by half a brick:
 * floor and mod on (s,t), mortar by step (unfiltered), bricks bevelled.
 * Idiom: bricks with mod/floor/step (issue 9, finding 5).
 */
#include "include/patterns.h"

displacement bricks(float Km = 0.01, bwidth = 0.25, bheight = 0.08, mortar = 0.1)
{
    float ss, tt, bs, bt;
    brickcoords(s, t, bwidth, bheight, ss, tt, bs, bt);
    float w = step(mortar * 0.5, ss) - step(1 - mortar * 0.5, ss);
    float h = step(mortar * 0.5, tt) - step(1 - mortar * 0.5, tt);
    P += Km * w * h * normalize(N);
    N = calculatenormal(P);
}

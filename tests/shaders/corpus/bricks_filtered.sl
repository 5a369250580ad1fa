/*
 * bricks_filtered.sl: the same brick layout with mortar edges as filtered
 * pulses (filter width of s and t from filterwidth), bricks slightly
 * rounded with smoothstep, and a per-brick random height from cellnoise.
 * Idiom: bricks + filteredpulse + cellnoise per brick.
 */
#include "include/filterwidth.h"
#include "include/patterns.h"

displacement bricks_filtered(float Km = 0.015, bwidth = 0.25, bheight = 0.08, mortar = 0.1)
{
    float ss, tt, bs, bt;
    brickcoords(s, t, bwidth, bheight, ss, tt, bs, bt);
    float sw = filterwidth(s) / bwidth, tw = filterwidth(t) / bheight;
    float inside = filteredpulse(mortar * 0.5, 1 - mortar * 0.5, ss, sw)
                 * filteredpulse(mortar * 0.5, 1 - mortar * 0.5, tt, tw);
    float jitter = 0.7 + 0.3 * float cellnoise(point(bs, bt, 0));
    P += Km * inside * jitter * normalize(N);
    N = calculatenormal(P);
}

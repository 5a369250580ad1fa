/*
 * cell_stones.sl: cobblestones: Voronoi cells in (s,t) from jittered
 * cellnoise points (a loop over the 3x3 neighbouring cells); each stone is
 * domed by its F2 - F1 distance and lifted by a random height per cell.
 * Idiom: cellnoise stones, cell loops over neighbours, if on distances.
 */
#include "include/patterns.h"

displacement cell_stones(float Km = 0.03, frequency = 6, jitter = 0.8, groove = 0.1)
{
    float f1, f2, cs, ct;
    voronoi_f1f2_2d(s * frequency, t * frequency, jitter, f1, f2, cs, ct);
    float edge = f2 - f1;
    float dome = smoothstep(0, groove, edge);
    float lift = 0.5 + 0.5 * float cellnoise(point(cs, ct, 7));
    P += Km * dome * lift * normalize(N);
    N = calculatenormal(P);
}

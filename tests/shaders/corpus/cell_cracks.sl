/*
 * cell_cracks.sl: dried mud: cracks where F2 - F1 of a Voronoi pattern in
 * (s,t) is small, cut into the surface with a smoothstep.
 * Idiom: Voronoi F1/F2 cell loop, cracks by smoothstep.
 */
#include "include/patterns.h"

displacement cell_cracks(float Km = 0.02, frequency = 5, width = 0.06)
{
    float f1, f2, cs, ct;
    voronoi_f1f2_2d(s * frequency, t * frequency, 1, f1, f2, cs, ct);
    float crack = 1 - smoothstep(0, width, f2 - f1);
    P -= Km * crack * normalize(N);
    N = calculatenormal(P);
}

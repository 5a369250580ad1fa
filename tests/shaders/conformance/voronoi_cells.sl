/* voronoi.h: cellular noise through output parameters */
#include "voronoi.h"

displacement voronoi_cells(float freq = 3, jitter = 0.8)
{
    float f1, sp, tp;
    voronoi_f1_2d(s * freq, t * freq, jitter, f1, sp, tp);
    P = point(f1, sp, tp);
}

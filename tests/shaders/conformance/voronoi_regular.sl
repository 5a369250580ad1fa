/* voronoi.h without jitter: the feature points are the cell centres, so
 * f1 is the distance to the centre of the cell the point is in */
#include "voronoi.h"

displacement voronoi_regular(float freq = 3)
{
    float f1, sp, tp;
    voronoi_f1_2d(s * freq, t * freq, 0, f1, sp, tp);
    P = point(f1, sp, tp);
}

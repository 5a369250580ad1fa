/* noises.h: fBm overloaded for a point and a float, loops over octaves */
#include "noises.h"

displacement noises_fbm(float octaves = 3)
{
    P = point(fBm(point(s, t, 0) * 2, octaves, 2, 0.5), fBm(t * 3, octaves, 2.17, 0.6), 0);
}

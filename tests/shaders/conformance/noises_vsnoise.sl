/* noises.h: vector signed noise as a bump direction, and snoise of a float */
#include "noises.h"

displacement noises_vsnoise(float Km = 0.2)
{
    vector d = vsnoise(point(s, t, 0) * 3);
    P = point(Km * xcomp(d), Km * ycomp(d) + snoise(t * 4), zcomp(d));
}

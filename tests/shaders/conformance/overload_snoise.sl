/* overloading by argument type: noises.h's snoise of a float and a point */
#include "noises.h"

displacement overload_snoise()
{
    P = point(snoise(s * 4), snoise(point(s, t, 0) * 3), ycomp(vsnoise(P)));
}

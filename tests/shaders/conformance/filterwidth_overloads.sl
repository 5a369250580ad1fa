/* filterwidth.h: the filter width of a float and of a point (overloads) */
#include "filterwidth.h"
#include "patterns.h"

displacement filterwidth_overloads()
{
    float fw = filterwidth(s);
    float fp = filterwidth(P);
    P = point(filteredpulse(0.25, 0.75, s, fw + 0.1), fp * 1e6, 0);
}

/*
 * fw_pulse_ring.sl: a raised ring around (0.5, 0.5) in (s,t): filteredpulse
 * on the radius with the radius's filter width.
 * Idiom: filteredpulse(edge0, edge1, x, filterwidth(x)).
 */
#include "include/filterwidth.h"

displacement fw_pulse_ring(float Km = 0.03, rin = 0.2, rout = 0.3)
{
    float r = distance(point(s, t, 0), point(0.5, 0.5, 0));
    float fw = filterwidth(r);
    P += Km * filteredpulse(rin, rout, r, fw) * normalize(N);
    N = calculatenormal(P);
}

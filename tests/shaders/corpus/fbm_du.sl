/*
 * fbm_du.sl: fBm of (s,t) whose octave count stops at the grid spacing
 * computed directly from du and dv (not from the derivatives).
 * Idiom: octave count from du/dv, max of them.
 */
#include "include/noises.h"

displacement fbm_du(float Km = 0.03, frequency = 4, octaves = 6)
{
    point p = point(s * frequency, t * frequency, 0);
    float fw = max(du, dv) * frequency;
    float h = fBm(p, fw, octaves, 2, 0.5);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

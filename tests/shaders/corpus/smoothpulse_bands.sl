/*
 * smoothpulse_bands.sl: soft raised bands repeating in t: smoothpulse of
 * mod(t * frequency, 1).
 * Idiom: smoothpulse (two smoothsteps) over mod.
 */
#include "include/filterwidth.h"

displacement smoothpulse_bands(float Km = 0.025, frequency = 6)
{
    float tt = mod(t * frequency, 1);
    float b = smoothpulse(0.1, 0.3, 0.6, 0.8, tt);
    P += Km * b * normalize(N);
    N = calculatenormal(P);
}

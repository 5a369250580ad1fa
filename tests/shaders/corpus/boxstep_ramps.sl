/*
 * boxstep_ramps.sl: a sawtooth of ramps in s (boxstep of mod) with a flat
 * pulse-shaped band in t (the unfiltered macros).
 * Idiom: boxstep, pulse, mod (continuous ramps, discontinuous band).
 */
#include "include/filterwidth.h"

displacement boxstep_ramps(float Km = 0.02, frequency = 5)
{
    float ss = mod(s * frequency, 1);
    float ramp = boxstep(0.2, 0.8, ss) * (1 - boxstep(0.8, 1, ss));
    float band = pulse(0.45, 0.55, t);
    P += Km * (ramp + 0.5 * band) * normalize(N);
    N = calculatenormal(P);
}

/*
 * turbulence_filtered.sl: turbulence (sum of |snoise|) pushed inwards, the
 * octave count from the filter width of the object-space point.
 * Idiom: turbulence loop, octaves from filterwidthp, object space.
 */
#include "include/noises.h"

displacement turbulence_filtered(float Km = 0.03, frequency = 4, octaves = 5)
{
    point Pobj = transform("object", P) * frequency;
    float fw = filterwidthp(Pobj);
    float h = turbulence(Pobj, fw, octaves, 2, 0.5);
    P -= Km * h * normalize(N);
    N = calculatenormal(P);
}

/*
 * fbm_filtered.sl: fBm in shader space whose octave count stops where an
 * octave becomes finer than the footprint, fw = filterwidthp(P).
 * Idiom: fBm loop with a filter-width-dependent octave count.
 */
#include "include/noises.h"

displacement fbm_filtered(float Km = 0.03, frequency = 3, octaves = 6,
                          lacunarity = 2, gain = 0.5)
{
    point Psh = transform("shader", P) * frequency;
    float fw = filterwidthp(Psh);
    float h = fBm(Psh, fw, octaves, lacunarity, gain);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

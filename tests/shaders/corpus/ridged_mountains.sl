/*
 * ridged_mountains.sl: Musgrave's ridged multifractal in shader space.
 * Idiom: ridged multifractal (weights from the previous octave, pow).
 */
#include "include/noises.h"

displacement ridged_mountains(float Km = 0.02, frequency = 2, octaves = 4,
                              H = 1, offset = 1, gain = 2)
{
    point Psh = transform("shader", P) * frequency;
    float h = ridgedmf(Psh, octaves, 2.1, H, offset, gain);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

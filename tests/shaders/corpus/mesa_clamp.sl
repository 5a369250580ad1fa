/*
 * mesa_clamp.sl: mesas: fBm clamped to a plateau from above and below.
 * Idiom: clamp / min / max of a noise sum (kinks).
 */
#include "include/noises.h"

displacement mesa_clamp(float Km = 0.03, frequency = 2, lo = -0.2, hi = 0.25)
{
    point Psh = transform("shader", P) * frequency;
    float h = fBm_fixed(Psh, 4, 2, 0.5);
    h = min(max(h, lo), hi);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

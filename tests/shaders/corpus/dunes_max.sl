/*
 * dunes_max.sl: the higher of two dune fields at different scales and
 * directions: where one field is well above the other, the other is not
 * seen at all.
 * Idiom: max() of two noise layers (a union of height fields).
 */
#include "include/noises.h"

displacement dunes_max(float Km = 0.03, frequency = 3)
{
    point Psh = transform("shader", P) * frequency;
    float a = fBm_fixed(Psh, 2, 2, 0.5);
    float b = 0.8 * fBm_fixed(Psh * 1.7 + point(5, 9, 2), 2, 2, 0.5) - 0.1;
    P += Km * max(a, b) * normalize(N);
    N = calculatenormal(P);
}

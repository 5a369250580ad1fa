/*
 * ridges_abs.sl: sharp ridges from 1 - |snoise|, squared, two octaves.
 * Idiom: abs of signed noise (a crease), in object space.
 */
#include "include/noises.h"

displacement ridges_abs(float Km = 0.03, frequency = 3)
{
    point Pobj = transform("object", P) * frequency;
    float r1 = 1 - abs(snoise(Pobj)), r2 = 1 - abs(snoise(Pobj * 2.2));
    float h = r1 * r1 + 0.4 * r2 * r2;
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

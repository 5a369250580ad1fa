/*
 * layer_mask.sl: two displacement layers, rock (fBm) and sand (fine
 * ripples along one axis), blended by a mask that a low-frequency noise
 * saturates: most of the surface is all rock or all sand, a band between
 * them is both.
 * Idiom: mix(a, b, smoothstep(lo, hi, mask)) layering, as terrain
 * materials are layered by a mask.
 */
#include "include/noises.h"

displacement layer_mask(float Km = 0.03, frequency = 3, lo = 0.45, hi = 0.55)
{
    point Psh = transform("shader", P) * frequency;
    float rock = fBm_fixed(Psh, 3, 2, 0.5);
    float sand = 0.3 * snoise(Psh * point(8, 1, 2)) + 0.1 * snoise(Psh * 16);
    float mask = smoothstep(lo, hi, noise(Psh * 0.5 + point(17, 3, 5)));
    float h = mix(rock, sand, mask);
    P += Km * h * normalize(N);
    N = calculatenormal(P);
}

/*
 * uv_quilt.sl: a quilt in the surface parameters u, v (not s, t): pillows
 * between stitched seams, seams pulled down by a smoothpulse.
 * Idiom: the globals u and v, mod, smoothpulse.
 */
#include "include/filterwidth.h"

displacement uv_quilt(float Km = 0.02, frequency = 6)
{
    float uu = mod(u * frequency, 1), vv = mod(v * frequency, 1);
    float pillow = sin(PI * uu) * sin(PI * vv);
    float seam = smoothpulse(0.45, 0.49, 0.51, 0.55, uu);
    P += Km * (pillow - 0.5 * seam) * normalize(N);
    N = calculatenormal(P);
}

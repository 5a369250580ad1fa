/*
 * fwp_checks.sl: a checkerboard of raised squares in shader space, filter
 * width from the point footprint filterwidthp(P) = sqrt(area(P)), faded to
 * the average where the checks get too small.
 * Idiom: filterwidthp / area(P), fadeout, filterstep on mod.
 */
#include "include/filterwidth.h"

displacement fwp_checks(float Km = 0.02, frequency = 4)
{
    point Psh = transform("shader", P) * frequency;
    float fw = filterwidthp(Psh);
    float x = mod(xcomp(Psh), 1), y = mod(ycomp(Psh), 1);
    float cx = filterstep(0.5, x, fw), cy = filterstep(0.5, y, fw);
    float check = cx + cy - 2 * cx * cy;
    check = fadeout(check, 0.5, 1, fw);
    P += Km * check * normalize(N);
    N = calculatenormal(P);
}

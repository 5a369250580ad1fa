/*
 * fw_grooves.sl: two grooves cut across t, each edge a filterstep whose
 * width comes from filterwidth(t).
 * Idiom: filterstep with a filterwidth from the derivatives.
 */
#include "include/filterwidth.h"

displacement fw_grooves(float Km = 0.02; float t0 = 0.3; float t1 = 0.6; float width = 0.05)
{
    float fw = filterwidth(t);
    float g = filterstep(t0, t, fw) - filterstep(t0 + width, t, fw)
            + filterstep(t1, t, fw) - filterstep(t1 + width, t, fw);
    P -= Km * g * normalize(N);
    N = calculatenormal(P);
}

/*
 * peers_diff.c: the pixels of a peer's image that differ from a reference
 * (peers_diff.h).
 */
#include "peers_diff.h"

#include <math.h>
#include <stddef.h>

peers_diff peers_diff_images(const float *test, const float *ref, int w, int h,
                             double tol, float *pic)
{
    static const float mark[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {1, 1, 0}};
    peers_diff d = {0, 0, 0};
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        const float *p = &test[i * 4], *q = &ref[i * 4];
        int hp = p[3] > 0.5f, hq = q[3] > 0.5f, kind = 0;
        if (hq && !hp) {
            d.holes++;
            kind = 1;
        } else if (hp && !hq) {
            d.extra++;
            kind = 2;
        } else if (hp && hq) {
            for (int k = 0; k < 3; k++)
                if (!(fabs((double)p[k] - (double)q[k]) <= tol)) {
                    d.colour++;
                    kind = 3;
                    break;
                }
        }
        if (pic) {
            float grey = (p[0] + p[1] + p[2]) / 3;
            for (int k = 0; k < 3; k++) pic[i * 4 + k] = kind ? mark[kind][k] : grey;
            pic[i * 4 + 3] = 1;
        }
    }
    return d;
}

/*
 * pinholes.c: the pinhole count (see pinholes.h).
 */
#include "pinholes.h"

#include <stddef.h>

static float alpha(const float *rgba, int w, int x, int y)
{
    return rgba[((size_t)y * (size_t)w + (size_t)x) * 4 + 3];
}

int count_pinholes(const float *rgba, int w, int h)
{
    int n = 0;
    for (int y = 1; y + 1 < h; y++)
        for (int x = 1; x + 1 < w; x++) {
            if (alpha(rgba, w, x, y) >= 1.0f) continue;
            int opaque = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    if ((dx || dy) && alpha(rgba, w, x + dx, y + dy) >= 1.0f) opaque++;
            if (opaque == 8) n++;
        }
    return n;
}

int count_opaque(const float *rgba, int w, int h)
{
    int n = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            if (alpha(rgba, w, x, y) >= 1.0f) n++;
    return n;
}

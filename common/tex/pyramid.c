/*
 * pyramid.c: a texture's two pyramids (tex.h): the mean pyramid that the
 * filter interpolates (trilinear mip-mapping) and the min-max pyramid that
 * bounds it (Thonat et al. 2021 §4; Logie 1995), built together level by
 * level from the image; plus the per-channel bounds of the filter's
 * derivatives (the largest texel step of any level times its resolution).
 *
 * Level k's texel (i, j) covers the level-0 block [i 2^k, (i+1) 2^k) x
 * [j 2^k, (j+1) 2^k) cut at the image's edge. Its mean is the mean of the
 * block, computed from the four texels below weighted by the level-0
 * texels each covers, then clamped into their min and max so that rounding
 * never takes it outside the min-max pyramid's bound.
 */
#include "tex/tex_internal.h"
#include "util/xalloc.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Level-0 texels covered by index q of level k along a side of n texels. */
static double covered(int q, int k, int n)
{
    long a = (long)q << k, b = ((long)q + 1) << k;
    if (b > n)
        b = n;
    return b > a ? (double)(b - a) : 0.0;
}

static double level_lipschitz(const float *v, int w, int h, int nch, int c, bool along_s)
{
    double m = 0;
    int n = along_s ? w : h, rows = along_s ? h : w;
    for (int r = 0; r < rows; r++) {
        for (int q = 0; q < n; q++) {
            size_t a = along_s ? (size_t)r * w + q : (size_t)q * w + r;
            size_t b = along_s ? (size_t)r * w + (q + 1) % n : (size_t)((q + 1) % n) * w + r;
            double x = v[a * nch + c], y = v[b * nch + c];
            m = fmax(m, fabs(y - x));             /* interior and periodic edge */
            if (q == 0 || q == n - 1)
                m = fmax(m, fabs(x));             /* black edge */
        }
    }
    return m * n;
}

tex_texture *tex_new_levels(const char *name, const char *type, int w, int h, int nch)
{
    assert(w >= 1 && h >= 1 && w <= TEX_MAX_SIDE && h <= TEX_MAX_SIDE);
    assert(nch >= 1 && nch <= TEX_MAX_CHANNELS);
    tex_texture *t = xcalloc(1, sizeof *t);
    t->name = xstrdup(name);
    t->type = type;
    t->w = w;
    t->h = h;
    t->nch = nch;
    int n = 1;
    for (int a = w, b = h; a > 1 || b > 1; n++) {
        a = (a + 1) / 2;
        b = (b + 1) / 2;
    }
    t->nlevels = n;
    t->lw = xcalloc((size_t)n, sizeof *t->lw);
    t->lh = xcalloc((size_t)n, sizeof *t->lh);
    t->avg = xcalloc((size_t)n, sizeof *t->avg);
    t->mn = xcalloc((size_t)n, sizeof *t->mn);
    t->mx = xcalloc((size_t)n, sizeof *t->mx);
    t->lips = xcalloc((size_t)nch, sizeof *t->lips);
    t->lipt = xcalloc((size_t)nch, sizeof *t->lipt);
    for (int k = 0; k < n; k++) {
        t->lw[k] = k ? (t->lw[k - 1] + 1) / 2 : w;
        t->lh[k] = k ? (t->lh[k - 1] + 1) / 2 : h;
    }
    assert(t->lw[n - 1] == 1 && t->lh[n - 1] == 1);   /* the top level is one texel */
    return t;
}

tex_texture *tex_build(tex_pixels *px, const char *name)
{
    tex_texture *t = tex_new_levels(name, px->type ? px->type : "float", px->w, px->h, px->nch);
    int n = t->nlevels;
    int nch = t->nch;
    float *img = px->data;
    px->data = NULL;
    size_t count = (size_t)t->w * (size_t)t->h * (size_t)nch;
    for (size_t k = 0; k < count; k++)
        if (!isfinite(img[k]))
            img[k] = 0.0f;
    t->avg[0] = t->mn[0] = t->mx[0] = img;
    t->bytes = count * sizeof(float);
    for (int k = 1; k < n; k++) {
        int pw = t->lw[k - 1], ph = t->lh[k - 1];
        int w = t->lw[k], h = t->lh[k];
        size_t sz = (size_t)w * (size_t)h * (size_t)nch;
        t->avg[k] = xmalloc(sz * sizeof(float));
        t->mn[k] = xmalloc(sz * sizeof(float));
        t->mx[k] = xmalloc(sz * sizeof(float));
        t->bytes += 3 * sz * sizeof(float);
        const float *pa = t->avg[k - 1], *pmn = t->mn[k - 1], *pmx = t->mx[k - 1];
        for (int j = 0; j < h; j++)
            for (int i = 0; i < w; i++)
                for (int c = 0; c < nch; c++) {
                    double sum = 0, weight = 0, lo = INFINITY, hi = -INFINITY;
                    double alo = INFINITY, ahi = -INFINITY;
                    for (int b = 0; b < 2; b++)
                        for (int a = 0; a < 2; a++) {
                            int x = 2 * i + a, y = 2 * j + b;
                            if (x >= pw || y >= ph)
                                continue;
                            size_t e = ((size_t)y * pw + x) * nch + c;
                            double wt = covered(x, k - 1, t->w) * covered(y, k - 1, t->h);
                            sum += wt * pa[e];
                            weight += wt;
                            alo = fmin(alo, pa[e]);
                            ahi = fmax(ahi, pa[e]);
                            lo = fmin(lo, pmn[e]);
                            hi = fmax(hi, pmx[e]);
                        }
                    size_t o = ((size_t)j * w + i) * nch + c;
                    float m = (float)(sum / weight);
                    t->avg[k][o] = m < alo ? (float)alo : m > ahi ? (float)ahi : m;
                    t->mn[k][o] = (float)lo;
                    t->mx[k][o] = (float)hi;
                }
    }
    for (int c = 0; c < nch; c++)
        for (int k = 0; k < n; k++) {
            t->lips[c] = fmax(t->lips[c], level_lipschitz(t->avg[k], t->lw[k], t->lh[k], nch,
                                                          c, true));
            t->lipt[c] = fmax(t->lipt[c], level_lipschitz(t->avg[k], t->lw[k], t->lh[k], nch,
                                                          c, false));
        }
    return t;
}

tex_texture *tex_from_pixels(const float *pixels, int w, int h, int nch, const char *name)
{
    if (w < 1 || h < 1 || nch < 1 || w > TEX_MAX_SIDE || h > TEX_MAX_SIDE ||
        nch > TEX_MAX_CHANNELS)
        return NULL;
    size_t count = (size_t)w * (size_t)h * (size_t)nch;
    tex_pixels px = { xmalloc(count * sizeof(float)), w, h, nch, "float" };
    memcpy(px.data, pixels, count * sizeof(float));
    return tex_build(&px, name);
}

void tex_destroy(tex_texture **t_p)
{
    tex_texture *t = *t_p;
    if (!t)
        return;
    tex_tiled_destroy(&t->tiled);
    for (int k = 0; k < t->nlevels && t->avg; k++) {
        free(t->avg[k]);
        if (k > 0 && t->mn)
            free(t->mn[k]);
        if (k > 0 && t->mx)
            free(t->mx[k]);
    }
    free(t->avg);
    free(t->mn);
    free(t->mx);
    free(t->lw);
    free(t->lh);
    free(t->lips);
    free(t->lipt);
    free(t->name);
    free(t);
    *t_p = NULL;
}

int tex_width(const tex_texture *t) { return t->w; }
int tex_height(const tex_texture *t) { return t->h; }
int tex_channels(const tex_texture *t) { return t->nch; }
int tex_levels(const tex_texture *t) { return t->nlevels; }
const char *tex_name(const tex_texture *t) { return t->name; }
const char *tex_type(const tex_texture *t) { return t->type; }
size_t tex_bytes(const tex_texture *t) { return t->bytes; }

float tex_texel(const tex_texture *t, int level, int c, int i, int j)
{
    float v = tex_at(t, 0, level, c, i, j);
    if (t->tiled)
        tex_tiles_unpin();
    return v;
}

/*
 * filter.c: the texture filter (trilinear mip-mapping over the mean
 * pyramid, tex.h "The filter") at a point, and its bound over a range of
 * lookups from the min-max pyramid (tex.h "The bound"; Thonat et al. 2021
 * §4), plus the single bilinear cell that affine runs turn into an affine
 * form with its linear part (issue 16).
 *
 * Periodic wrap reduces s to s - floor(s) before the lookup; clamp and
 * black clamp the texel coordinate to [-2, n + 1] (which changes nothing:
 * beyond the edge the texels repeat the edge or are 0), so no coordinate
 * overflows an int. The bound widens every texel coordinate by a relative
 * 1e-9 before rounding it down, so a lookup that rounds the other way
 * still lands on a texel the bound covered.
 *
 * Texels come through tex_at: from memory, or from a tile read on demand
 * (tiles.c), which each public function lets go of when it returns.
 */
#include "tex/tex_internal.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <string.h>

double tex_level_of(const tex_texture *t, double ws, double wt)
{
    double m = fmax(fabs(ws) * t->w, fabs(wt) * t->h);
    if (isnan(ws) || isnan(wt))
        return t->nlevels - 1;
    if (!(m > 1.0))
        return 0.0;
    double l = log2(m);
    return l < t->nlevels - 1 ? l : t->nlevels - 1;
}

static int wrap_index(int i, int n, tex_wrap wrap, bool *outside)
{
    *outside = false;
    if (i >= 0 && i < n)
        return i;
    if (wrap == TEX_WRAP_PERIODIC)
        return ((i % n) + n) % n;
    if (wrap == TEX_WRAP_CLAMP)
        return i < 0 ? 0 : n - 1;
    *outside = true;
    return 0;
}

static double fetch(const tex_texture *t, int k, int c, int i, int j, tex_wrap sw, tex_wrap tw)
{
    bool oi, oj;
    i = wrap_index(i, t->lw[k], sw, &oi);
    j = wrap_index(j, t->lh[k], tw, &oj);
    if (oi || oj)
        return 0.0;
    return tex_at(t, 0, k, c, i, j);
}

/* out[b * ni + a] = texel (wi[a], wj[b]) of channel c of level k of part
 * p, for valid indexes: from memory, or a block of tiles at once */
static void read_block(const tex_texture *t, int p, int k, int c, const int *wi, int ni,
                       const int *wj, int nj, float *out)
{
    if (!(p == 0 ? t->avg[k] : p == 1 ? t->mn[k] : t->mx[k])) {   /* a tiled level */
        tex_tile_block(t, p, k, c, wi, ni, wj, nj, out);
        return;
    }
    for (int b = 0; b < nj; b++)
        for (int a = 0; a < ni; a++)
            out[b * ni + a] = tex_at(t, p, k, c, wi[a], wj[b]);
}

/* The texel coordinate of s at a level of n texels. */
static double coord(double s, int n, tex_wrap wrap)
{
    if (wrap == TEX_WRAP_PERIODIC)
        s -= floor(s);
    double x = s * n - 0.5;
    return x < -2.0 ? -2.0 : x > n + 1.0 ? n + 1.0 : x;
}

static double bilinear(const tex_texture *t, int k, int c, double s, double tt, tex_wrap sw,
                       tex_wrap tw, double *dds, double *ddt)
{
    double x = coord(s, t->lw[k], sw), y = coord(tt, t->lh[k], tw);
    double fi = floor(x), fj = floor(y), f = x - fi, g = y - fj;
    int i = (int)fi, j = (int)fj;
    double v00 = fetch(t, k, c, i, j, sw, tw), v10 = fetch(t, k, c, i + 1, j, sw, tw);
    double v01 = fetch(t, k, c, i, j + 1, sw, tw), v11 = fetch(t, k, c, i + 1, j + 1, sw, tw);
    double v = (1 - f) * (1 - g) * v00 + f * (1 - g) * v10 + (1 - f) * g * v01 + f * g * v11;
    double lo = fmin(fmin(v00, v10), fmin(v01, v11)), hi = fmax(fmax(v00, v10), fmax(v01, v11));
    *dds = t->lw[k] * ((v10 - v00) * (1 - g) + (v11 - v01) * g);
    *ddt = t->lh[k] * ((v01 - v00) * (1 - f) + (v11 - v10) * f);
    return v < lo ? lo : v > hi ? hi : v;
}

double tex_sample(const tex_texture *t, int c, double s, double tt, double ws, double wt,
                  tex_wrap swrap, tex_wrap twrap, double fill, double *dds, double *ddt)
{
    double ds = 0, dt = 0, v;
    if (c < 0 || c >= t->nch) {
        v = fill;
    } else if (!isfinite(s) || !isfinite(tt)) {
        v = 0;                       /* no texel is there: as black */
    } else {
        double l = tex_level_of(t, ws, wt), k0 = floor(l), fr = l - k0;
        int k = (int)k0;
        v = bilinear(t, k, c, s, tt, swrap, twrap, &ds, &dt);
        if (fr > 0 && k + 1 < t->nlevels) {
            double ds1, dt1, v1 = bilinear(t, k + 1, c, s, tt, swrap, twrap, &ds1, &dt1);
            double m = (1 - fr) * v + fr * v1;
            double lo = fmin(v, v1), hi = fmax(v, v1);
            v = m < lo ? lo : m > hi ? hi : m;
            ds = (1 - fr) * ds + fr * ds1;
            dt = (1 - fr) * dt + fr * dt1;
        }
    }
    if (dds)
        *dds = ds;
    if (ddt)
        *ddt = dt;
    if (t->tiled)
        tex_tiles_unpin();
    return v;
}

/* ---- the bound ---- */

/* |w| over w in [a, b]: [lo, hi] (NaN: [0, inf]) */
static void abs_range(const double w[2], double *lo, double *hi)
{
    if (isnan(w[0]) || isnan(w[1])) {
        *lo = 0;
        *hi = INFINITY;
        return;
    }
    *lo = (w[0] <= 0 && w[1] >= 0) ? 0 : fmin(fabs(w[0]), fabs(w[1]));
    *hi = fmax(fabs(w[0]), fabs(w[1]));
}

/* The texels (of a level of n) under the bilinear cells of every s in
 * [s0, s1], as up to two ranges of valid indexes; *zero when a black edge
 * is among them. Returns the number of ranges. */
static int texel_ranges(double s0, double s1, int n, tex_wrap wrap, int out[2][2], bool *zero)
{
    if (!isfinite(s0) || !isfinite(s1) || (wrap == TEX_WRAP_PERIODIC && s1 - s0 >= 1.0)) {
        out[0][0] = 0;
        out[0][1] = n - 1;         /* a non-finite coordinate reads 0 (tex_sample) */
        *zero = *zero || wrap == TEX_WRAP_BLACK || !isfinite(s0) || !isfinite(s1);
        return 1;
    }
    if (wrap == TEX_WRAP_PERIODIC) {
        double fl = floor(s0);
        s0 -= fl;
        s1 -= fl;
    }
    double x0 = s0 * n - 0.5, x1 = s1 * n - 0.5;
    x0 -= 1e-9 * (fabs(x0) + 1.0);
    x1 += 1e-9 * (fabs(x1) + 1.0);
    if (wrap != TEX_WRAP_PERIODIC) {
        x0 = x0 < -2.0 ? -2.0 : x0 > n + 1.0 ? n + 1.0 : x0;
        x1 = x1 < -2.0 ? -2.0 : x1 > n + 1.0 ? n + 1.0 : x1;
    }
    long i0 = (long)floor(x0), i1 = (long)floor(x1) + 1;
    if (wrap == TEX_WRAP_PERIODIC) {
        if (i1 - i0 + 1 >= n) {
            out[0][0] = 0;
            out[0][1] = n - 1;
            return 1;
        }
        long a = ((i0 % n) + n) % n, b = a + (i1 - i0);
        if (b < n) {
            out[0][0] = (int)a;
            out[0][1] = (int)b;
            return 1;
        }
        out[0][0] = (int)a;
        out[0][1] = n - 1;
        out[1][0] = 0;
        out[1][1] = (int)(b - n);
        return 2;
    }
    if (i0 < 0 || i1 > n - 1) {
        if (wrap == TEX_WRAP_BLACK)
            *zero = true;
        if (wrap == TEX_WRAP_CLAMP) {
            i0 = i0 < 0 ? 0 : i0 > n - 1 ? n - 1 : i0;
            i1 = i1 < 0 ? 0 : i1 > n - 1 ? n - 1 : i1;
        }
    }
    if (i0 < 0)
        i0 = 0;
    if (i1 > n - 1)
        i1 = n - 1;
    if (i0 > i1)
        return 0;
    out[0][0] = (int)i0;
    out[0][1] = (int)i1;
    return 1;
}

/* min and max of channel c over the level-0 texels [i0, i1] x [j0, j1],
 * from the level of the min-max pyramid where that spans <= 4 x 4 */
static void minmax(const tex_texture *t, int c, int i0, int i1, int j0, int j1, double *lo,
                   double *hi)
{
    int m = 0;
    while (m + 1 < t->nlevels && (((i1 >> m) - (i0 >> m)) > 3 || ((j1 >> m) - (j0 >> m)) > 3))
        m++;
    int ni = (i1 >> m) - (i0 >> m) + 1, nj = (j1 >> m) - (j0 >> m) + 1;
    if (ni <= TEX_BLOCK_MAX && nj <= TEX_BLOCK_MAX) {     /* the texels a block at a time */
        int wi[TEX_BLOCK_MAX], wj[TEX_BLOCK_MAX];
        float mn[TEX_BLOCK_MAX * TEX_BLOCK_MAX], mx[TEX_BLOCK_MAX * TEX_BLOCK_MAX];
        for (int a = 0; a < ni; a++)
            wi[a] = (i0 >> m) + a;
        for (int b = 0; b < nj; b++)
            wj[b] = (j0 >> m) + b;
        read_block(t, 1, m, c, wi, ni, wj, nj, mn);
        read_block(t, 2, m, c, wi, ni, wj, nj, mx);
        for (int q = 0; q < ni * nj; q++) {     /* the same order as below */
            *lo = fmin(*lo, mn[q]);
            *hi = fmax(*hi, mx[q]);
        }
        return;
    }
    for (int j = j0 >> m; j <= j1 >> m; j++)
        for (int i = i0 >> m; i <= i1 >> m; i++) {
            *lo = fmin(*lo, tex_at(t, 1, m, c, i, j));
            *hi = fmax(*hi, tex_at(t, 2, m, c, i, j));
        }
}

/* A texel coordinate moved out by a relative 1e-9 (as texel_ranges): the
 * float lookup computes it differently (periodic wrap first), so it may
 * land in the cell next to the one the exact coordinate is in; the exact
 * bounds take in every cell it can reach. */
static double widen_lo(double x) { return x - 1e-9 * (fabs(x) + 1.0); }
static double widen_hi(double x) { return x + 1e-9 * (fabs(x) + 1.0); }

/* The bilinear cell of level k (n texels along the axis) under every s of
 * [s0, s1]: true with its origin i (texel coordinate x = s n - 1/2, the
 * cell spans [i, i + 1]); unreduced, the texels wrap when fetched. */
static bool one_cell(double s0, double s1, int n, double *origin)
{
    double x0 = widen_lo(s0 * n - 0.5), x1 = widen_hi(s1 * n - 0.5);
    if (!(fabs(x0) < 1e9 && fabs(x1) < 1e9))
        return false;
    double f = floor(x0);
    if (x1 > f + 1.0)
        return false;
    *origin = f;
    return true;
}

/* min and max of two numbers, neither NaN (texels are finite: tex.h; the
 * coordinates were checked by few_cells): a compare, where fmin and fmax
 * are library calls that also order NaNs */
static inline double dmin(double a, double b) { return b < a ? b : a; }
static inline double dmax(double a, double b) { return b > a ? b : a; }

/* 1e-9 of the largest magnitude: covers the float lookup's rounding (its
 * texel coordinate and blend are computed differently from the bound's) */
static double slack(double a, double b)
{
    return 1e-9 * fmax(fabs(a), fabs(b)) + 0x1p-1000;
}

/* The cells of level k (n texels) under [s0, s1]: the first and last
 * origin; false where there are more than `most` or the coordinates are
 * too large to split. */
static bool few_cells(double s0, double s1, int n, int most, double *first, double *last)
{
    double x0 = widen_lo(s0 * n - 0.5), x1 = widen_hi(s1 * n - 0.5);
    if (!(fabs(x0) < 1e9 && fabs(x1) < 1e9))
        return false;
    *first = floor(x0);
    *last = fmax(*first, ceil(x1) - 1.0);
    return *last - *first < most;
}

/* v[b][a] = texel (i + a, j + b) of level k, wrapped (0 outside a black
 * edge), for a < ni <= 4, b < nj <= 4: the
 * texels under at most 3 x 3 cells, each read once and each index wrapped
 * once (the cells share their edges: 16 reads where 36 were, issue 24) */
static void gather(const tex_texture *t, int k, int c, int i, int ni, int j, int nj,
                   tex_wrap sw, tex_wrap tw, double v[4][4])
{
    assert(ni >= 1 && ni <= 4 && nj >= 1 && nj <= 4);
    int wi[4] = { 0 }, wj[4] = { 0 };
    bool oi[4], oj[4];
    for (int a = 0; a < ni; a++)
        wi[a] = wrap_index(i + a, t->lw[k], sw, &oi[a]);
    for (int b = 0; b < nj; b++)
        wj[b] = wrap_index(j + b, t->lh[k], tw, &oj[b]);
    float f[16];
    read_block(t, 0, k, c, wi, ni, wj, nj, f);       /* outside: index 0, then 0 */
    for (int b = 0; b < nj; b++)
        for (int a = 0; a < ni; a++)
            v[b][a] = oi[a] || oj[b] ? 0.0 : f[b * ni + a];
}

/* lo <= level k's bilinear <= hi over the s and t of r: exact where r
 * covers at most 3 x 3 cells (each cell's part of r is a rectangle, and a
 * bilinear function takes its extremes at a rectangle's corners), so the
 * bound shrinks with r even across cell edges; else the min-max pyramid
 * over the texels the cells touch. */
static void level_range(const tex_texture *t, int k, int c, const tex_range *r, tex_wrap sw,
                        tex_wrap tw, double *lo, double *hi)
{
    double i0, i1, j0, j1;
    int n = t->lw[k], m = t->lh[k];
    if (few_cells(r->s[0], r->s[1], n, 3, &i0, &i1) &&
        few_cells(r->t[0], r->t[1], m, 3, &j0, &j1)) {
        double x0 = widen_lo(r->s[0] * n - 0.5), x1 = widen_hi(r->s[1] * n - 0.5);
        double y0 = widen_lo(r->t[0] * m - 0.5), y1 = widen_hi(r->t[1] * m - 0.5);
        double l = INFINITY, h = -INFINITY;
        double tx[4][4];
        gather(t, k, c, (int)i0, (int)i1 - (int)i0 + 2, (int)j0, (int)j1 - (int)j0 + 2, sw, tw, tx);
        for (double cj = j0; cj <= j1; cj++)
            for (double ci = i0; ci <= i1; ci++) {
                int ti = (int)(ci - i0), tj = (int)(cj - j0);
                double v00 = tx[tj][ti], v10 = tx[tj][ti + 1], v01 = tx[tj + 1][ti];
                double v11 = tx[tj + 1][ti + 1];
                double vmin = dmin(dmin(v00, v10), dmin(v01, v11));
                double vmax = dmax(dmax(v00, v10), dmax(v01, v11));
                double fs[2] = { dmax(x0, ci) - ci, dmin(x1, ci + 1) - ci };
                double gs[2] = { dmax(y0, cj) - cj, dmin(y1, cj + 1) - cj };
                for (int a = 0; a < 2; a++) {
                    fs[a] = fs[a] < 0 ? 0 : fs[a] > 1 ? 1 : fs[a];
                    gs[a] = gs[a] < 0 ? 0 : gs[a] > 1 ? 1 : gs[a];
                }
                if (fs[0] == 0 && fs[1] == 1 && gs[0] == 0 && gs[1] == 1) {
                    /* the whole cell: its extremes are its texels */
                    l = dmin(l, vmin);
                    h = dmax(h, vmax);
                    continue;
                }
                double cl = INFINITY, ch = -INFINITY;
                for (int a = 0; a < 2; a++)
                    for (int b = 0; b < 2; b++) {
                        double f = fs[a], g = gs[b];
                        double v = (1 - f) * (1 - g) * v00 + f * (1 - g) * v10 +
                                   (1 - f) * g * v01 + f * g * v11;
                        cl = dmin(cl, v);
                        ch = dmax(ch, v);
                    }
                double e = slack(vmin, vmax);
                l = dmin(l, dmax(cl - e, vmin));
                h = dmax(h, dmin(ch + e, vmax));
            }
        *lo = l;
        *hi = h;
        return;
    }
    bool zero = false;
    double l = INFINITY, h = -INFINITY;
    int si[2][2], ti[2][2];
    int ns = texel_ranges(r->s[0], r->s[1], t->lw[k], sw, si, &zero);
    int nt = texel_ranges(r->t[0], r->t[1], t->lh[k], tw, ti, &zero);
    for (int a = 0; a < ns; a++)
        for (int b = 0; b < nt; b++) {
            long ie = ((long)si[a][1] + 1) << k, je = ((long)ti[b][1] + 1) << k;
            minmax(t, c, si[a][0] << k, (int)(ie < t->w ? ie : t->w) - 1, ti[b][0] << k,
                   (int)(je < t->h ? je : t->h) - 1, &l, &h);
        }
    if (zero) {
        l = fmin(l, 0.0);
        h = fmax(h, 0.0);
    }
    *lo = l;
    *hi = h;
}

/* The filter's levels over the widths of r: lmin <= l <= lmax. */
static void levels_of(const tex_texture *t, const tex_range *r, double *lmin, double *lmax)
{
    double wslo, wshi, wtlo, wthi;
    abs_range(r->ws, &wslo, &wshi);
    abs_range(r->wt, &wtlo, &wthi);
    *lmin = tex_level_of(t, wslo, wtlo);
    *lmax = tex_level_of(t, wshi, wthi);
}

static bool has_nan(const tex_range *r)
{
    return isnan(r->s[0]) || isnan(r->s[1]) || isnan(r->t[0]) || isnan(r->t[1]);
}

/* tex_bound of a valid channel and coordinates without NaN, at the levels
 * [lmin, lmax] (levels_of), the tiles left pinned */
static void bound_at(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
                     tex_wrap twrap, double lmin, double lmax, double *lo, double *hi)
{
    int k0 = (int)floor(lmin), k1 = (int)floor(lmax);
    double l, h;
    if (k0 == k1) {              /* one pair of levels, blend f in [f0, f1] */
        double f0 = lmin - k0, f1 = lmax - k0;
        level_range(t, k0, c, r, swrap, twrap, &l, &h);
        if (f1 > 0 && k0 + 1 < t->nlevels) {
            double l1, h1;
            level_range(t, k0 + 1, c, r, swrap, twrap, &l1, &h1);
            double a = (1 - f0) * l + f0 * l1, b = (1 - f1) * l + f1 * l1;
            double c0 = (1 - f0) * h + f0 * h1, d = (1 - f1) * h + f1 * h1;
            double e = slack(fmin(l, l1), fmax(h, h1));
            double lo2 = fmax(fmin(a, b) - e, fmin(l, l1));
            double hi2 = fmin(fmax(c0, d) + e, fmax(h, h1));
            l = lo2;
            h = hi2;
        }
    } else {                     /* several levels: the hull of their ranges */
        l = INFINITY;
        h = -INFINITY;
        for (int k = k0; k <= k1 + 1 && k < t->nlevels; k++) {
            double a, b;
            level_range(t, k, c, r, swrap, twrap, &a, &b);
            l = fmin(l, a);
            h = fmax(h, b);
        }
    }
    *lo = l;
    *hi = h;
}

void tex_bound(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
               tex_wrap twrap, double fill, double *lo, double *hi)
{
    if (c < 0 || c >= t->nch) {
        *lo = *hi = fill;
        return;
    }
    if (has_nan(r)) {
        tex_range all = { { 0, 2 }, { 0, 2 }, { INFINITY, INFINITY }, { INFINITY, INFINITY } };
        tex_bound(t, c, &all, TEX_WRAP_BLACK, TEX_WRAP_BLACK, fill, lo, hi);
        return;
    }
    double lmin, lmax;
    levels_of(t, r, &lmin, &lmax);
    bound_at(t, c, r, swrap, twrap, lmin, lmax, lo, hi);
    if (t->tiled)
        tex_tiles_unpin();
}

/* tex_cells of a valid channel at the levels [lmin, lmax], the tiles left
 * pinned */
static int cells_at(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
                    tex_wrap twrap, double lmin, double lmax, tex_cell out[2])
{
    if (lmin != lmax)
        return 0;                /* the blend varies: no single form */
    int k = (int)floor(lmin);
    double f = lmin - k;
    int n = f > 0 && k + 1 < t->nlevels ? 2 : 1;
    for (int q = 0; q < n; q++) {
        int lv = k + q;
        double oi, oj;
        if (!one_cell(r->s[0], r->s[1], t->lw[lv], &oi) ||
            !one_cell(r->t[0], r->t[1], t->lh[lv], &oj))
            return 0;
        tex_cell *cell = &out[q];
        cell->weight = n == 1 ? 1.0 : q == 0 ? 1 - f : f;
        cell->w = t->lw[lv];
        cell->h = t->lh[lv];
        cell->oi = oi;
        cell->oj = oj;
        double tx[4][4];
        gather(t, lv, c, (int)oi, 2, (int)oj, 2, swrap, twrap, tx);
        cell->v[0] = tx[0][0];
        cell->v[1] = tx[0][1];
        cell->v[2] = tx[1][0];
        cell->v[3] = tx[1][1];
    }
    return n;
}

int tex_cells(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
              tex_wrap twrap, tex_cell out[2])
{
    if (c < 0 || c >= t->nch)
        return 0;
    double lmin, lmax;
    levels_of(t, r, &lmin, &lmax);
    int n = cells_at(t, c, r, swrap, twrap, lmin, lmax, out);
    if (t->tiled)
        tex_tiles_unpin();
    return n;
}

int tex_cells_or_bound(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
                       tex_wrap twrap, double fill, tex_cell out[2], double *lo, double *hi)
{
    if (c < 0 || c >= t->nch) {
        *lo = *hi = fill;
        return 0;
    }
    if (has_nan(r)) {            /* no cells (one_cell fails on NaN): the whole map */
        tex_bound(t, c, r, swrap, twrap, fill, lo, hi);
        return 0;
    }
    double lmin, lmax;
    levels_of(t, r, &lmin, &lmax);
    int n = cells_at(t, c, r, swrap, twrap, lmin, lmax, out);
    if (n == 0)
        bound_at(t, c, r, swrap, twrap, lmin, lmax, lo, hi);
    if (t->tiled)
        tex_tiles_unpin();
    return n;
}

/* The slopes of level k's bilinear filter over the s and t of r:
 * ds[0] <= d/ds <= ds[1] and dt likewise. Per cell under r, d/ds =
 * n ((v10 - v00)(1 - g) + (v11 - v01) g) is linear in the cell's g, so its
 * extremes over the cell's part of r are at that part's two g ends (and
 * d/dt likewise in f). The texels are read with the lookup's wrap; cells
 * beyond a clamp or black edge have equal texels, as the lookup's clamped
 * coordinate is constant there. False where r spans more than
 * TEX_SLOPE_CELLS cells along an axis. */
enum { TEX_SLOPE_CELLS = 24 };

/* row[a] = texel (wi[a], j) of level k, j wrapped (fetch's texels: 0
 * outside a black edge) */
static void slope_row(const tex_texture *t, int k, int c, const int *wi, const bool *oi, int ni,
                      int j, int m, tex_wrap tw, double *row)
{
    bool oj;
    int wj = wrap_index(j, m, tw, &oj);
    for (int a = 0; a < ni; a++)
        row[a] = oi[a] || oj ? 0.0 : tex_at(t, 0, k, c, wi[a], wj);
}
static bool level_slopes(const tex_texture *t, int k, int c, const tex_range *r, tex_wrap sw,
                         tex_wrap tw, double ds[2], double dt[2])
{
    double i0, i1, j0, j1;
    int n = t->lw[k], m = t->lh[k];
    if (!few_cells(r->s[0], r->s[1], n, TEX_SLOPE_CELLS, &i0, &i1) ||
        !few_cells(r->t[0], r->t[1], m, TEX_SLOPE_CELLS, &j0, &j1))
        return false;
    double x0 = widen_lo(r->s[0] * n - 0.5), x1 = widen_hi(r->s[1] * n - 0.5);
    double y0 = widen_lo(r->t[0] * m - 0.5), y1 = widen_hi(r->t[1] * m - 0.5);
    int ni = (int)(i1 - i0) + 2, nj = (int)(j1 - j0) + 2;
    double row0[TEX_SLOPE_CELLS + 1], row1[TEX_SLOPE_CELLS + 1];
    double sl = INFINITY, sh = -INFINITY, tl = INFINITY, th = -INFINITY;
    int wi[TEX_SLOPE_CELLS + 1];         /* the columns, wrapped once (as fetch) */
    bool oi[TEX_SLOPE_CELLS + 1];
    for (int a = 0; a < ni; a++)
        wi[a] = wrap_index((int)i0 + a, n, sw, &oi[a]);
    slope_row(t, k, c, wi, oi, ni, (int)j0, m, tw, row1);
    for (int b = 0; b + 1 < nj; b++) {   /* the cells between rows b and b + 1 */
        memcpy(row0, row1, (size_t)ni * sizeof *row0);
        slope_row(t, k, c, wi, oi, ni, (int)j0 + b + 1, m, tw, row1);
        double cj = j0 + b;
        double g0 = dmax(y0, cj) - cj, g1 = dmin(y1, cj + 1) - cj;
        g0 = g0 < 0 ? 0 : g0 > 1 ? 1 : g0;
        g1 = g1 < 0 ? 0 : g1 > 1 ? 1 : g1;
        for (int a = 0; a + 1 < ni; a++) {
            double ci = i0 + a;
            double f0 = dmax(x0, ci) - ci, f1 = dmin(x1, ci + 1) - ci;
            f0 = f0 < 0 ? 0 : f0 > 1 ? 1 : f0;
            f1 = f1 < 0 ? 0 : f1 > 1 ? 1 : f1;
            double es0 = row0[a + 1] - row0[a], es1 = row1[a + 1] - row1[a];
            double et0 = row1[a] - row0[a], et1 = row1[a + 1] - row0[a + 1];
            double s0 = es0 + (es1 - es0) * g0, s1 = es0 + (es1 - es0) * g1;
            double q0 = et0 + (et1 - et0) * f0, q1 = et0 + (et1 - et0) * f1;
            sl = dmin(sl, dmin(s0, s1));
            sh = dmax(sh, dmax(s0, s1));
            tl = dmin(tl, dmin(q0, q1));
            th = dmax(th, dmax(q0, q1));
        }
    }
    /* differences and blends in doubles of float texels: a few roundings
     * each, which slack's relative 1e-9 covers many times over; times n
     * (a factor 1 + 2^-53) inside the outward step of tex_slopes */
    double es = slack(sl, sh), et = slack(tl, th);
    ds[0] = n * (sl - es);
    ds[1] = n * (sh + es);
    dt[0] = m * (tl - et);
    dt[1] = m * (th + et);
    return true;
}

/* the hull over f in [f0, f1] of (1 - f) a + f b, a in [a0, a1], b in
 * [b0, b1]: linear in f for fixed ends, so at f0 or f1 */
static void blend_slopes(double f0, double f1, const double a[2], const double b[2],
                         double out[2])
{
    out[0] = dmin((1 - f0) * a[0] + f0 * b[0], (1 - f1) * a[0] + f1 * b[0]);
    out[1] = dmax((1 - f0) * a[1] + f0 * b[1], (1 - f1) * a[1] + f1 * b[1]);
}

bool tex_slopes(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
                tex_wrap twrap, bool fixed_widths, double ds[2], double dt[2])
{
    ds[0] = ds[1] = dt[0] = dt[1] = 0.0;
    if (c < 0 || c >= t->nch)
        return true;
    if (!(isfinite(r->s[0]) && isfinite(r->s[1]) && isfinite(r->t[0]) && isfinite(r->t[1])))
        return false;
    double lmin, lmax;
    levels_of(t, r, &lmin, &lmax);
    int k = (int)floor(lmin);
    /* the blend may vary over r only where the widths are constant (then
     * it is one f of [f0, f1]), and the pair of levels may not */
    if (lmin != lmax && !(fixed_widths && floor(lmax) == k))
        return false;
    double f0 = lmin - k, f1 = lmax - k;
    bool two = f1 > 0 && k + 1 < t->nlevels;
    double as[2], at[2], bs[2] = { 0, 0 }, bt[2] = { 0, 0 };
    bool ok = level_slopes(t, k, c, r, swrap, twrap, as, at);
    if (ok && two)
        ok = level_slopes(t, k + 1, c, r, swrap, twrap, bs, bt);
    if (t->tiled)
        tex_tiles_unpin();
    if (!ok)
        return false;
    if (two) {
        blend_slopes(f0, f1, as, bs, ds);
        blend_slopes(f0, f1, at, bt, dt);
    } else {
        memcpy(ds, as, sizeof as);
        memcpy(dt, at, sizeof at);
    }
    /* the level's n and the blend's products and sums: outward by a
     * relative 2^-40 */
    for (int q = 0; q < 2; q++) {
        double sg = q ? 1.0 : -1.0;
        ds[q] += sg * (0x1p-40 * fabs(ds[q]) + 0x1p-1000);
        dt[q] += sg * (0x1p-40 * fabs(dt[q]) + 0x1p-1000);
    }
    return true;
}

void tex_lipschitz(const tex_texture *t, int c, double *ls, double *lt)
{
    bool have = c >= 0 && c < t->nch;
    *ls = have ? t->lips[c] : 0.0;
    *lt = have ? t->lipt[c] : 0.0;
}

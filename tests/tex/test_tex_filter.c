/*
 * tests/tex/test_tex_filter.c: the texture filter and its bound
 * (common/tex/filter.c).
 *
 *  - at level 0 (zero footprint) the filter equals a bilinear lookup
 *    written here from scratch (texel centres at (i + 1/2) / W, the three
 *    wrap modes), at random points including far outside [0, 1];
 *  - the bound of random (s, t, footprint) ranges, on random textures of
 *    odd and even sizes, contains the filter at dense samples of the range
 *    (ends, corners, random points), for every wrap mode, including ranges
 *    across the periodic seam and footprints that blend levels;
 *  - the bound is tight where it can be: a point range at a texel centre
 *    stays within the texels around it; a huge footprint gives the mean
 *    of the image; all lookups give the min and max of the texels;
 *  - tex_cells: inside one cell (of one level, or of the two levels a
 *    footprint blends) the weighted bilinear forms are the filter;
 *  - inside one cell the bound converges: 1000 times smaller ranges give
 *    bounds at least 100 times narrower;
 *  - the derivative bounds (tex_lipschitz) hold for difference quotients
 *    and for the filter's own derivatives at every sampled point;
 *  - the slope bounds over a range (tex_slopes) hold the difference
 *    quotients between any two points of the range along s and along t
 *    (so the filter is continuous there: across cells, seams and black
 *    or clamped edges) and its derivatives, for a fixed footprint and for
 *    any fixed footprint of a width range (fixed_widths); a point range's
 *    bound is the derivative there, and no bound is looser than the
 *    global one.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "tex/tex.h"

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}
static double range(double lo, double hi) { return lo + (hi - lo) * uniform(); }

static tex_texture *random_texture(int w, int h, int nch, float **pixels)
{
    float *px = malloc((size_t)w * h * nch * sizeof *px);
    for (int k = 0; k < w * h * nch; k++)
        px[k] = (float)range(-1.0, 3.0);
    tex_texture *t = tex_from_pixels(px, w, h, nch, "random");
    *pixels = px;
    return t;
}

/* the independent lookup: level 0, bilinear, wrap per axis */
static double texel_of(const float *px, int w, int h, int nch, int c, long i, long j,
                       tex_wrap sw, tex_wrap tw)
{
    if (sw == TEX_WRAP_PERIODIC)
        i = ((i % w) + w) % w;
    else if (sw == TEX_WRAP_CLAMP)
        i = i < 0 ? 0 : i >= w ? w - 1 : i;
    else if (i < 0 || i >= w)
        return 0.0;
    if (tw == TEX_WRAP_PERIODIC)
        j = ((j % h) + h) % h;
    else if (tw == TEX_WRAP_CLAMP)
        j = j < 0 ? 0 : j >= h ? h - 1 : j;
    else if (j < 0 || j >= h)
        return 0.0;
    return px[((size_t)j * w + (size_t)i) * nch + c];
}

static double reference(const float *px, int w, int h, int nch, int c, double s, double t,
                        tex_wrap sw, tex_wrap tw)
{
    double x = s * w - 0.5, y = t * h - 0.5;
    double fi = floor(x), fj = floor(y), a = x - fi, b = y - fj;
    long i = (long)fi, j = (long)fj;
    return (1 - a) * (1 - b) * texel_of(px, w, h, nch, c, i, j, sw, tw) +
           a * (1 - b) * texel_of(px, w, h, nch, c, i + 1, j, sw, tw) +
           (1 - a) * b * texel_of(px, w, h, nch, c, i, j + 1, sw, tw) +
           a * b * texel_of(px, w, h, nch, c, i + 1, j + 1, sw, tw);
}

static void test_level0_is_bilinear(void **state)
{
    (void)state;
    static const int sizes[][2] = { { 1, 1 }, { 2, 3 }, { 7, 5 }, { 16, 16 }, { 33, 9 } };
    for (size_t n = 0; n < sizeof sizes / sizeof sizes[0]; n++) {
        float *px;
        int w = sizes[n][0], h = sizes[n][1];
        tex_texture *t = random_texture(w, h, 2, &px);
        for (int k = 0; k < 4000; k++) {
            tex_wrap sw = (tex_wrap)(k % 3), tw = (tex_wrap)((k / 3) % 3);
            double s = range(-2.5, 3.5), tt = range(-2.5, 3.5);
            int c = k % 2;
            double want = reference(px, w, h, 2, c, s, tt, sw, tw);
            double got = tex_sample(t, c, s, tt, 0, 0, sw, tw, 0, NULL, NULL);
            if (fabs(got - want) > 1e-9 * (1 + fabs(want)))
                fail_msg("%dx%d c%d wrap %d/%d at (%.17g, %.17g): %.17g, bilinear %.17g", w,
                         h, c, sw, tw, s, tt, got, want);
        }
        assert_true(tex_sample(t, 5, 0.3, 0.3, 0, 0, TEX_WRAP_CLAMP, TEX_WRAP_CLAMP, 0.25,
                               NULL, NULL) == 0.25);         /* missing channel: fill */
        for (int k = 0; k < 3; k++) {                       /* non-finite: 0, bounded */
            double bad = k == 0 ? INFINITY : k == 1 ? -INFINITY : NAN, lo, hi;
            assert_true(tex_sample(t, 0, bad, 0.3, 0, 0, (tex_wrap)k, (tex_wrap)k, 0, NULL,
                                   NULL) == 0.0);
            tex_range r = { { 0.1, k == 2 ? NAN : INFINITY }, { 0.2, 0.3 }, { 0, 0 }, { 0, 0 } };
            tex_bound(t, 0, &r, (tex_wrap)k, (tex_wrap)k, 0, &lo, &hi);
            assert_true(lo <= 0 && hi >= 0);
        }
        tex_destroy(&t);
        free(px);
    }
}

static void check_range(const tex_texture *t, int c, const tex_range *r, tex_wrap sw,
                        tex_wrap tw, long *checked)
{
    double lo, hi;
    tex_bound(t, c, r, sw, tw, 0.0, &lo, &hi);
    assert_true(lo <= hi);
    for (int k = 0; k < 60; k++) {
        double a = k < 4 ? (k & 1) : uniform(), b = k < 4 ? (k >> 1) : uniform();
        double e = k % 5 == 0 ? 0 : uniform(), f = k % 7 == 0 ? 1 : uniform();
        double s = r->s[0] + a * (r->s[1] - r->s[0]), tt = r->t[0] + b * (r->t[1] - r->t[0]);
        double ws = r->ws[0] + e * (r->ws[1] - r->ws[0]);
        double wt = r->wt[0] + f * (r->wt[1] - r->wt[0]);
        double v = tex_sample(t, c, s, tt, ws, wt, sw, tw, 0, NULL, NULL);
        if (!(v >= lo && v <= hi))
            fail_msg("%dx%d wrap %d/%d: filter at s %.17g t %.17g ws %g wt %g = %.17g outside "
                     "the bound [%.17g, %.17g] of s [%.17g, %.17g] t [%.17g, %.17g] ws [%g, %g] "
                     "wt [%g, %g]", tex_width(t), tex_height(t), sw, tw, s, tt, ws, wt, v, lo,
                     hi, r->s[0], r->s[1], r->t[0], r->t[1], r->ws[0], r->ws[1], r->wt[0],
                     r->wt[1]);
        (*checked)++;
    }
}

static void random_range(tex_range *r, int w, int h)
{
    int kind = (int)(uniform() * 5);
    double c = range(-1.5, 2.5), d = range(-1.5, 2.5);
    double span = kind == 0 ? 0 : kind == 1 ? range(0, 1.0 / w) : kind == 2 ? range(0, 0.2)
                : kind == 3 ? range(0, 1.5) : range(0, 3.0 / w);
    if (uniform() < 0.3)
        c = floor(c) + range(-2.0 / w, 2.0 / w);           /* across the seam */
    r->s[0] = c;
    r->s[1] = c + span;
    double tspan = uniform() < 0.5 ? span : range(0, 0.3);
    r->t[0] = d;
    r->t[1] = d + tspan;
    double wmax = uniform() < 0.4 ? 0 : uniform() < 0.5 ? range(0, 4.0 / w) : range(0, 1.2);
    r->ws[0] = uniform() < 0.5 ? wmax : range(0, wmax);
    r->ws[1] = wmax;
    r->wt[0] = r->ws[0] * (double)w / h;
    r->wt[1] = r->ws[1] * (uniform() < 0.5 ? 1.0 : 0.3);
    if (r->wt[0] > r->wt[1])
        r->wt[0] = r->wt[1];
}

static void test_bound_contains_filter(void **state)
{
    (void)state;
    static const int sizes[][2] = { { 1, 1 }, { 3, 2 }, { 8, 8 }, { 13, 31 }, { 64, 40 } };
    long checked = 0;
    for (size_t n = 0; n < sizeof sizes / sizeof sizes[0]; n++) {
        float *px;
        int w = sizes[n][0], h = sizes[n][1];
        tex_texture *t = random_texture(w, h, 3, &px);
        for (int k = 0; k < 3000; k++) {
            tex_range r;
            random_range(&r, w, h);
            check_range(t, k % 3, &r, (tex_wrap)(k % 3), (tex_wrap)((k / 3) % 3), &checked);
        }
        tex_destroy(&t);
        free(px);
    }
    assert_true(checked > 500000);
}

/* Ranges over bilinear cells (1.5 to 3.5 texels of level 0 or 1, or
 * exactly 1 to 3 whole cells; no blend): the bound holds the filter at
 * every texel centre of the level inside the range, where the filter is
 * that texel. Random samples seldom land on a texel, which is where a
 * whole cell's bound (its four texels, filter.c) takes its extremes. */
static void test_bound_holds_texels(void **state)
{
    (void)state;
    static const int sizes[][2] = { { 8, 8 }, { 13, 31 }, { 64, 32 } };
    long checked = 0;
    for (size_t n = 0; n < sizeof sizes / sizeof sizes[0]; n++) {
        float *px;
        int w = sizes[n][0], h = sizes[n][1];
        tex_texture *t = random_texture(w, h, 2, &px);
        for (int k = 0; k < 4000; k++) {
            int lv = k % 2, lw = lv == 0 ? w : (w + 1) / 2, lh = lv == 0 ? h : (h + 1) / 2;
            double ws = lv == 0 ? 0.0 : 2.0 / w, wt = lv == 0 ? 0.0 : 2.0 / h;
            if (lv == 1 && (w < 2 || h < 2))
                continue;
            tex_wrap sw = (tex_wrap)(k / 2 % 3), tw = (tex_wrap)(k / 6 % 3);
            double s0 = range(-0.5, 1.5), t0 = range(-0.5, 1.5);
            tex_range r = { { s0, s0 + range(1.5, 3.5) / lw }, { t0, t0 + range(1.5, 3.5) / lh },
                            { ws, ws }, { wt, wt } };
            if (k % 4 >= 2) {
                /* from texel centre to texel centre (exact in binary for
                 * the power-of-two sizes): 1 to 3 whole cells, no part
                 * of a neighbour around them */
                r.s[0] = (floor(range(-4, lw + 4)) + 0.5) / lw;
                r.s[1] = r.s[0] + (double)(1 + k / 4 % 3) / lw;
                r.t[0] = (floor(range(-4, lh + 4)) + 0.5) / lh;
                r.t[1] = r.t[0] + (double)(1 + k / 12 % 3) / lh;
            }
            double lo, hi;
            tex_bound(t, k % 2, &r, sw, tw, 0.0, &lo, &hi);
            for (long j = (long)floor(r.t[0] * lh - 0.5); j <= (long)ceil(r.t[1] * lh); j++)
                for (long i = (long)floor(r.s[0] * lw - 0.5); i <= (long)ceil(r.s[1] * lw); i++) {
                    double s = (i + 0.5) / lw, tt = (j + 0.5) / lh;
                    if (s < r.s[0] || s > r.s[1] || tt < r.t[0] || tt > r.t[1])
                        continue;
                    double v = tex_sample(t, k % 2, s, tt, ws, wt, sw, tw, 0, NULL, NULL);
                    if (!(v >= lo && v <= hi))
                        fail_msg("%dx%d level %d wrap %d/%d: the texel at s %.17g t %.17g = "
                                 "%.17g outside the bound [%.17g, %.17g] of s [%.17g, %.17g] "
                                 "t [%.17g, %.17g]", w, h, lv, sw, tw, s, tt, v, lo, hi,
                                 r.s[0], r.s[1], r.t[0], r.t[1]);
                    checked++;
                }
        }
        tex_destroy(&t);
        free(px);
    }
    assert_true(checked > 20000);
}

static void test_bound_is_tight(void **state)
{
    (void)state;
    float *px;
    tex_texture *t = random_texture(16, 8, 1, &px);
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 16; i++) {
            tex_range r = { { (i + 0.5) / 16, (i + 0.5) / 16 }, { (j + 0.5) / 8, (j + 0.5) / 8 },
                            { 0, 0 }, { 0, 0 } };
            double lo, hi;
            tex_bound(t, 0, &r, TEX_WRAP_CLAMP, TEX_WRAP_CLAMP, 0, &lo, &hi);
            /* the widening by 1e-9 takes in the neighbours: at most the 3x3 block */
            double mn = INFINITY, mx = -INFINITY;
            for (int b = -1; b <= 1; b++)
                for (int a = -1; a <= 1; a++) {
                    double v = texel_of(px, 16, 8, 1, 0, i + a, j + b, TEX_WRAP_CLAMP,
                                        TEX_WRAP_CLAMP);
                    mn = fmin(mn, v);
                    mx = fmax(mx, v);
                }
            assert_true(lo >= mn && hi <= mx);
            assert_true(lo <= px[j * 16 + i] && hi >= px[j * 16 + i]);
        }
    /* a huge footprint reads the top level, the mean of all texels: the
     * bound is that mean; footprints from 0 to huge: the min and max */
    double mn = INFINITY, mx = -INFINITY, mean = 0;
    for (int k = 0; k < 128; k++) {
        mn = fmin(mn, px[k]);
        mx = fmax(mx, px[k]);
        mean += px[k] / 128.0;
    }
    tex_range all = { { 0.2, 0.3 }, { 0.2, 0.3 }, { 10, 10 }, { 10, 10 } };
    double lo, hi;
    tex_bound(t, 0, &all, TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0, &lo, &hi);
    assert_true(lo <= mean + 1e-6 && hi >= mean - 1e-6 && hi - lo < 1e-6);
    tex_range any = { { 0, 1 }, { 0, 1 }, { 0, 10 }, { 0, 10 } };
    tex_bound(t, 0, &any, TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0, &lo, &hi);
    assert_true(lo == mn && hi == mx);
    tex_destroy(&t);
    free(px);
}

static void test_cells_are_the_filter(void **state)
{
    (void)state;
    float *px;
    tex_texture *t = random_texture(9, 6, 1, &px);
    int found[3] = { 0, 0, 0 };
    for (int k = 0; k < 4000; k++) {
        tex_wrap sw = (tex_wrap)(k % 3), tw = (tex_wrap)((k / 3) % 3);
        double s = range(-1.2, 2.2), tt = range(-1.2, 2.2);
        double w = k % 2 ? 0 : range(0, 0.4);         /* level 0, or a blend */
        tex_range r = { { s, s + range(0, 0.02) }, { tt, tt + range(0, 0.03) }, { w, w },
                        { w, w } };
        tex_cell cells[2];
        int n = tex_cells(t, 0, &r, sw, tw, cells);
        found[n]++;
        if (n == 0)
            continue;
        for (int q = 0; q < 10; q++) {
            double ss = range(r.s[0], r.s[1]), ts = range(r.t[0], r.t[1]), want = 0;
            for (int c = 0; c < n; c++) {
                const tex_cell *e = &cells[c];
                double fx = ss * e->w - 0.5 - e->oi, fy = ts * e->h - 0.5 - e->oj;
                assert_true(fx >= -1e-12 && fx <= 1 + 1e-12 && fy >= -1e-12 && fy <= 1 + 1e-12);
                want += e->weight * (e->v[0] + (e->v[1] - e->v[0]) * fx +
                                     (e->v[2] - e->v[0]) * fy +
                                     (e->v[3] - e->v[2] - e->v[1] + e->v[0]) * fx * fy);
            }
            double got = tex_sample(t, 0, ss, ts, w, w, sw, tw, 0, NULL, NULL);
            assert_true(fabs(got - want) < 1e-9);
        }
    }
    assert_true(found[1] > 100 && found[2] > 100);
    /* a varying footprint gives no single form */
    tex_range vary = { { 0.5, 0.5 }, { 0.5, 0.5 }, { 0.1, 0.2 }, { 0.1, 0.2 } };
    tex_cell cells[2];
    assert_int_equal(tex_cells(t, 0, &vary, TEX_WRAP_CLAMP, TEX_WRAP_CLAMP, cells), 0);
    tex_destroy(&t);
    free(px);
}

/* The bound shrinks with the range (the subdivision of a ray tracer
 * converges): a range 1000 times smaller gives a bound at least 100 times
 * narrower, at level 0 and in a blend of two levels, inside a cell and
 * across a cell edge. */
static void test_bound_converges(void **state)
{
    (void)state;
    float *px;
    tex_texture *t = random_texture(16, 16, 1, &px);
    for (int k = 0; k < 500; k++) {
        double s = range(0.1, 0.9), tt = range(0.1, 0.9), w = k % 2 ? 0 : 0.09;
        if (k % 3 == 0)                   /* straddling a cell edge (a texel centre) */
            s = (floor(s * 16) + 0.5) / 16 - 5e-7;
        tex_range big = { { s, s + 1e-3 }, { tt, tt + 1e-3 }, { w, w }, { w, w } };
        tex_range small = { { s, s + 1e-6 }, { tt, tt + 1e-6 }, { w, w }, { w, w } };
        double l0, h0, l1, h1;
        tex_bound(t, 0, &big, TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0, &l0, &h0);
        tex_bound(t, 0, &small, TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0, &l1, &h1);
        if (h0 - l0 > 1e-6)
            assert_true((h1 - l1) * 100 <= h0 - l0);
    }
    tex_destroy(&t);
    free(px);
}

static void test_lipschitz(void **state)
{
    (void)state;
    float *px;
    tex_texture *t = random_texture(12, 7, 1, &px);
    double ls, lt;
    tex_lipschitz(t, 0, &ls, &lt);
    assert_true(ls > 0 && lt > 0);
    for (int k = 0; k < 20000; k++) {
        tex_wrap sw = (tex_wrap)(k % 3), tw = (tex_wrap)((k / 3) % 3);
        double s = range(-1.5, 2.5), tt = range(-1.5, 2.5), w = range(0, 0.5) * (k % 2);
        double ds, dt;
        double v = tex_sample(t, 0, s, tt, w, w, sw, tw, 0, &ds, &dt);
        assert_true(fabs(ds) <= ls * (1 + 1e-12) && fabs(dt) <= lt * (1 + 1e-12));
        double h = 1e-4;
        double v2 = tex_sample(t, 0, s + h, tt, w, w, sw, tw, 0, NULL, NULL);
        assert_true(fabs(v2 - v) <= ls * h * (1 + 1e-9) + 1e-12);
    }
    tex_destroy(&t);
    free(px);
}

/* f(b) - f(a) over b - a, along s (axis 0) or t, at footprint w */
static double quotient(const tex_texture *t, int axis, double s, double tt, double h, double w,
                       tex_wrap sw, tex_wrap tw, double *err)
{
    double a = tex_sample(t, 0, s, tt, w, w, sw, tw, 0, NULL, NULL);
    double b = axis ? tex_sample(t, 0, s, tt + h, w, w, sw, tw, 0, NULL, NULL)
                    : tex_sample(t, 0, s + h, tt, w, w, sw, tw, 0, NULL, NULL);
    /* the lookups' own rounding, over h */
    *err = 1e-12 * (fabs(a) + fabs(b) + 1.0) / fabs(h);
    return (b - a) / h;
}

static void test_slopes(void **state)
{
    (void)state;
    static const int sizes[][2] = { { 1, 1 }, { 5, 3 }, { 16, 16 }, { 37, 20 } };
    long checked = 0, refused = 0, points = 0;
    for (size_t n = 0; n < sizeof sizes / sizeof sizes[0]; n++) {
        float *px;
        int W = sizes[n][0], H = sizes[n][1];
        tex_texture *t = random_texture(W, H, 1, &px);
        double ls, lt;
        tex_lipschitz(t, 0, &ls, &lt);
        for (int k = 0; k < 4000; k++) {
            tex_wrap sw = (tex_wrap)(k % 3), tw = (tex_wrap)((k / 3) % 3);
            bool fixed = k % 4 == 3;
            double c = range(-1.5, 2.5), d = range(-1.5, 2.5);
            if (uniform() < 0.3)
                c = floor(c) + range(-2.0 / W, 2.0 / W);   /* across the seam */
            double span = uniform() < 0.1 ? 0.0 : range(0, 6.0 / W);
            double tspan = span == 0.0 ? 0.0 : range(0, 6.0 / H);
            double w0 = uniform() < 0.4 ? 0.0 : range(0, 4.0 / W);
            double w1 = fixed ? w0 * (1 + range(0, 0.01)) : w0;
            tex_range r = { { c, c + span }, { d, d + tspan }, { w0, w1 }, { w0, w1 } };
            double ds[2], dt[2];
            if (!tex_slopes(t, 0, &r, sw, tw, fixed, ds, dt)) {
                refused++;
                continue;
            }
            assert_true(ds[0] <= ds[1] && dt[0] <= dt[1]);
            if (!(ds[1] - ds[0] <= 2 * ls * (1 + 1e-8) + 1e-300 &&
                  dt[1] - dt[0] <= 2 * lt * (1 + 1e-8) + 1e-300))
                fail_msg("%dx%d wrap %d/%d: ds [%.17g, %.17g] dt [%.17g, %.17g] looser than the "
                         "global %.17g, %.17g", W, H, sw, tw, ds[0], ds[1], dt[0], dt[1], ls, lt);
            for (int q = 0; q < 20; q++) {
                double w = w0 + uniform() * (w1 - w0);    /* one footprint for the range */
                double sa = c + uniform() * span, sb = c + uniform() * span;
                double ta = d + uniform() * tspan, tb = d + uniform() * tspan;
                double g[2];
                tex_sample(t, 0, sa, ta, w, w, sw, tw, 0, &g[0], &g[1]);
                if (span == 0.0 && w0 == w1) {
                    /* a point: the bound is the derivative there (off
                     * the cells' edges, where random doubles fall) */
                    assert_true(ds[1] - ds[0] <= 1e-6 * (ls + 1) && dt[1] - dt[0] <= 1e-6 * (lt + 1));
                    points++;
                }
                if (!(g[0] >= ds[0] - 1e-9 * (fabs(g[0]) + 1) && g[0] <= ds[1] + 1e-9 * (fabs(g[0]) + 1) &&
                      g[1] >= dt[0] - 1e-9 * (fabs(g[1]) + 1) && g[1] <= dt[1] + 1e-9 * (fabs(g[1]) + 1)))
                    fail_msg("%dx%d wrap %d/%d: derivative (%.17g, %.17g) at s %.17g t %.17g w %g "
                             "outside ds [%.17g, %.17g] dt [%.17g, %.17g]", W, H, sw, tw, g[0],
                             g[1], sa, ta, w, ds[0], ds[1], dt[0], dt[1]);
                for (int axis = 0; axis < 2 && span > 0; axis++) {
                    double a0 = axis ? ta : sa, a1 = axis ? tb : sb;
                    double h = a1 - a0;
                    if (!(fabs(h) > 1e-4 * (axis ? tspan : span)))
                        continue;
                    double err, qv = quotient(t, axis, axis ? sa : a0, axis ? a0 : ta, h, w,
                                              sw, tw, &err);
                    const double *b = axis ? dt : ds;
                    if (!(qv >= b[0] - err && qv <= b[1] + err))
                        fail_msg("%dx%d wrap %d/%d axis %d: quotient %.17g from %.17g over "
                                 "%.17g (w %g) outside [%.17g, %.17g]", W, H, sw, tw, axis, qv,
                                 a0, h, w, b[0], b[1]);
                    checked++;
                }
            }
        }
        tex_destroy(&t);
        free(px);
    }
    assert_true(checked > 100000);
    assert_true(points > 1000);
    assert_true(refused < 4000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_level0_is_bilinear),
        cmocka_unit_test(test_bound_contains_filter),
        cmocka_unit_test(test_bound_holds_texels),
        cmocka_unit_test(test_bound_is_tight),
        cmocka_unit_test(test_cells_are_the_filter),
        cmocka_unit_test(test_bound_converges),
        cmocka_unit_test(test_lipschitz),
        cmocka_unit_test(test_slopes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

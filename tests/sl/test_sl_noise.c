/*
 * tests/sl/test_sl_noise.c: the noise functions of common/sl (noise.h).
 *
 *   lattice         noise is exactly 0.5 at every integer lattice point, and
 *                   its gradient there (divided by the scale) is a member of
 *                   the documented gradient set
 *   reconstruction  the value at a random point equals Perlin's improved
 *                   noise (Perlin 2002) rebuilt here, in long double, from
 *                   the gradients read off at the cell's corners
 *   gradient        sl_noise_grad against central finite differences
 *   range           millions of random points: every variant within [0, 1]
 *   certificate     branch-and-bound with interval arithmetic proving the
 *                   global bounds B_3, B_4 of |raw noise| used by noise.c
 *                   (B_1, B_2 have short proofs: noise.c, docs/noise.md)
 *   periodic        pnoise repeats with its integer periods; periods <= 0
 *                   give noise
 *   cellnoise       constant in a cell, in [0, 1), a multiple of 2^-24; the
 *                   interval/affine versions are the hull, flagged
 *   determinism     the same samples in another order and through other
 *                   entry points give the same bits; channels uncorrelated
 *   float accuracy  the float result against the rigorous point enclosure
 *   containment     tens of thousands of random boxes in 1-4D (tiny, one
 *                   cell, two cells, many cells, next to lattice planes):
 *                   dense samples lie inside the interval result and inside
 *                   the affine result evaluated at the samples' noise
 *                   symbol values
 *   box methods     the Taylor model, the interval jets and the rule that
 *                   picks between them, each alone: values and gradients
 *                   sampled in boxes of sides 1e-9 .. 2 (some across
 *                   lattice planes) inside the results; the float jet's
 *                   error table against its derivation; widths
 *   tightness       affine never wider than interval, interval narrower
 *                   than the interval jets alone on small boxes; affine
 *                   close to the true range on 1e-3 boxes
 *   correlation     noise(P) - noise(P) is small in affine arithmetic, and
 *                   P + N*noise(P) keeps its dependence on u and v
 *   special inputs  NaN, infinities, unbounded forms, invalid dims
 *
 * Random inputs come from a fixed-seed splitmix64 generator.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "aa/rounding.h"
#include "sl/noise.h"
#include "test_rng.h"

_Static_assert(LDBL_MANT_DIG >= 64, "the reconstruction needs an extended long double");

/*
 * TOL: a bound on |fl(noise(x)) - noise(x)|, the float evaluation's own
 * rounding (u = 2^-53):
 *   f = x - floor(x) errs by at most u (|f| <= 1), moving the exact noise
 *     by at most D * sup|dN/df_k| * u <= 4 * 19 * u (sup|d raw/df_k| <=
 *     2 max s' * max|g.d| + max|g| <= 3.75*8 + 8 = 38 and K <= 1/2);
 *   each corner dot product (<= 2D operations on values <= 8) errs by at
 *     most 100u; the fade by at most 16u; each of the D levels of linear
 *     interpolation a + s(b - a) (|a|, |b| <= 8) adds at most
 *     |b - a| * 16u + 3 * 16u <= 304u to the error it carries;
 *   0.5 + K*raw adds 2u and halves the rest.
 * In all fewer than 1000u ~ 1.1e-13. TOL = 2^-40 = 8192u leaves a factor 8,
 * and test_float_accuracy checks the float result against the rigorous
 * point enclosure of the interval mode with it on every run.
 */
#define TOL 0x1p-40

/* ---- a small fixed-seed generator (splitmix64) ---- */

static uint64_t rng_state = 0x5eed1234abcdef01u;

static uint64_t rng_next(void)
{
    return test_rng_next(&rng_state);
}

static void rng_seed(uint64_t s) { rng_state = s; }

/* uniform in [0, 1) */
static double urand(void) { return (double)(rng_next() >> 11) * 0x1p-53; }
static double urange(double a, double b) { return a + (b - a) * urand(); }
static int irange(int a, int b)
{
    return (int)((int64_t)a + (int64_t)(rng_next() % (uint64_t)((int64_t)b - a + 1)));
}

static double now_s(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---------------------------------------------------------------------- */
/* lattice points and the gradient set                                    */
/* ---------------------------------------------------------------------- */

/* Is g (integers) a member of the documented gradient set of dim? */
static int in_gradient_set(int dim, const long g[4])
{
    int zeros = 0, ones = 0;
    if (dim == 1)
        return g[0] != 0 && labs(g[0]) <= 8;
    for (int k = 0; k < dim; k++) {
        if (g[k] == 0)
            zeros++;
        else if (labs(g[k]) == 1)
            ones++;
        else
            return 0;
    }
    switch (dim) {
    case 2: return ones >= 1;                 /* (+-1,+-1), (+-1,0), (0,+-1) */
    case 3: return ones == 2 && zeros == 1;
    default: return ones == 3 && zeros == 1;
    }
}

/* The gradient hashed to lattice point p (integers), read off the noise's
 * derivative there: d raw / dx = g at a lattice point. */
static void lattice_gradient(int dim, const double *p, long g[4], double *worst)
{
    double grad[4];
    double v = sl_noise_grad(dim, p, NULL, grad);
    assert_true(v == 0.5);
    for (int k = 0; k < dim; k++) {
        double x = grad[k] / sl_noise_scale(dim);
        g[k] = lround(x);
        double e = fabs(x - (double)g[k]);
        if (e > *worst)
            *worst = e;
    }
}

static void test_lattice(void **state)
{
    (void)state;
    rng_seed(1);
    long seen[5][81] = { { 0 } };
    long points = 0, off_grid = 0;
    double worst = 0.0;
    for (int dim = 1; dim <= 4; dim++) {
        for (int n = 0; n < 20000; n++) {
            double p[4];
            int per[4];
            for (int k = 0; k < dim; k++) {
                int scale = n % 3 == 0 ? 20 : (n % 3 == 1 ? 100000 : 1 << 30);
                p[k] = (double)irange(-scale, scale);
                per[k] = irange(-1, 7);
            }
            double v3[3];
            assert_true(sl_noise(dim, p) == 0.5);
            assert_true(sl_pnoise(dim, p, per) == 0.5);
            sl_vnoise(dim, p, v3);
            for (int i = 0; i < 3; i++)
                assert_true(v3[i] == 0.5);
            long g[4];
            lattice_gradient(dim, p, g, &worst);
            if (!in_gradient_set(dim, g))
                off_grid++;
            /* which member: encode components in base 3 (1D: 16 values) */
            int code = 0;
            for (int k = 0; k < dim; k++)
                code = dim == 1 ? (int)(g[0] + 8) : code * 3 + (int)(g[k] + 1);
            if (code >= 0 && code < 81)
                seen[dim][code]++;
            points++;
        }
    }
    /* huge integers: still lattice points */
    for (int n = 0; n < 100; n++) {
        double p[4] = { 0x1p52 * irange(1, 1000), -0x1p60, 0x1p61 + 0x1p40 * n, 3.0 };
        assert_true(sl_noise(4, p) == 0.5);
        assert_true(sl_noise(1, p) == 0.5);
    }
    int members[5] = { 0 };
    for (int dim = 1; dim <= 4; dim++)
        for (int c = 0; c < 81; c++)
            members[dim] += seen[dim][c] > 0;
    printf("lattice: %ld points exactly 0.5; gradients off the set: %ld; "
           "worst |grad/K - integer| %.3g; set members seen 1D..4D: %d %d %d %d "
           "(of 16 8 12 32)\n", points, off_grid, worst, members[1], members[2],
           members[3], members[4]);
    assert_int_equal(off_grid, 0);
    assert_true(worst < 1e-12);
    assert_int_equal(members[1], 16);
    assert_int_equal(members[2], 8);
    assert_int_equal(members[3], 12);
    assert_int_equal(members[4], 32);
}

/* ---------------------------------------------------------------------- */
/* reconstruction from the corner gradients, and finite differences        */
/* ---------------------------------------------------------------------- */

static long double fade_l(long double t)
{
    return t * t * t * (t * (t * 6 - 15) + 10);
}

static void test_reconstruction(void **state)
{
    (void)state;
    rng_seed(2);
    long cases = 0;
    double worst = 0.0, worst_grad = 0.0;
    for (int dim = 1; dim <= 4; dim++) {
        for (int n = 0; n < 3000; n++) {
            double p[4], base[4];
            long double f[4];
            for (int k = 0; k < dim; k++) {
                p[k] = urange(-300.0, 300.0);
                base[k] = floor(p[k]);
                f[k] = (long double)p[k] - (long double)base[k];
            }
            long double raw = 0.0L;
            for (int c = 0; c < (1 << dim); c++) {
                double q[4];
                long g[4];
                for (int k = 0; k < dim; k++)
                    q[k] = base[k] + ((c >> k) & 1);
                lattice_gradient(dim, q, g, &worst_grad);
                assert_true(in_gradient_set(dim, g));
                long double W = 1.0L, dot = 0.0L;
                for (int k = 0; k < dim; k++) {
                    int b = (c >> k) & 1;
                    long double s = fade_l(f[k]);
                    W *= b ? s : 1.0L - s;
                    dot += (long double)g[k] * (f[k] - b);
                }
                raw += W * dot;
            }
            long double ref = 0.5L + (long double)sl_noise_scale(dim) * raw;
            double e = (double)fabsl((long double)sl_noise(dim, p) - ref);
            if (e > worst)
                worst = e;
            cases++;
        }
    }
    printf("reconstruction: %ld points, max |noise - Perlin formula| %.3g "
           "(tolerance %.3g)\n", cases, worst, TOL);
    assert_true(worst <= TOL);
}

static void test_gradient(void **state)
{
    (void)state;
    rng_seed(3);
    long cases = 0, bad = 0;
    double worst = 0.0;
    const double h = 1e-6;
    for (int dim = 1; dim <= 4; dim++) {
        for (int n = 0; n < 5000; n++) {
            double p[4], grad[4];
            for (int k = 0; k < dim; k++) {
                do
                    p[k] = urange(-100.0, 100.0);
                while (fabs(p[k] - nearbyint(p[k])) < 1e-4);
            }
            double v = sl_noise_grad(dim, p, NULL, grad);
            assert_true(v == sl_noise(dim, p));
            for (int k = 0; k < dim; k++) {
                double a[4], b[4];
                memcpy(a, p, sizeof a);
                memcpy(b, p, sizeof b);
                a[k] += h;
                b[k] -= h;
                double fd = (sl_noise(dim, a) - sl_noise(dim, b)) / (2.0 * h);
                double e = fabs(fd - grad[k]);
                if (e > worst)
                    worst = e;
                if (e > 1e-6)
                    bad++;
            }
            cases++;
        }
        /* sl_noise3_grad is the same */
        double p3[3] = { 0.3, -1.7, 2.25 }, g1[3], g2[3];
        if (dim == 3) {
            assert_true(sl_noise3_grad(p3, g1) == sl_noise_grad(3, p3, NULL, g2));
            assert_memory_equal(g1, g2, sizeof g1);
        }
    }
    printf("gradient: %ld points, max |grad - finite difference| %.3g, bad %ld\n",
           cases, worst, bad);
    assert_int_equal(bad, 0);
}

/*
 * The derivative bounds behind the sliver merge (noise.c): sampled first,
 * second and third partials of raw noise (the gradient exact, the rest by
 * central differences of the gradient inside a cell) stay below them.
 */
static void test_derivative_bounds(void **state)
{
    (void)state;
    rng_seed(31);
    const double h = 1e-4;
    double worst[4] = { 0 };
    for (int dim = 1; dim <= 4; dim++) {
        double K = sl_noise_scale(dim);
        for (int n = 0; n < 20000; n++) {
            double p[4], g0[4], gp[4], gm[4];
            for (int k = 0; k < dim; k++) {
                do
                    p[k] = urange(-50.0, 50.0);
                while (fabs(p[k] - nearbyint(p[k])) < 4.0 * h);
            }
            sl_noise_grad(dim, p, NULL, g0);
            for (int k = 0; k < dim; k++)
                if (fabs(g0[k] / K) > worst[1])
                    worst[1] = fabs(g0[k] / K);
            for (int j = 0; j < dim; j++) {
                double a[4], b[4];
                memcpy(a, p, sizeof a);
                memcpy(b, p, sizeof b);
                a[j] += h;
                b[j] -= h;
                sl_noise_grad(dim, a, NULL, gp);
                sl_noise_grad(dim, b, NULL, gm);
                for (int k = 0; k < dim; k++) {
                    double d2 = (gp[k] - gm[k]) / (2.0 * h) / K;
                    double d3 = (gp[k] - 2.0 * g0[k] + gm[k]) / (h * h) / K;
                    if (fabs(d2) > worst[2]) worst[2] = fabs(d2);
                    if (fabs(d3) > worst[3]) worst[3] = fabs(d3);
                }
            }
        }
    }
    for (int order = 1; order <= 3; order++) {
        double bound = sl_noise_raw_derivative_bound(order);
        printf("derivative bounds: order %d: sampled max %.4g, bound %.4g (%.0f%%)\n", order,
               worst[order], bound, 100.0 * worst[order] / bound);
        assert_true(worst[order] <= bound);
        assert_true(worst[order] > 0.0);
    }
}

/* ---------------------------------------------------------------------- */
/* range                                                                   */
/* ---------------------------------------------------------------------- */

static void test_range(void **state)
{
    (void)state;
    rng_seed(4);
    long points = 0, outside = 0;
    double lo[5] = { 1, 1, 1, 1, 1 }, hi[5] = { 0 };
    double t0 = now_s();
    for (int dim = 1; dim <= 4; dim++) {
        for (long n = 0; n < 1000000; n++) {
            double p[4], v3[3];
            int per[4];
            double scale = (n & 3) == 0 ? 4.0 : ((n & 3) == 1 ? 1e3 : ((n & 3) == 2 ? 1e9 : 30.0));
            for (int k = 0; k < dim; k++) {
                p[k] = urange(-scale, scale);
                per[k] = irange(-2, 9);
            }
            double v = sl_noise(dim, p);
            if (!(v >= 0.0 && v <= 1.0))
                outside++;
            if (v < lo[dim]) lo[dim] = v;
            if (v > hi[dim]) hi[dim] = v;
            points++;
            if ((n & 7) == 0) {
                double w = sl_pnoise(dim, p, per);
                double c = sl_cellnoise(dim, p);
                sl_vnoise(dim, p, v3);
                if (!(w >= 0.0 && w <= 1.0) || !(c >= 0.0 && c < 1.0))
                    outside++;
                for (int i = 0; i < 3; i++)
                    if (!(v3[i] >= 0.0 && v3[i] <= 1.0))
                        outside++;
                points += 5;
            }
        }
    }
    printf("range: %ld values, %ld outside; observed noise range 1D [%.4f, %.4f] "
           "2D [%.4f, %.4f] 3D [%.4f, %.4f] 4D [%.4f, %.4f] (%.2f s)\n",
           points, outside, lo[1], hi[1], lo[2], hi[2], lo[3], hi[3], lo[4],
           hi[4], now_s() - t0);
    assert_int_equal(outside, 0);
}

/* ---------------------------------------------------------------------- */
/* the global bound: a certificate by branch-and-bound                     */
/* ---------------------------------------------------------------------- */
/*
 * |raw| <= Phi(f) = sum_c W_c(f) gmax top_m(|f - c|) (noise.c), and on
 * S = {0 <= f_1 <= ... <= f_D <= 1/2}, where the maximum of Phi is taken,
 * Phi equals the polynomial P below (fixed "top m" sets). We prove
 * P <= B on S: S is covered by boxes of [0, 1/2]^D (boxes missing S are
 * dropped), each either bounded by B via interval arithmetic (the smaller
 * of the natural extension and the mean-value form P(mid) + sum_k
 * [dP/df_k over box] [-r_k, r_k]) or split in two along its widest axis.
 * Everything is evaluated with common/aa's rounding-safe intervals, and
 * the fade by its monotonicity (s' >= 0): s([a,b]) = [s(a), s(b)].
 */

typedef struct cert_stats {
    long boxes;
    double best_lower;      /* max of P at box midpoints: the bound's slack */
    int failed;
} cert_stats;

static ia_interval ia_fade_pt(double t)
{
    ia_interval x = ia_point(t);
    ia_interval inner = ia_add_s(ia_mul(x, ia_add_s(ia_mul_s(x, 6.0), -15.0)), 10.0);
    return ia_mul(ia_pow_int(x, 3), inner);
}

static ia_interval ia_fade_box(ia_interval F)
{
    return ia_make(ia_fade_pt(F.lo).lo, ia_fade_pt(F.hi).hi);
}

/* s'(t) = 30 (t(1-t))^2 is increasing on [0, 1/2], where all boxes lie */
static ia_interval ia_dfade_pt(double t)
{
    ia_interval x = ia_point(t);
    return ia_mul_s(ia_sqr(ia_mul(x, ia_sub(ia_point(1.0), x))), 30.0);
}

static ia_interval ia_dfade_box(ia_interval F)
{
    return ia_make(ia_dfade_pt(F.lo).lo, ia_dfade_pt(F.hi).hi);
}

/* P and its gradient over the box F (order 1) or at the point (order 0) */
static void cert_eval(int dim, int m, double gmax, const ia_interval *F,
                      int order, ia_interval *val, ia_interval *grad)
{
    ia_interval w[4][2], dw[4][2], a[4][2];
    for (int k = 0; k < dim; k++) {
        ia_interval s = ia_fade_box(F[k]);
        w[k][1] = s;
        w[k][0] = ia_sub(ia_point(1.0), s);
        a[k][0] = F[k];                               /* |f - 0| */
        a[k][1] = ia_sub(ia_point(1.0), F[k]);        /* |f - 1| */
        if (order) {
            dw[k][1] = ia_dfade_box(F[k]);
            dw[k][0] = ia_neg(dw[k][1]);
        }
    }
    *val = ia_point(0.0);
    for (int k = 0; k < dim; k++)
        grad[k] = ia_point(0.0);
    for (int c = 0; c < (1 << dim); c++) {
        /* the m largest |f_k - c_k| on S: c_k = 1 in increasing k, then
         * c_k = 0 in decreasing k */
        int top[4] = { 0 }, taken = 0;
        for (int k = 0; k < dim && taken < m; k++)
            if ((c >> k) & 1) { top[k] = 1; taken++; }
        for (int k = dim - 1; k >= 0 && taken < m; k--)
            if (!((c >> k) & 1)) { top[k] = 1; taken++; }
        ia_interval L = ia_point(0.0), W = ia_point(1.0);
        for (int k = 0; k < dim; k++) {
            int b = (c >> k) & 1;
            if (top[k])
                L = ia_add(L, a[k][b]);
            W = ia_mul(W, w[k][b]);
        }
        L = ia_mul_s(L, gmax);
        *val = ia_add(*val, ia_mul(W, L));
        if (!order)
            continue;
        for (int j = 0; j < dim; j++) {
            int b = (c >> j) & 1;
            ia_interval dW = dw[j][b];
            for (int k = 0; k < dim; k++)
                if (k != j)
                    dW = ia_mul(dW, w[k][(c >> k) & 1]);
            double dL = top[j] ? (b ? -gmax : gmax) : 0.0;
            grad[j] = ia_add(grad[j], ia_add(ia_mul(dW, L), ia_mul_s(W, dL)));
        }
    }
}

static void certify(int dim, int m, double gmax, double B, cert_stats *st)
{
    enum { STACK = 4096 };
    static ia_interval stack[STACK][4];
    int top = 0;
    for (int k = 0; k < dim; k++)
        stack[0][k] = ia_make(0.0, 0.5);
    top = 1;
    st->boxes = 0;
    st->best_lower = 0.0;
    st->failed = 0;
    while (top > 0) {
        ia_interval F[4];
        top--;
        memcpy(F, stack[top], sizeof F);
        st->boxes++;
        /* drop boxes without a sorted point */
        int meets = 1;
        for (int k = 0; k + 1 < dim; k++)
            if (F[k].lo > F[k + 1].hi)
                meets = 0;
        if (!meets)
            continue;
        ia_interval natural, grad[4], mid[4], vmid, g0[4];
        cert_eval(dim, m, gmax, F, 1, &natural, grad);
        double r[4];
        for (int k = 0; k < dim; k++) {
            double c = ia_mid(F[k]);
            mid[k] = ia_point(c);
            r[k] = fmax(fp_add_up(F[k].hi, -c), fp_add_up(c, -F[k].lo));
        }
        cert_eval(dim, m, gmax, mid, 0, &vmid, g0);
        if (vmid.lo > st->best_lower)
            st->best_lower = vmid.lo;
        ia_interval mv = vmid;
        for (int k = 0; k < dim; k++)
            mv = ia_add(mv, ia_mul(grad[k], ia_make(-r[k], r[k])));
        double upper = fmin(natural.hi, mv.hi);
        if (upper <= B)
            continue;
        int widest = 0;
        for (int k = 1; k < dim; k++)
            if (F[k].hi - F[k].lo > F[widest].hi - F[widest].lo)
                widest = k;
        double w = F[widest].hi - F[widest].lo;
        if (w < 1e-9 || top + 2 > STACK || st->boxes > 20000000) {
            st->failed = 1;
            return;
        }
        double c = ia_mid(F[widest]);
        memcpy(stack[top], F, sizeof F);
        stack[top][widest].hi = c;
        top++;
        memcpy(stack[top], F, sizeof F);
        stack[top][widest].lo = c;
        top++;
    }
}

static void test_global_bound_certificate(void **state)
{
    (void)state;
    /* K_D * B_D <= 1/2, checked with an upward-rounded product */
    for (int dim = 1; dim <= 4; dim++) {
        double K = sl_noise_scale(dim), B = sl_noise_raw_bound(dim);
        assert_true(K > 0.0 && B > 0.0);
        assert_true(fp_mul_up(K, B) <= 0.5 || K * B == 0.5);
        printf("certificate: dim %d: B = %.17g, K = %a, K*B <= 1/2\n", dim, B, K);
    }
    assert_true(sl_noise_scale(1) * 4.0 == 0.5 && sl_noise_raw_bound(1) == 4.0);
    assert_true(sl_noise_scale(2) * 1.0 == 0.5 && sl_noise_raw_bound(2) == 1.0);
    assert_true(sl_noise_raw_bound(0) == 0.0 && sl_noise_raw_bound(5) == 0.0);

    const int ms[5] = { 0, 1, 2, 2, 3 };
    const double gm[5] = { 0, 8, 1, 1, 1 };
    for (int dim = 3; dim <= 4; dim++) {
        cert_stats st;
        double t0 = now_s();
        certify(dim, ms[dim], gm[dim], sl_noise_raw_bound(dim), &st);
        printf("certificate: dim %d: |raw| <= %.6g proven with %ld boxes "
               "(largest value found %.9f, slack %.2g) in %.2f s%s\n", dim,
               sl_noise_raw_bound(dim), st.boxes, st.best_lower,
               sl_noise_raw_bound(dim) - st.best_lower, now_s() - t0,
               st.failed ? " FAILED" : "");
        assert_false(st.failed);
        /* and the bound is within 0.1% of the supremum over all hashes */
        assert_true(st.best_lower > sl_noise_raw_bound(dim) * (1.0 - 1e-3));
    }
    /* the 1D/2D lemma phi(t) <= 1/2 (noise.c), spot-checked on a grid */
    for (int i = 0; i <= 1000; i++) {
        double t = i / 1000.0;
        long double s = fade_l(t);
        assert_true((1 - s) * t + s * (1 - t) <= 0.5L + 1e-18L);
    }
}

/* ---------------------------------------------------------------------- */
/* pnoise                                                                  */
/* ---------------------------------------------------------------------- */

static void test_periodic(void **state)
{
    (void)state;
    rng_seed(5);
    long cases = 0, mismatches = 0, differ = 0;
    for (int dim = 1; dim <= 4; dim++) {
        for (int n = 0; n < 20000; n++) {
            double p[4], q[4];
            int per[4], none[4];
            /* dyadic coordinates: x - floor(x) is exact before and after
             * the shift, so the results must agree to the bit */
            for (int k = 0; k < dim; k++) {
                p[k] = (double)irange(-50000, 50000) / 1024.0;
                per[k] = irange(1, 12);
                none[k] = irange(-3, 0);
            }
            double v = sl_pnoise(dim, p, per);
            for (int k = 0; k < dim; k++) {
                memcpy(q, p, sizeof q);
                q[k] += (double)(per[k] * irange(-5, 5));
                if (sl_pnoise(dim, q, per) != v)
                    mismatches++;
                double vv[3], ww[3];
                sl_vpnoise(dim, p, per, vv);
                sl_vpnoise(dim, q, per, ww);
                if (memcmp(vv, ww, sizeof vv) != 0)
                    mismatches++;
            }
            if (sl_pnoise(dim, p, none) != sl_noise(dim, p) ||
                sl_pnoise(dim, p, NULL) != sl_noise(dim, p))
                mismatches++;
            if (v != sl_noise(dim, p))
                differ++;
            cases++;
        }
    }
    /* the period also shows in interval mode: same enclosure one period on */
    int per3[3] = { 3, 5, 2 };
    ia_interval a[3] = { ia_make(0.2, 0.4), ia_make(1.1, 1.3), ia_make(-0.5, -0.25) };
    ia_interval b[3] = { ia_make(3.2, 3.4), ia_make(1.1, 1.3), ia_make(-0.5, -0.25) };
    ia_interval ra = sl_pnoise3_ia(a, per3), rb = sl_pnoise3_ia(b, per3);
    printf("periodic: %ld points, %ld mismatches after shifts by whole periods; "
           "%ld differ from noise (expected: most)\n", cases, mismatches, differ);
    assert_int_equal(mismatches, 0);
    assert_true(differ > cases / 2);
    assert_true(fabs(ra.lo - rb.lo) < 1e-12 && fabs(ra.hi - rb.hi) < 1e-12);
}

/* ---------------------------------------------------------------------- */
/* cellnoise                                                               */
/* ---------------------------------------------------------------------- */

static void test_cellnoise(void **state)
{
    (void)state;
    rng_seed(6);
    long cases = 0, bad = 0, same_neighbour = 0, neighbours = 0;
    for (int dim = 1; dim <= 4; dim++) {
        for (int n = 0; n < 20000; n++) {
            double cell[4], p[4], q[4];
            for (int k = 0; k < dim; k++) {
                cell[k] = (double)irange(-1000, 1000);
                p[k] = cell[k] + urand();
                q[k] = cell[k] + urand();
            }
            double v = sl_cellnoise(dim, p);
            if (!(v >= 0.0 && v < 1.0) || v != sl_cellnoise(dim, q) ||
                v != sl_cellnoise(dim, cell) || ldexp(v, 24) != floor(ldexp(v, 24)))
                bad++;
            double v3[3], w3[3];
            sl_vcellnoise(dim, p, v3);
            sl_vcellnoise(dim, q, w3);
            if (memcmp(v3, w3, sizeof v3) != 0)
                bad++;
            /* the next cell along axis 0 */
            q[0] = cell[0] + 1.0;
            neighbours++;
            if (sl_cellnoise(dim, q) == v)
                same_neighbour++;
            /* just below the lower face: the previous cell */
            q[0] = nextafter(cell[0], -INFINITY);
            double prev[4];
            memcpy(prev, cell, sizeof prev);
            prev[0] -= 1.0;
            if (sl_cellnoise(dim, q) != sl_cellnoise(dim, prev))
                bad++;

            /* interval and affine: one cell is a constant, several the hull */
            ia_interval box[4];
            aa_form in[4], out;
            aa_context ctx;
            aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
            int one = n & 1;
            for (int k = 0; k < dim; k++) {
                double lo = one ? cell[k] + 0.25 * urand() : cell[k] - urand();
                double hi = one ? cell[k] + 0.5 + 0.5 * urand() : cell[k] + urand();
                if (hi >= cell[k] + 1.0) hi = nextafter(cell[k] + 1.0, 0.0);
                box[k] = ia_make(lo, hi);
                aa_input(&ctx, &in[k], lo, hi);
            }
            ia_interval r = sl_cellnoise_ia(dim, box);
            sl_cellnoise_aa(&ctx, &out, dim, in);
            ia_interval ra = aa_range(&out);
            if (one) {
                if (!(r.lo == v && r.hi == v) || (r.flags & AA_DISCONTINUOUS) ||
                    !aa_is_point(&out) || out.x0 != v)
                    bad++;
            } else {
                if (!(r.flags & AA_DISCONTINUOUS) || !(out.flags & AA_DISCONTINUOUS))
                    bad++;
                for (int s = 0; s < 40; s++) {
                    double x[4];
                    for (int k = 0; k < dim; k++)
                        x[k] = urange(box[k].lo, box[k].hi);
                    double w = sl_cellnoise(dim, x);
                    if (!ia_contains(r, w) || !ia_contains(ra, w))
                        bad++;
                }
            }
            cases++;
        }
    }
    /* wide boxes: the global range */
    ia_interval wide[2] = { ia_make(-1e6, 1e6), ia_make(0.0, 1.0) };
    ia_interval rw = sl_cellnoise_ia(2, wide);
    printf("cellnoise: %ld cases, %ld bad; neighbour cells equal in %ld of %ld\n",
           cases, bad, same_neighbour, neighbours);
    assert_int_equal(bad, 0);
    assert_true(same_neighbour < neighbours / 100);
    assert_true(rw.lo == 0.0 && rw.hi < 1.0 && rw.hi > 0.999 &&
                (rw.flags & AA_DISCONTINUOUS));
}

/* ---------------------------------------------------------------------- */
/* determinism and decorrelation                                           */
/* ---------------------------------------------------------------------- */

static uint64_t fnv(uint64_t h, double v)
{
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    for (int i = 0; i < 8; i++) {
        h ^= (b >> (8 * i)) & 0xffu;
        h *= 0x100000001b3u;
    }
    return h;
}

enum { NDET = 4000 };

static void test_determinism(void **state)
{
    (void)state;
    static double pts[NDET][4];
    rng_seed(7);
    for (int i = 0; i < NDET; i++)
        for (int k = 0; k < 4; k++)
            pts[i][k] = urange(-1e4, 1e4);
    uint64_t fwd = 0xcbf29ce484222325u, rev = fwd, alt = fwd;
    int per[4] = { 4, 7, 0, 3 };
    for (int i = 0; i < NDET; i++) {
        for (int dim = 1; dim <= 4; dim++) {
            double v3[3];
            fwd = fnv(fwd, sl_noise(dim, pts[i]));
            fwd = fnv(fwd, sl_pnoise(dim, pts[i], per));
            fwd = fnv(fwd, sl_cellnoise(dim, pts[i]));
            sl_vnoise(dim, pts[i], v3);
            for (int c = 0; c < 3; c++)
                fwd = fnv(fwd, v3[c]);
        }
    }
    /* the same, in reverse order, through the fixed-dimension spellings */
    static double vals[NDET][4][6];
    for (int i = NDET - 1; i >= 0; i--) {
        const double *p = pts[i];
        double v3[3];
        vals[i][0][0] = sl_noise1(p[0]);
        vals[i][1][0] = sl_noise2(p[0], p[1]);
        vals[i][2][0] = sl_noise3(p);
        vals[i][3][0] = sl_noise4(p);
        vals[i][0][1] = sl_pnoise1(p[0], per[0]);
        vals[i][1][1] = sl_pnoise2(p[0], p[1], per[0], per[1]);
        vals[i][2][1] = sl_pnoise3(p, per);
        vals[i][3][1] = sl_pnoise4(p, per);
        vals[i][0][2] = sl_cellnoise1(p[0]);
        vals[i][1][2] = sl_cellnoise2(p[0], p[1]);
        vals[i][2][2] = sl_cellnoise3(p);
        vals[i][3][2] = sl_cellnoise4(p);
        for (int dim = 1; dim <= 4; dim++) {
            sl_vnoise(dim, p, v3);
            for (int c = 0; c < 3; c++)
                vals[i][dim - 1][3 + c] = v3[c];
        }
    }
    for (int i = 0; i < NDET; i++)
        for (int d = 0; d < 4; d++)
            for (int j = 0; j < 6; j++)
                rev = fnv(rev, vals[i][d][j]);
    /* and once more after unrelated calls (no hidden state) */
    aa_context ctx;
    aa_context_init(&ctx, 4);
    aa_form junk_in[3], junk_out;
    for (int k = 0; k < 3; k++)
        aa_input(&ctx, &junk_in[k], 0.1 * k, 0.1 * k + 0.5);
    sl_noise3_aa(&ctx, &junk_out, junk_in);
    for (int i = 0; i < NDET; i++) {
        for (int dim = 1; dim <= 4; dim++) {
            double v3[3];
            alt = fnv(alt, sl_noise(dim, pts[i]));
            alt = fnv(alt, sl_pnoise(dim, pts[i], per));
            alt = fnv(alt, sl_cellnoise(dim, pts[i]));
            sl_vnoise(dim, pts[i], v3);
            for (int c = 0; c < 3; c++)
                alt = fnv(alt, v3[c]);
        }
    }
    printf("determinism: %d points x 4 dims x 6 values: checksum %016llx, "
           "reverse order %016llx, after other calls %016llx\n", NDET,
           (unsigned long long)fwd, (unsigned long long)rev,
           (unsigned long long)alt);
    assert_true(fwd == rev && fwd == alt);

    /* channels: scalar and the three vector channels are uncorrelated */
    rng_seed(8);
    enum { NC = 100000 };
    double sum[4] = { 0 }, sq[4] = { 0 }, cross[4][4] = { { 0 } };
    for (int i = 0; i < NC; i++) {
        double p[3] = { urange(-1e3, 1e3), urange(-1e3, 1e3), urange(-1e3, 1e3) };
        double v[4];
        v[0] = sl_noise3(p);
        sl_vnoise(3, p, v + 1);
        for (int a = 0; a < 4; a++) {
            sum[a] += v[a];
            sq[a] += v[a] * v[a];
            for (int b = 0; b < 4; b++)
                cross[a][b] += v[a] * v[b];
        }
    }
    double worst = 0.0, sd[4];
    for (int a = 0; a < 4; a++) {
        double m = sum[a] / NC;
        sd[a] = sqrt(sq[a] / NC - m * m);
        assert_true(fabs(m - 0.5) < 0.01);
    }
    for (int a = 0; a < 4; a++)
        for (int b = a + 1; b < 4; b++) {
            double cov = cross[a][b] / NC - (sum[a] / NC) * (sum[b] / NC);
            double r = cov / (sd[a] * sd[b]);
            if (fabs(r) > worst)
                worst = fabs(r);
        }
    printf("channels: %d points, standard deviation %.4f, max |correlation| "
           "between noise and the 3 vector channels %.4f\n", NC, sd[0], worst);
    assert_true(worst < 0.03);
}

/* ---------------------------------------------------------------------- */
/* the float result against the rigorous point enclosure                   */
/* ---------------------------------------------------------------------- */

static void test_float_accuracy(void **state)
{
    (void)state;
    /* Both box methods: the interval jets' natural extension over a point
     * box is an enclosure computed independently of the float code (the
     * interval kit); the Taylor model's is the float jet within its
     * a-priori error, which this also checks against the float value. */
    static const int methods[2] = { SL_NOISE_BOX_JETS, SL_NOISE_BOX_AUTO };
    static const char *const mname[2] = { "interval jets", "default" };
    for (int m = 0; m < 2; m++) {
        sl_noise_set_box_method(methods[m]);
        rng_seed(9);
        long cases = 0, bad = 0;
        double worst = 0.0, widest = 0.0;
        for (int dim = 1; dim <= 4; dim++) {
            for (int n = 0; n < 25000; n++) {
                double p[4];
                ia_interval P[4];
                for (int k = 0; k < dim; k++) {
                    double scale = n % 3 == 0 ? 1.0 : (n % 3 == 1 ? 1e3 : 1e7);
                    p[k] = urange(-scale, scale);
                    if (n % 5 == 0)   /* next to a lattice plane, either side */
                        p[k] = nearbyint(p[k]) + (n % 2 ? 1 : -1) * urange(0, 1e-12);
                    P[k] = ia_point(p[k]);
                }
                double v = sl_noise(dim, p);
                ia_interval r = sl_noise_ia(dim, P);
                double e = v < r.lo ? r.lo - v : (v > r.hi ? v - r.hi : 0.0);
                if (e > worst)
                    worst = e;
                if (r.hi - r.lo > widest)
                    widest = r.hi - r.lo;
                if (e > TOL)
                    bad++;
                cases++;
            }
        }
        printf("float accuracy (%s): %ld points, max distance of the float result from "
               "the point enclosure %.3g (TOL %.3g), widest point enclosure %.3g\n",
               mname[m], cases, worst, TOL, widest);
        assert_int_equal(bad, 0);
        assert_true(widest < 1e-12);
    }
    sl_noise_set_box_method(SL_NOISE_BOX_AUTO);
}

/* ---------------------------------------------------------------------- */
/* containment                                                             */
/* ---------------------------------------------------------------------- */

enum box_kind { BOX_TINY, BOX_ONE_CELL, BOX_TWO_CELLS, BOX_MANY_CELLS,
                BOX_NEAR_PLANE, BOX_SMALL, BOX_SLIVER, BOX_KINDS };
static const char *const box_kind_name[BOX_KINDS] = {
    "tiny", "one-cell", "two-cell", "many-cell", "near-plane", "small", "sliver"
};

static void random_box(int kind, int dim, double lo[4], double hi[4])
{
    for (int k = 0; k < dim; k++) {
        double cell = (double)irange(-200, 200), a, b;
        switch (kind) {
        case BOX_TINY: {
            double w = pow(10.0, urange(-9.0, -3.0));
            a = cell + urand();
            b = a + w;
            break;
        }
        case BOX_ONE_CELL:
            a = cell + urand();
            b = cell + urand();
            break;
        case BOX_TWO_CELLS:
            a = cell - urange(0.0, 0.5);
            b = cell + urange(0.0, 0.5);
            if (irange(0, 3) == 0) {          /* some axes in one cell */
                a = cell + 0.5 * urand();
                b = a + 0.4 * urand();
            }
            break;
        case BOX_MANY_CELLS:
            a = cell + urand();
            b = a + urange(0.0, 4.0);
            break;
        case BOX_NEAR_PLANE: {
            double w = pow(10.0, urange(-6.0, -1.0));
            double gap = irange(0, 1) ? 0.0 : urange(0.0, 1e-12);
            if (irange(0, 1)) {
                a = cell + gap;
                b = a + w;
            } else {
                b = cell - gap;
                a = b - w;
            }
            break;
        }
        case BOX_SLIVER: {
            /* across a lattice plane by a sliver (1e-17 .. 1e-8: some
             * merged into the other cell by noise.c, some not), on about
             * half the axes; the rest inside one cell */
            double w = pow(10.0, urange(-6.0, -1.0));
            double e = pow(10.0, urange(-17.0, -8.0));
            if (irange(0, 1)) {
                a = cell + 0.5 * urand();
                b = a + w;
            } else if (irange(0, 1)) {
                a = cell - e;
                b = cell + w;
            } else {
                a = cell - w;
                b = cell + e;
            }
            break;
        }
        default:                              /* BOX_SMALL */
            a = urange(-100.0, 100.0);
            b = a + urange(0.01, 0.3);
            break;
        }
        if (a > b) {
            double t = a;
            a = b;
            b = t;
        }
        lo[k] = a;
        hi[k] = b;
    }
}

typedef struct containment_stats {
    long cases, points, ia_viol, aa_viol, lin, minrange;
} containment_stats;

/* One box: the variant is 0 noise, 1 pnoise, 2 a vector channel. */
static void check_box(int dim, int kind, int variant, containment_stats *st)
{
    double lo[4], hi[4];
    random_box(kind, dim, lo, hi);
    int per[4];
    for (int k = 0; k < dim; k++)
        per[k] = irange(1, 6);
    int chan = irange(0, 2);

    ia_interval P[4];
    aa_form in[4], outs[3];
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    for (int k = 0; k < dim; k++) {
        P[k] = ia_make(lo[k], hi[k]);
        aa_input(&ctx, &in[k], lo[k], hi[k]);
    }
    ia_interval r, r3[3];
    const aa_form *z;
    switch (variant) {
    case 0:
        r = sl_noise_ia(dim, P);
        sl_noise_aa(&ctx, &outs[0], dim, in);
        z = &outs[0];
        break;
    case 1:
        r = sl_pnoise_ia(dim, P, per);
        sl_pnoise_aa(&ctx, &outs[0], dim, in, per);
        z = &outs[0];
        break;
    default:
        sl_vnoise_ia(dim, P, r3);
        r = r3[chan];
        sl_vnoise_aa(&ctx, outs, dim, in);
        z = &outs[chan];
        break;
    }
    st->cases++;
    /* the output's own part: coefficients of the symbols beyond the inputs
     * (the new error symbols) and err */
    double slack = z->err, mag = fabs(z->x0);
    for (int i = 0; i < z->n; i++) {
        if (i >= dim)
            slack += fabs(z->c[i]);
        else
            mag += fabs(z->c[i]);
    }
    int linear = 0;
    for (int i = 0; i < z->n && i < dim; i++)
        if (z->c[i] != 0.0)
            linear = 1;
    if (linear)
        st->lin++;
    else
        st->minrange++;
    /*
     * The affine check evaluates z at eps_k = (x_k - mid_k) / rad_k in
     * double: the subtraction and division err by at most 3u |eps_k|, so
     * the sum over the input symbols errs by at most
     * (dim + 3) u (|z0| + sum |z_k|) < 2^-48 (|z0| + sum |z_k|).
     */
    double aa_tol = TOL + 0x1p-48 * mag;

    int nsamples = (1 << dim) + 48;
    for (int s = 0; s < nsamples; s++) {
        double x[4];
        for (int k = 0; k < dim; k++) {
            if (s < (1 << dim)) {
                x[k] = ((s >> k) & 1) ? hi[k] : lo[k];          /* corners */
            } else if (s % 4 == 0 && floor(hi[k]) > lo[k]) {
                x[k] = floor(hi[k]);                           /* on a plane */
            } else if (s % 4 == 1 && floor(hi[k]) > lo[k] && floor(hi[k]) == floor(lo[k]) + 1) {
                /* in the narrower part across the plane (a sliver) */
                double plane = floor(hi[k]);
                x[k] = plane - lo[k] < hi[k] - plane ? urange(lo[k], plane) : urange(plane, hi[k]);
                if (x[k] > hi[k]) x[k] = hi[k];
                if (x[k] < lo[k]) x[k] = lo[k];
            } else {
                x[k] = urange(lo[k], hi[k]);
                if (x[k] > hi[k]) x[k] = hi[k];
            }
        }
        double v, v3[3];
        switch (variant) {
        case 0: v = sl_noise(dim, x); break;
        case 1: v = sl_pnoise(dim, x, per); break;
        default: sl_vnoise(dim, x, v3); v = v3[chan]; break;
        }
        st->points++;
        if (v < r.lo - TOL || v > r.hi + TOL)
            st->ia_viol++;
        double val = z->x0;
        for (int k = 0; k < dim && k < z->n; k++) {
            double rad = in[k].c[k];
            double eps = rad > 0.0 ? (x[k] - in[k].x0) / rad : 0.0;
            val += z->c[k] * eps;
        }
        if (fabs(v - val) > slack + aa_tol || (z->flags & AA_UNBOUNDED))
            st->aa_viol++;
        /* and inside the form's range (the affine range met with its hull) */
        ia_interval zr = aa_range(z);
        if (v < zr.lo - TOL || v > zr.hi + TOL)
            st->aa_viol++;
    }
}

static void test_containment(void **state)
{
    (void)state;
    rng_seed(10);
    double t0 = now_s();
    long total_cases = 0, total_points = 0, total_ia = 0, total_aa = 0;
    for (int dim = 1; dim <= 4; dim++) {
        for (int kind = 0; kind < BOX_KINDS; kind++) {
            containment_stats st = { 0 };
            int n = dim <= 2 ? 2000 : 1500;
            for (int i = 0; i < n; i++)
                check_box(dim, kind, i % 3, &st);
            printf("containment: %dD %-10s %5ld boxes (%5ld linear, %5ld interval) "
                   "%7ld points: %ld interval, %ld affine violations\n", dim,
                   box_kind_name[kind], st.cases, st.lin, st.minrange, st.points,
                   st.ia_viol, st.aa_viol);
            total_cases += st.cases;
            total_points += st.points;
            total_ia += st.ia_viol;
            total_aa += st.aa_viol;
        }
    }
    printf("containment: %ld boxes, %ld points, %ld interval violations, "
           "%ld affine violations (%.2f s)\n", total_cases, total_points,
           total_ia, total_aa, now_s() - t0);
    assert_int_equal(total_ia, 0);
    assert_int_equal(total_aa, 0);
}

/* ---------------------------------------------------------------------- */
/* box methods: the Taylor model, the interval jets, and the rule          */
/* ---------------------------------------------------------------------- */

/*
 * GTOL: a bound on the float gradient's own rounding (sl_noise_grad, u =
 * 2^-53): f errs by at most u, moving the exact gradient by at most
 * D2 * dim * u = 640u (raw); each of the <= 16 corners adds a term
 * pdw * dot + pw * w * g of magnitude <= 1.875 * 8 + 8 = 23 computed with
 * <= 12 operations (< 30u relative each, as the weights and dot products
 * carry their own few-u errors), so the sum errs by < 16 * 23 * 30u +
 * 16u * 16 * 23 < 17000u (raw); K <= 1/2 halves it. In all < 10^4 u ~
 * 1.1e-12; GTOL = 2^-36 ~ 1.5e-11 leaves a factor 13.
 */
#define GTOL 0x1p-36

typedef struct method_stats {
    long boxes, points, ia_viol, aa_viol, grad_viol, grad_points;
    double rem_used;          /* largest |value - linear part| / delta seen
                               * (linear results with delta > 1e-6) */
} method_stats;

/* A box of side about 10^[-9, 0.3] (log-uniform, each axis 0.5..1 of it);
 * with probability 1/3 per axis across a lattice plane. */
static void scale_box(int dim, double lo[4], double hi[4])
{
    double w = pow(10.0, urange(-9.0, 0.3));
    for (int k = 0; k < dim; k++) {
        double wk = w * urange(0.5, 1.0), cell = (double)irange(-300, 300);
        lo[k] = irange(0, 2) == 0 ? cell - wk * urand() : cell + urange(0.0, 1.0 - 1e-9);
        hi[k] = lo[k] + wk;
    }
}

static void check_method_box(int dim, int variant, method_stats *st)
{
    double lo[4], hi[4];
    scale_box(dim, lo, hi);
    int per[4];
    for (int k = 0; k < dim; k++)
        per[k] = irange(1, 6);
    const int *period = variant == 1 ? per : NULL;
    int chan = irange(0, 2);
    ia_interval P[4], r, r3[3], gv, G[4];
    aa_form in[4], outs[3];
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    for (int k = 0; k < dim; k++) {
        P[k] = ia_make(lo[k], hi[k]);
        aa_input(&ctx, &in[k], lo[k], hi[k]);
    }
    const aa_form *z;
    bool have_grad = false;
    if (variant < 2) {
        r = variant == 1 ? sl_pnoise_ia(dim, P, per) : sl_noise_ia(dim, P);
        if (variant == 1)
            sl_pnoise_aa(&ctx, &outs[0], dim, in, per);
        else
            sl_noise_aa(&ctx, &outs[0], dim, in);
        z = &outs[0];
        have_grad = sl_noise_gradient_ia(dim, P, period, -1, &gv, G);
        if (have_grad && (gv.lo < r.lo || gv.hi > r.hi))
            st->ia_viol++;            /* the value: the same bound, or met with more */
    } else {
        sl_vnoise_ia(dim, P, r3);
        r = r3[chan];
        sl_vnoise_aa(&ctx, outs, dim, in);
        z = &outs[chan];
    }
    st->boxes++;
    double slack = z->err, mag = fabs(z->x0);
    for (int i = 0; i < z->n; i++) {
        if (i >= dim)
            slack += fabs(z->c[i]);
        else
            mag += fabs(z->c[i]);
    }
    double aa_tol = TOL + 0x1p-48 * mag;     /* as in check_box */
    ia_interval zr = aa_range(z);
    for (int s = 0; s < (1 << dim) + 40; s++) {
        double x[4];
        for (int k = 0; k < dim; k++) {
            if (s < (1 << dim))
                x[k] = ((s >> k) & 1) ? hi[k] : lo[k];
            else if (s % 3 == 0 && floor(hi[k]) > lo[k])
                x[k] = floor(hi[k]);          /* on a lattice plane */
            else {
                x[k] = urange(lo[k], hi[k]);
                if (x[k] > hi[k]) x[k] = hi[k];
            }
        }
        double v, v3[3], g[4];
        if (variant < 2) {
            v = sl_noise_grad(dim, x, period, g);
        } else {
            sl_vnoise(dim, x, v3);
            v = v3[chan];
        }
        st->points++;
        if (v < r.lo - TOL || v > r.hi + TOL)
            st->ia_viol++;
        double val = z->x0;
        for (int k = 0; k < dim && k < z->n; k++) {
            double rad = in[k].c[k];
            double eps = rad > 0.0 ? (x[k] - in[k].x0) / rad : 0.0;
            val += z->c[k] * eps;
        }
        double dev = fabs(v - val);
        if (dev > slack + aa_tol || (z->flags & AA_UNBOUNDED))
            st->aa_viol++;
        if (z->n > 0 && z->c[0] != 0.0 && slack > 1e-6 && dev / slack > st->rem_used)
            st->rem_used = dev / slack;
        if (v < zr.lo - TOL || v > zr.hi + TOL)
            st->aa_viol++;
        if (have_grad) {
            if (v < gv.lo - TOL || v > gv.hi + TOL)
                st->ia_viol++;
            st->grad_points++;
            for (int k = 0; k < dim; k++)
                if (g[k] < G[k].lo - GTOL || g[k] > G[k].hi + GTOL)
                    st->grad_viol++;
        }
    }
}

static void test_box_methods(void **state)
{
    (void)state;
    static const char *const mname[3] = { "auto", "jets", "taylor" };
    static const int methods[3] = { SL_NOISE_BOX_AUTO, SL_NOISE_BOX_JETS,
                                    SL_NOISE_BOX_TAYLOR };

    /* the float jet's error table is not below its derivation */
    for (int dim = 1; dim <= 4; dim++) {
        double derived[3], used[3];
        sl_noise_point_jet_error(dim, derived, used);
        for (int j = 0; j < 3; j++) {
            assert_true(derived[j] > 0.0);
            assert_true(used[j] >= derived[j]);
        }
        printf("box methods: %dD float jet error bounds (value, gradient, Hessian) "
               "%.3g %.3g %.3g, used %.3g %.3g %.3g\n", dim, derived[0], derived[1],
               derived[2], used[0], used[1], used[2]);
    }

    /* containment of values and gradients, each method, boxes at all scales */
    double t0 = now_s();
    long total = 0;
    for (int m = 0; m < 3; m++) {
        sl_noise_set_box_method(methods[m]);
        for (int dim = 1; dim <= 4; dim++) {
            rng_seed(40 + (uint64_t)dim);      /* the same boxes for each method */
            method_stats st = { 0 };
            int n = dim <= 2 ? 3000 : 2000;
            for (int i = 0; i < n; i++)
                check_method_box(dim, i % 3, &st);
            printf("box methods: %-6s %dD %5ld boxes %7ld points: %ld interval, %ld affine, "
                   "%ld gradient violations (of %ld); largest deviation / new symbol %.3f\n",
                   mname[m], dim, st.boxes, st.points, st.ia_viol, st.aa_viol, st.grad_viol,
                   st.grad_points * dim, st.rem_used);
            total += st.ia_viol + st.aa_viol + st.grad_viol;
        }
    }
    printf("box methods: %.2f s\n", now_s() - t0);
    assert_int_equal(total, 0);

    /* widths: on small 3D boxes the Taylor model is at most the jets'
     * (affine, interval, gradient), and the rule never wider than the
     * Taylor model alone */
    rng_seed(47);
    double w[3][3] = { { 0 } };
    long auto_wider = 0;
    int n = 1500;
    for (int i = 0; i < n; i++) {
        ia_interval P[3];
        double side = pow(10.0, urange(-3.0, log10(0.02)));
        for (int k = 0; k < 3; k++) {
            double a = urange(-100.0, 100.0);
            P[k] = ia_make(a, a + side * urange(0.5, 1.0));
        }
        double iw[3];
        for (int m = 0; m < 3; m++) {
            sl_noise_set_box_method(methods[m]);
            aa_context ctx;
            aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
            aa_form in[3], out;
            for (int k = 0; k < 3; k++)
                aa_input(&ctx, &in[k], P[k].lo, P[k].hi);
            sl_noise_aa(&ctx, &out, 3, in);
            ia_interval ra = aa_range(&out), r = sl_noise_ia(3, P), gv, G[3];
            assert_true(sl_noise_gradient_ia(3, P, NULL, -1, &gv, G));
            w[m][0] += (ra.hi - ra.lo) / n;
            w[m][1] += (r.hi - r.lo) / n;
            iw[m] = r.hi - r.lo;
            for (int k = 0; k < 3; k++)
                w[m][2] += (G[k].hi - G[k].lo) / (3 * n);
        }
        if (iw[0] > iw[2])
            auto_wider++;
    }
    sl_noise_set_box_method(SL_NOISE_BOX_AUTO);
    for (int m = 0; m < 3; m++)
        printf("box methods: 3D, %d boxes of side 1e-3..0.02: %-6s mean widths affine %.5f, "
               "interval %.5f, gradient %.5f\n", n, mname[m], w[m][0], w[m][1], w[m][2]);
    assert_true(w[2][0] <= w[1][0]);
    assert_true(w[2][1] < w[1][1]);
    assert_true(w[2][2] < w[1][2]);
    assert_int_equal(auto_wider, 0);
}

/* ---------------------------------------------------------------------- */
/* boxes on lattice planes, against an independent oracle                  */
/* ---------------------------------------------------------------------- */
/*
 * The interval jets skip an axis whose piece is a lattice plane, or a
 * sliver of a few ulps on one (noise_bound.c, "Point axes": a ground plane
 * y = 0 in shader space). These boxes have such axes (exactly on a plane,
 * a sliver of 1e-18..1e-8 on one side or both, or that close to a plane
 * without touching it) beside wide ones (0.05..0.6, so the jets run in the
 * default method too). The oracle is Perlin's formula and its gradient in
 * long double from the corner gradients read off at the lattice points
 * (as test_reconstruction), not noise.c's evaluation: its rounding is
 * below 2^-56 (|raw| <= 8, |d raw| <= 40, a few dozen long double
 * operations of relative error 2^-64 each), so OTOL = 2^-48 and GOTOL =
 * 2^-44 are slack enough and far below the enclosures' widths.
 */
#define OTOL 0x1p-48
#define GOTOL 0x1p-44

/* the corner gradients of the lattice points base[k] + 0..2 per axis */
typedef struct plane_oracle {
    int dim;
    double base[4];
    long g[81][4];
} plane_oracle;

static void plane_oracle_init(plane_oracle *o, int dim, const double lo[4])
{
    o->dim = dim;
    double worst = 0.0;
    for (int k = 0; k < dim; k++)
        o->base[k] = floor(lo[k]);
    int n = 1;
    for (int k = 0; k < dim; k++)
        n *= 3;
    for (int i = 0; i < n; i++) {
        double q[4];
        int rest = i;
        for (int k = 0; k < dim; k++) {
            q[k] = o->base[k] + rest % 3;
            rest /= 3;
        }
        lattice_gradient(dim, q, o->g[i], &worst);
        assert_true(in_gradient_set(dim, o->g[i]));
    }
    assert_true(worst < 1e-9);
}

/* noise and its gradient at x (within 2 cells of base per axis) */
static long double plane_oracle_eval(const plane_oracle *o, const double *x,
                                     long double grad[4])
{
    int dim = o->dim, cell[4];
    long double f[4], s[4], ds[4];
    for (int k = 0; k < dim; k++) {
        double b = floor(x[k]);
        cell[k] = (int)(b - o->base[k]);
        assert_true(cell[k] >= 0 && cell[k] <= 1);
        f[k] = (long double)x[k] - (long double)b;
        s[k] = fade_l(f[k]);
        ds[k] = 30.0L * f[k] * f[k] * (1.0L - f[k]) * (1.0L - f[k]);
        grad[k] = 0.0L;
    }
    long double raw = 0.0L;
    for (int c = 0; c < (1 << dim); c++) {
        int idx = 0, mul = 1;
        for (int k = 0; k < dim; k++) {
            idx += (cell[k] + ((c >> k) & 1)) * mul;
            mul *= 3;
        }
        const long *g = o->g[idx];
        long double W = 1.0L, dot = 0.0L, w[4], dw[4];
        for (int k = 0; k < dim; k++) {
            int b = (c >> k) & 1;
            w[k] = b ? s[k] : 1.0L - s[k];
            dw[k] = b ? ds[k] : -ds[k];
            W *= w[k];
            dot += (long double)g[k] * (f[k] - b);
        }
        raw += W * dot;
        for (int j = 0; j < dim; j++) {
            long double dW = dw[j];
            for (int k = 0; k < dim; k++)
                if (k != j)
                    dW *= w[k];
            grad[j] += dW * dot + W * (long double)g[j];
        }
    }
    long double K = (long double)sl_noise_scale(dim);
    for (int k = 0; k < dim; k++)
        grad[k] *= K;
    return 0.5L + K * raw;
}

/* a box with at least one axis on (or a hair from) a lattice plane */
static void plane_box(int dim, double lo[4], double hi[4])
{
    int thin = irange(1, (1 << dim) - 1);     /* which axes are thin */
    for (int k = 0; k < dim; k++) {
        double cell = (double)irange(-200, 200);
        if (thin >> k & 1) {
            double e = pow(10.0, urange(-18.0, -8.0)), e2 = pow(10.0, urange(-18.0, -8.0));
            switch (irange(0, 5)) {
            case 0: lo[k] = hi[k] = cell; break;                   /* the plane */
            case 1: lo[k] = cell; hi[k] = cell + e; break;
            case 2: lo[k] = cell - e; hi[k] = cell; break;
            case 3: lo[k] = cell - e; hi[k] = cell + e2; break;    /* a sliver across */
            case 4: lo[k] = cell + e; hi[k] = cell + e + e2; break; /* near, not on */
            default: lo[k] = cell - e - e2; hi[k] = cell - e; break;
            }
            if (!(lo[k] <= hi[k]))
                hi[k] = lo[k];
        } else {
            double w = pow(10.0, urange(log10(0.05), log10(0.6)));
            lo[k] = cell + urange(-0.5 * w, 1.0 - 0.5 * w);
            hi[k] = lo[k] + w;
        }
    }
}

typedef struct plane_stats {
    long boxes, points, ia_viol, aa_viol, grad_viol;
    double width;
} plane_stats;

static void check_plane_box(int dim, plane_stats *st)
{
    double lo[4], hi[4];
    plane_box(dim, lo, hi);
    plane_oracle o;
    plane_oracle_init(&o, dim, lo);
    ia_interval P[4], gv, G[4];
    aa_form in[4], z;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    for (int k = 0; k < dim; k++) {
        P[k] = ia_make(lo[k], hi[k]);
        aa_input(&ctx, &in[k], lo[k], hi[k]);
    }
    ia_interval r = sl_noise_ia(dim, P);
    sl_noise_aa(&ctx, &z, dim, in);
    bool have_grad = sl_noise_gradient_ia(dim, P, NULL, -1, &gv, G);
    ia_interval zr = aa_range(&z);
    st->boxes++;
    st->width += r.hi - r.lo;
    double slack = z.err, mag = fabs(z.x0);
    for (int i = 0; i < z.n; i++) {
        if (i >= dim)
            slack += fabs(z.c[i]);
        else
            mag += fabs(z.c[i]);
    }
    double aa_tol = OTOL + 0x1p-48 * mag;     /* as in check_box */
    /* the corners, then a dense random set; thin axes also at the plane */
    for (int s = 0; s < (1 << dim) + 150; s++) {
        double x[4];
        for (int k = 0; k < dim; k++) {
            double plane = floor(hi[k]);
            if (s < (1 << dim))
                x[k] = ((s >> k) & 1) ? hi[k] : lo[k];
            else if (s % 4 == 0 && plane >= lo[k])
                x[k] = plane;
            else {
                x[k] = urange(lo[k], hi[k]);
                if (x[k] > hi[k]) x[k] = hi[k];
                if (x[k] < lo[k]) x[k] = lo[k];
            }
        }
        long double gl[4];
        long double v = plane_oracle_eval(&o, x, gl);
        st->points++;
        if (v < (long double)r.lo - OTOL || v > (long double)r.hi + OTOL)
            st->ia_viol++;
        long double val = z.x0;
        for (int k = 0; k < dim && k < z.n; k++) {
            double rad = in[k].c[k];
            double eps = rad > 0.0 ? (x[k] - in[k].x0) / rad : 0.0;
            val += (long double)z.c[k] * eps;
        }
        if (fabsl(v - val) > slack + aa_tol || (z.flags & AA_UNBOUNDED))
            st->aa_viol++;
        if (v < (long double)zr.lo - OTOL || v > (long double)zr.hi + OTOL)
            st->aa_viol++;
        if (have_grad) {
            if (v < (long double)gv.lo - OTOL || v > (long double)gv.hi + OTOL)
                st->ia_viol++;
            for (int k = 0; k < dim; k++)
                if (gl[k] < (long double)G[k].lo - GOTOL || gl[k] > (long double)G[k].hi + GOTOL)
                    st->grad_viol++;
        }
    }
}

static void test_plane_boxes(void **state)
{
    (void)state;
    static const char *const mname[2] = { "auto", "jets" };
    static const int methods[2] = { SL_NOISE_BOX_AUTO, SL_NOISE_BOX_JETS };
    double t0 = now_s();
    long total = 0;
    for (int m = 0; m < 2; m++) {
        sl_noise_set_box_method(methods[m]);
        for (int dim = 1; dim <= 4; dim++) {
            rng_seed(60 + (uint64_t)dim);
            plane_stats st = { 0 };
            int n = dim <= 2 ? 300 : 400;
            for (int i = 0; i < n; i++)
                check_plane_box(dim, &st);
            printf("plane boxes: %-4s %dD %4ld boxes %6ld points: %ld interval, %ld affine, "
                   "%ld gradient violations; mean interval width %.4f\n", mname[m], dim,
                   st.boxes, st.points, st.ia_viol, st.aa_viol, st.grad_viol,
                   st.width / (double)st.boxes);
            total += st.ia_viol + st.aa_viol + st.grad_viol;
        }
    }
    sl_noise_set_box_method(SL_NOISE_BOX_AUTO);
    printf("plane boxes: %.2f s\n", now_s() - t0);
    assert_int_equal(total, 0);
}

/* ---------------------------------------------------------------------- */
/* tightness                                                               */
/* ---------------------------------------------------------------------- */

static void test_tightness(void **state)
{
    (void)state;
    rng_seed(11);
    /* small boxes inside one cell, widths 0.01 .. 0.3: the affine range is
     * never wider than the interval result (it is met with it); the widths
     * of the interval jets alone (the method before the Taylor model, which
     * is tighter on the widest of these boxes) are printed beside */
    for (int dim = 1; dim <= 4; dim++) {
        double ratio = 0.0, wia = 0.0, waa = 0.0, wjets = 0.0, waj = 0.0;
        int n = 4000, wider = 0;
        for (int i = 0; i < n; i++) {
            ia_interval P[4];
            aa_form in[4], out;
            aa_context ctx;
            aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
            for (int k = 0; k < dim; k++) {
                double w = urange(0.01, 0.3);
                double a = (double)irange(-100, 100) + urange(0.0, 1.0 - w);
                P[k] = ia_make(a, a + w);
                aa_input(&ctx, &in[k], a, a + w);
            }
            ia_interval r = sl_noise_ia(dim, P);
            sl_noise_aa(&ctx, &out, dim, in);
            sl_noise_set_box_method(SL_NOISE_BOX_JETS);
            ia_interval rj = sl_noise_ia(dim, P);
            aa_form outj;
            sl_noise_aa(&ctx, &outj, dim, in);
            ia_interval raj = aa_range(&outj);
            waj += raj.hi - raj.lo;
            sl_noise_set_box_method(SL_NOISE_BOX_AUTO);
            ia_interval ra = aa_range(&out);
            double a_w = ra.hi - ra.lo, i_w = r.hi - r.lo;
            if (a_w > i_w)
                wider++;
            ratio += a_w / i_w;
            wia += i_w;
            waa += a_w;
            wjets += rj.hi - rj.lo;
        }
        ratio /= n;
        printf("tightness: %dD, %d boxes of width 0.01..0.3 in one cell: mean "
               "affine/interval width %.3f (mean widths %.4f / %.4f; interval jets "
               "alone %.4f / %.4f)\n", dim, n, ratio, waa / n, wia / n, waj / n, wjets / n);
        assert_int_equal(wider, 0);
    }

    /* boxes of width 1e-3: affine range against the sampled true range */
    for (int dim = 1; dim <= 4; dim++) {
        int n = dim == 4 ? 150 : 300, grid = dim == 1 ? 200 : (dim == 2 ? 30 : (dim == 3 ? 11 : 6));
        int bad = 0;
        double worst = 0.0, mean = 0.0;
        for (int i = 0; i < n; i++) {
            double lo[4];
            aa_form in[4], out;
            aa_context ctx;
            aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
            for (int k = 0; k < dim; k++) {
                lo[k] = urange(-100.0, 100.0);
                aa_input(&ctx, &in[k], lo[k], lo[k] + 1e-3);
            }
            sl_noise_aa(&ctx, &out, dim, in);
            ia_interval ra = aa_range(&out);
            double vmin = 1.0, vmax = 0.0;
            long total = 1;
            for (int k = 0; k < dim; k++)
                total *= grid + 1;
            for (long t = 0; t < total; t++) {
                double x[4];
                long rest = t;
                for (int k = 0; k < dim; k++) {
                    x[k] = lo[k] + 1e-3 * (double)(rest % (grid + 1)) / grid;
                    rest /= grid + 1;
                }
                double v = sl_noise(dim, x);
                if (v < vmin) vmin = v;
                if (v > vmax) vmax = v;
            }
            double truew = vmax - vmin, aw = ra.hi - ra.lo;
            if (aw > 2.0 * truew + 1e-5)
                bad++;
            double q = aw / (truew + 1e-5);
            mean += q;
            if (q > worst)
                worst = q;
        }
        printf("tightness: %dD, %d boxes of width 1e-3: affine width / (sampled "
               "width + 1e-5) mean %.3f, max %.3f; %d above 2x + 1e-5\n", dim, n,
               mean / n, worst, bad);
        assert_int_equal(bad, 0);
    }
}

/* ---------------------------------------------------------------------- */
/* correlation                                                             */
/* ---------------------------------------------------------------------- */

static void test_correlation(void **state)
{
    (void)state;
    rng_seed(12);
    /* patch sides 0.001..0.01 and 0.01..0.05 (P spans up to twice that) */
    static const double wlo[2] = { 0.001, 0.01 }, whi[2] = { 0.01, 0.05 };
    for (int cls = 0; cls < 2; cls++) {
        double diff_ratio = 0.0;
        long kept_uv = 0, n = 1000;
        for (long i = 0; i < n; i++) {
            aa_context ctx;
            aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
            aa_form u, v, P[3], n1, n2, d, disp;
            double u0 = urange(-50.0, 50.0), v0 = urange(-50.0, 50.0);
            double w = urange(wlo[cls], whi[cls]);
            aa_input(&ctx, &u, u0, u0 + w);
            aa_input(&ctx, &v, v0, v0 + w);
            /* a sheared plane: P = (u + v, u - 0.5 v, 0.3 u + 2) */
            aa_lincomb(&ctx, &P[0], 1.0, &u, 1.0, &v, 0.0);
            aa_lincomb(&ctx, &P[1], 1.0, &u, -0.5, &v, 0.0);
            aa_lincomb(&ctx, &P[2], 0.3, &u, 0.0, NULL, 2.0);
            sl_noise3_aa(&ctx, &n1, P);
            sl_noise3_aa(&ctx, &n2, P);
            aa_sub(&ctx, &d, &n1, &n2);
            diff_ratio += aa_radius(&d) / aa_radius(&n1);
            /* P.z + 0.5 noise(P): the displaced coordinate depends on u, v */
            aa_lincomb(&ctx, &disp, 1.0, &P[2], 0.5, &n1, 0.0);
            if (disp.n >= 2 && disp.c[0] != 0.0 && disp.c[1] != 0.0 &&
                n1.c[1] != 0.0)
                kept_uv++;
        }
        diff_ratio /= n;
        /* uncorrelated results would give a ratio of 2 */
        printf("correlation: %ld sheared-plane patches of side %g..%g: radius of "
               "noise(P) - noise(P) / radius of noise(P) %.4f (uncorrelated: 2); "
               "P + N*noise(P) depends on u and v in %ld\n", n, wlo[cls],
               whi[cls], diff_ratio, kept_uv);
        assert_true(diff_ratio < (cls == 0 ? 0.1 : 0.5));
        assert_true(kept_uv == n);
    }
}

/* ---------------------------------------------------------------------- */
/* special inputs                                                          */
/* ---------------------------------------------------------------------- */

static void test_special_inputs(void **state)
{
    (void)state;
    const double specials[] = { NAN, INFINITY, -INFINITY, 0x1p62, -0x1p70, DBL_MAX,
                                -0.0, 0x1p-1074, -0x1p-1074, 0x1p52 + 0.5 };
    int ns = (int)(sizeof specials / sizeof specials[0]);
    for (int dim = 1; dim <= 4; dim++) {
        for (int i = 0; i < ns; i++) {
            double p[4] = { 0.3, 1.7, -2.2, 5.5 }, v3[3], g[4];
            p[dim - 1] = specials[i];
            double v = sl_noise(dim, p), c = sl_cellnoise(dim, p);
            double vg = sl_noise_grad(dim, p, NULL, g);
            sl_vnoise(dim, p, v3);
            assert_true(v >= 0.0 && v <= 1.0);
            assert_true(vg == v);
            assert_true(c >= 0.0 && c < 1.0);
            for (int k = 0; k < 3; k++)
                assert_true(v3[k] >= 0.0 && v3[k] <= 1.0);
        }
    }
    /* invalid dims */
    double p[4] = { 0.1, 0.2, 0.3, 0.4 };
    assert_true(sl_noise(0, p) == 0.5 && sl_noise(5, p) == 0.5);
    ia_interval P[4] = { ia_make(0, 1), ia_make(0, 1), ia_make(0, 1), ia_make(0, 1) };
    ia_interval r = sl_noise_ia(7, P);
    assert_true(r.lo == 0.0 && r.hi == 1.0);

    /* unbounded and infinite inputs: the global range, AA_UNBOUNDED dropped,
     * AA_DISCONTINUOUS kept */
    ia_interval E[3] = { ia_entire(), ia_make(0.2, 0.3), ia_make(0.0, 0.1) };
    E[1].flags |= AA_DISCONTINUOUS;
    r = sl_noise_ia(3, E);
    assert_true(r.lo == 0.0 && r.hi == 1.0);
    assert_true((r.flags & AA_DISCONTINUOUS) && !(r.flags & AA_UNBOUNDED));
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form in[3], out;
    aa_unbounded(&in[0], 0);
    aa_input(&ctx, &in[1], 0.2, 0.3);
    aa_input(&ctx, &in[2], 0.0, 0.1);
    sl_noise3_aa(&ctx, &out, in);
    ia_interval ra = aa_range(&out);
    assert_true(ra.lo <= 0.0 && ra.hi >= 1.0 && ra.hi < 1.01 && ra.lo > -0.01);
    assert_false(out.flags & AA_UNBOUNDED);
    sl_cellnoise3_aa(&ctx, &out, in);
    assert_false(out.flags & AA_UNBOUNDED);
    assert_true(out.flags & AA_DISCONTINUOUS);

    /* wide boxes: the global range */
    ia_interval W[2] = { ia_make(-3.0, 10.0), ia_make(0.5, 0.6) };
    r = sl_noise_ia(2, W);
    assert_true(r.lo == 0.0 && r.hi == 1.0);

    /* a point box gives a tiny enclosure of the float value (the float
     * jet's a-priori error, noise.c: below 1e-12 wide); an empty input an
     * empty result */
    ia_interval Q[3] = { ia_point(0.25), ia_point(-7.5), ia_point(3.125) };
    double q[3] = { 0.25, -7.5, 3.125 };
    r = sl_noise3_ia(Q);
    assert_true(r.lo <= sl_noise3(q) + TOL && sl_noise3(q) - TOL <= r.hi);
    assert_true(r.hi - r.lo < 1e-12);
    Q[1] = ia_empty();
    assert_true(ia_is_empty(sl_noise3_ia(Q)));

    /* context capacity spent: the new error folds into err, still sound */
    aa_context small;
    aa_context_init(&small, 3);
    aa_form pin[3];
    for (int k = 0; k < 3; k++)
        aa_input(&small, &pin[k], 0.1 + k, 0.2 + k);
    sl_noise3_aa(&small, &out, pin);
    assert_true(out.err > 0.0 && out.n <= 3);
    printf("special inputs: NaN, infinities, huge, subnormal, invalid dims, "
           "unbounded forms, spent context: ok\n");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lattice),
        cmocka_unit_test(test_reconstruction),
        cmocka_unit_test(test_gradient),
        cmocka_unit_test(test_derivative_bounds),
        cmocka_unit_test(test_range),
        cmocka_unit_test(test_global_bound_certificate),
        cmocka_unit_test(test_periodic),
        cmocka_unit_test(test_cellnoise),
        cmocka_unit_test(test_determinism),
        cmocka_unit_test(test_float_accuracy),
        cmocka_unit_test(test_containment),
        cmocka_unit_test(test_box_methods),
        cmocka_unit_test(test_plane_boxes),
        cmocka_unit_test(test_tightness),
        cmocka_unit_test(test_correlation),
        cmocka_unit_test(test_special_inputs),
    };
    return cmocka_run_group_tests_name("sl_noise", tests, NULL, NULL);
}

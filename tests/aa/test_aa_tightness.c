/*
 * tests/aa/test_aa_tightness.c: tests that common/aa is not just sound but
 * tight where it should be, and sets its flags where it should.
 *
 *   x - x                    exactly [0, 0] in affine mode, for x from aa_input
 *                            over random ranges (tiny, huge, subnormal, ...)
 *   lincomb3, centred        aa_lincomb3_centred equals aa_add_s(x, -x0) three
 *                            times and aa_lincomb3, bit for bit
 *   x*(1-x) over [0,1]       affine range strictly narrower than interval's
 *   (x+1)*(x-1) - x*x        over [2,3]: affine near -1, width < 0.1 of IA's
 *   sqr over [-1,1]          [0, 1] in both modes (Chebyshev square in AA)
 *   sin/cos, full periods    stay within [-1, 1] in both modes
 *   flags                    merge, floor, step, sign, smoothstep, sin, exp,
 *                            a division's pole: AA_DISCONTINUOUS exactly
 *                            where a jump (or a pole) is inside
 *   condensation             x*x*x - x and (x*x)^2 - x*x built from two inputs:
 *                            capacity 2 (fully reduced) stays conservative,
 *                            also symbol by symbol, and capacity 16 is never
 *                            wider than capacity 2
 *   closed forms             aa_sqrt, aa_exp and aa_invsqrt reach the
 *                            Chebyshev (minimax) error of the best linear
 *                            approximation, computed in long double, within
 *                            1e-9 of it; their slope is the secant's
 *   ia_mul, ia_div           the sign-case product and quotient equal the
 *                            four corners' directed roundings (never wider;
 *                            the same numbers unless a corner underflows to
 *                            0 or is inf/inf)
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "test_rng.h"

#define TWO_PI 6.283185307179586

/* ---- a small fixed-seed generator (splitmix64) ---- */

static uint64_t g_rng = 0x7167e5u;

static uint64_t rng_next(void)
{
    return test_rng_next(&g_rng);
}

static double rng_unit(void)
{
    return (double)(rng_next() >> 11) * 0x1p-53;
}

static double width_ia(ia_interval r)
{
    return r.hi - r.lo;
}

/* ---- x - x ---- */

static void random_range(int kind, double *lo, double *hi)
{
    double a, b;
    switch (kind) {
    case 0:                                            /* moderate */
        a = 20 * rng_unit() - 10;
        b = 20 * rng_unit() - 10;
        break;
    case 1: {                                          /* tiny relative width */
        double c = (rng_unit() < 0.5 ? -1 : 1) * pow(10.0, 8 * rng_unit() - 4);
        a = c;
        b = c * (1 + 1e-12 * rng_unit());
        break;
    }
    case 2:                                            /* huge */
        a = -pow(10.0, 300 * rng_unit());
        b = pow(10.0, 300 * rng_unit());
        break;
    case 3:                                            /* subnormal */
        a = 0x1p-1074 * (double)(rng_next() % 100000);
        b = 0x1p-1074 * (double)(rng_next() % 100000);
        break;
    case 4:                                            /* not exactly representable */
        a = 0.1 * (double)(rng_next() % 100);
        b = a + 0.3;
        break;
    default:                                           /* straddling 0 */
        a = -pow(10.0, 6 * rng_unit() - 3);
        b = pow(10.0, 6 * rng_unit() - 3);
        break;
    }
    *lo = fmin(a, b);
    *hi = fmax(a, b);
}

static void test_x_minus_x_is_zero(void **state)
{
    (void)state;
    long bad = 0;
    for (int i = 0; i < 60000; i++) {
        double lo, hi;
        random_range(i % 6, &lo, &hi);
        aa_context ctx;
        aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
        aa_form x, y, z;
        aa_input(&ctx, &x, lo, hi);
        y = x;                                         /* a copy, not an alias */
        aa_sub(&ctx, &z, &x, &x);
        ia_interval r1 = aa_range(&z);
        aa_sub(&ctx, &z, &x, &y);
        ia_interval r2 = aa_range(&z);
        if (!(r1.lo == 0 && r1.hi == 0 && r2.lo == 0 && r2.hi == 0)) {
            if (bad < 5) {
                printf("x - x over [%a, %a]: [%a, %a] / copy [%a, %a]; x: x0 %a c0 %a err %a\n",
                       lo, hi, r1.lo, r1.hi, r2.lo, r2.hi, x.x0, x.c[0], x.err);
            }
            bad++;
        }
    }
    printf("x - x: %ld of 60000 not exactly [0, 0]\n", bad);
    assert_int_equal(bad, 0);

    /* information only: a scaled combination carries a bound on the
     * rounding of its products in err (affine.h promises exactness for sums
     * and differences only), so y - y need not vanish */
    {
        aa_context ctx;
        aa_context_init(&ctx, 2);
        aa_form u, v, y, z;
        aa_input(&ctx, &u, 0.0, 1.0);
        aa_input(&ctx, &v, -2.0, 6.0);
        aa_lincomb(&ctx, &y, 2.0, &u, -0.25, &v, 3.0);
        aa_sub(&ctx, &z, &y, &y);
        ia_interval r = aa_range(&z);
        printf("y - y for y = 2u - v/4 + 3 (aa_lincomb): [%a, %a]\n", r.lo, r.hi);
    }
}

/* ---- aa_lincomb3_centred is aa_lincomb3 of the centred inputs ---- */

static bool same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static bool same_form(const aa_form *a, const aa_form *b)
{
    if (!same_bits(a->x0, b->x0) || !same_bits(a->err, b->err) || !same_bits(a->lo, b->lo) ||
        !same_bits(a->hi, b->hi) || a->n != b->n || a->flags != b->flags)
        return false;
    for (int i = 0; i < a->n; i++)
        if (!same_bits(a->c[i], b->c[i]))
            return false;
    return true;
}

/* noise's linearisation (common/sl/noise_bound.c) takes the one-pass
 * form; it must be the three aa_add_s and aa_lincomb3 to the bit, over
 * inputs with errors, hulls narrower than their affine ranges, flags and
 * every scale random_range gives (an unbounded input included) */
static void test_lincomb3_centred_bitwise(void **state)
{
    (void)state;
    long bad = 0;
    for (int i = 0; i < 40000; i++) {
        aa_context ctx;
        aa_context_init(&ctx, 2 + i % 7);
        aa_form u, v, x[3], y[3], z1, z2;
        double lo, hi;
        random_range(i % 6, &lo, &hi);
        aa_input(&ctx, &u, lo, hi);
        random_range((i / 6) % 6, &lo, &hi);
        aa_input(&ctx, &v, lo, hi);
        aa_lincomb(&ctx, &x[0], rng_unit() * 4 - 2, &u, rng_unit() - 0.5, &v, rng_unit() * 8 - 4);
        aa_mul(&ctx, &x[1], &u, &v);                 /* an error symbol, a hull */
        aa_sin(&ctx, &x[2], &x[0]);                  /* a hull narrower than the form */
        if (i % 97 == 0)
            aa_floor(&ctx, &x[1], &x[1]);            /* AA_DISCONTINUOUS */
        if (i % 101 == 0)
            aa_unbounded(&x[2], 0);
        double m[3] = { rng_unit() * 2 - 1, i % 5 == 0 ? 0.0 : rng_unit() * 100 - 50,
                        ldexp(rng_unit(), (int)(rng_next() % 40) - 20) };
        double c = rng_unit() * 2 - 1;
        for (int k = 0; k < 3; k++)
            aa_add_s(&ctx, &y[k], &x[k], -x[k].x0);
        aa_lincomb3(&ctx, &z1, m, y, c);
        aa_lincomb3_centred(&ctx, &z2, m, x, c);
        if (!same_form(&z1, &z2)) {
            if (bad < 5)
                printf("case %d: centred x0 %a err %a [%a, %a] n %d / plain x0 %a err %a "
                       "[%a, %a] n %d\n", i, z2.x0, z2.err, z2.lo, z2.hi, z2.n, z1.x0, z1.err,
                       z1.lo, z1.hi, z1.n);
            bad++;
        }
    }
    printf("lincomb3 of centred inputs: %ld of 40000 differ from aa_add_s + aa_lincomb3\n", bad);
    assert_int_equal(bad, 0);
}

/* ---- dependency: x*(1-x) ---- */

static void test_x_times_one_minus_x(void **state)
{
    (void)state;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form x, t, p;
    aa_input(&ctx, &x, 0.0, 1.0);
    aa_lincomb(&ctx, &t, -1.0, &x, 0.0, &x, 1.0);        /* 1 - x */
    aa_mul(&ctx, &p, &x, &t);
    ia_interval ra = aa_range(&p);

    ia_interval xi = ia_make(0.0, 1.0);
    ia_interval ri = ia_mul(xi, ia_add_s(ia_neg(xi), 1.0));
    printf("x*(1-x) over [0,1]: affine [%.17g, %.17g] width %.17g, interval [%.17g, %.17g] "
           "width %.17g\n", ra.lo, ra.hi, width_ia(ra), ri.lo, ri.hi, width_ia(ri));
    /* both sound: the true range is [0, 1/4] */
    assert_true(ra.lo <= 0.0 && ra.hi >= 0.25);
    assert_true(ri.lo <= 0.0 && ri.hi >= 0.25);
    assert_true(ri.lo <= 0.0 && ri.hi >= 1.0);          /* IA cannot do better */
    assert_true(width_ia(ra) < width_ia(ri));
}

/* ---- (x+1)*(x-1) - x*x == -1 ---- */

static void test_difference_of_squares(void **state)
{
    (void)state;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form x, xp, xm, prod, sq, sqm, d1, d2, xc;
    aa_input(&ctx, &x, 2.0, 3.0);
    aa_add_s(&ctx, &xp, &x, 1.0);
    aa_add_s(&ctx, &xm, &x, -1.0);
    aa_mul(&ctx, &prod, &xp, &xm);
    aa_sqr(&ctx, &sq, &x);
    aa_sub(&ctx, &d1, &prod, &sq);                      /* x*x via aa_sqr */
    xc = x;
    aa_mul(&ctx, &sqm, &x, &xc);                        /* x*x via the general mul */
    aa_sub(&ctx, &d2, &prod, &sqm);

    ia_interval xi = ia_make(2.0, 3.0);
    ia_interval di = ia_sub(ia_mul(ia_add_s(xi, 1.0), ia_add_s(xi, -1.0)), ia_sqr(xi));
    ia_interval r1 = aa_range(&d1), r2 = aa_range(&d2);
    printf("(x+1)*(x-1) - x*x over [2,3]: affine (sqr) [%.17g, %.17g], affine (mul) "
           "[%.17g, %.17g], interval [%.17g, %.17g]\n", r1.lo, r1.hi, r2.lo, r2.hi, di.lo, di.hi);
    assert_true(r1.lo <= -1.0 && r1.hi >= -1.0);
    assert_true(r2.lo <= -1.0 && r2.hi >= -1.0);
    assert_true(di.lo <= -1.0 && di.hi >= -1.0);
    assert_true(width_ia(r1) < 0.1 * width_ia(di));
    assert_true(width_ia(r2) < 0.1 * width_ia(di));
}

/* ---- products by powers of two: exact ---- */

/* x times a power of two a (2, 1/2, the octave factors of fBm, -1 of a
 * negation) is exactly a times x when no product is subnormal: centre,
 * coefficients, private error and hull, with no rounding margin (issue
 * 24, affine.c scale_exact); a subnormal product goes the general way and
 * still encloses a x */
static void test_power_of_two_scale_exact(void **state)
{
    (void)state;
    static const double factors[] = { 2.0, 4.0, 1.0, -1.0, -2.0, 0.5, 0.25, -0.125, 0x1p-60 };
    long cases = 0;
    for (int i = 0; i < 20000; i++) {
        aa_context ctx;
        aa_context_init(&ctx, 2 + i % 7);
        aa_form u, v, x, z;
        double lo, hi;
        random_range(i % 6, &lo, &hi);
        aa_input(&ctx, &u, lo, hi);
        random_range((i / 6) % 6, &lo, &hi);
        aa_input(&ctx, &v, lo, hi);
        aa_mul(&ctx, &x, &u, &v);            /* an error symbol, a private error, a hull */
        aa_add_s(&ctx, &x, &x, rng_unit() - 0.5);
        double a = factors[i % 9];
        aa_mul_s(&ctx, &z, &x, a);
        if (x.flags & AA_UNBOUNDED)
            continue;
        bool subnormal = false;           /* a product below 2^-1022: not exact */
        double parts[4 + AA_MAX_SYMBOLS] = { x.x0, x.err, x.lo, x.hi };
        for (int k = 0; k < x.n; k++)
            parts[4 + k] = x.c[k];
        for (int k = 0; k < 4 + x.n; k++)
            subnormal |= parts[k] != 0.0 && fabs(a * parts[k]) < 0x1p-1022;
        if (subnormal)
            continue;
        assert_true(z.x0 == a * x.x0 && z.err == fabs(a) * x.err && z.n == x.n);
        for (int k = 0; k < x.n; k++)
            assert_true(z.c[k] == a * x.c[k]);
        assert_true(z.lo == (a > 0 ? a * x.lo : a * x.hi));
        assert_true(z.hi == (a > 0 ? a * x.hi : a * x.lo));
        cases++;
    }
    printf("powers of two: %ld products exact, hull included\n", cases);
    /* subnormal products: the general path, which encloses them */
    aa_context ctx;
    aa_context_init(&ctx, 4);
    aa_form x, z;
    aa_input(&ctx, &x, 0x1.8p-1022, 0x1.cp-1020);
    aa_mul_s(&ctx, &z, &x, 0x1p-10);
    ia_interval r = aa_range(&z);
    assert_true(r.lo <= 0x1.8p-1032 && r.hi >= 0x1.cp-1030);
    assert_true(z.err > 0.0 || r.lo < 0x1.8p-1032);      /* the loss is accounted for */
}

/* ---- sqr over [-1, 1] ---- */

static void test_sqr_symmetric(void **state)
{
    (void)state;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form x, s, m;
    aa_input(&ctx, &x, -1.0, 1.0);
    aa_sqr(&ctx, &s, &x);
    aa_mul(&ctx, &m, &x, &x);                            /* the same form twice */
    ia_interval ra = aa_range(&s), rm = aa_range(&m);
    ia_interval ri = ia_sqr(ia_make(-1.0, 1.0));
    printf("sqr over [-1,1]: aa_sqr [%a, %a], aa_mul(x,x) [%a, %a], ia_sqr [%a, %a]\n",
           ra.lo, ra.hi, rm.lo, rm.hi, ri.lo, ri.hi);
    const double tol = 1e-12;
    assert_true(ra.lo <= 0.0 && ra.lo >= -tol && ra.hi >= 1.0 && ra.hi <= 1.0 + tol);
    assert_true(rm.lo <= 0.0 && rm.lo >= -tol && rm.hi >= 1.0 && rm.hi <= 1.0 + tol);
    assert_true(ri.lo <= 0.0 && ri.lo >= -tol && ri.hi >= 1.0 && ri.hi <= 1.0 + tol);
}

/* ---- sin and cos over whole periods ---- */

static void test_sin_cos_full_period(void **state)
{
    (void)state;
    static const double ranges[][2] = {
        {0.0, TWO_PI}, {1.0, 1.0 + TWO_PI + 0.1}, {-100.0, 100.0}, {-1e6, 1e6},
        {1e15, 1e15 + 10.0}, {-3.5, 3.5},
    };
    for (size_t i = 0; i < sizeof ranges / sizeof ranges[0]; i++) {
        double lo = ranges[i][0], hi = ranges[i][1];
        for (int f = 0; f < 2; f++) {
            aa_context ctx;
            aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
            aa_form x, z;
            aa_input(&ctx, &x, lo, hi);
            if (f == 0)
                aa_sin(&ctx, &z, &x);
            else
                aa_cos(&ctx, &z, &x);
            ia_interval ra = aa_range(&z);
            ia_interval ri = f == 0 ? ia_sin(ia_make(lo, hi)) : ia_cos(ia_make(lo, hi));
            printf("%s over [%g, %g]: affine [%.17g, %.17g] flags %u, interval [%.17g, %.17g] "
                   "flags %u\n", f ? "cos" : "sin", lo, hi, ra.lo, ra.hi, (unsigned)z.flags,
                   ri.lo, ri.hi, ri.flags);
            /* within [-1, 1] ... */
            assert_true(ra.lo >= -1.0 && ra.hi <= 1.0);
            assert_true(ri.lo >= -1.0 && ri.hi <= 1.0);
            /* ... and the whole of it (each range holds a full period,
             * except [-3.5, 3.5] for cos, which reaches only cos(3.5)) */
            if (!(f == 1 && lo == -3.5)) {
                assert_true(ra.lo == -1.0 && ra.hi == 1.0);
                assert_true(ri.lo == -1.0 && ri.hi == 1.0);
            }
            /* continuous: no flag */
            assert_false(z.flags & AA_DISCONTINUOUS);
            assert_false(ri.flags & AA_DISCONTINUOUS);
        }
    }
}

/* ---- flags ---- */

/* a fresh context and two inputs over [xl, xh] and [yl, yh] */
static void two_inputs(aa_context *ctx, aa_form *x, aa_form *y, double xl, double xh, double yl,
                       double yh)
{
    aa_context_init(ctx, AA_DEFAULT_CAPACITY);
    aa_input(ctx, x, xl, xh);
    aa_input(ctx, y, yl, yh);
}

static unsigned aa_unary_flags(void (*f)(aa_context *, aa_form *, const aa_form *), double lo,
                               double hi, ia_interval *range)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form x, z;
    aa_input(&ctx, &x, lo, hi);
    f(&ctx, &z, &x);
    *range = aa_range(&z);
    return z.flags;
}

static void test_flags(void **state)
{
    (void)state;
    ia_interval r;

    /* merge always flags */
    {
        aa_context ctx;
        aa_form x, y, z;
        two_inputs(&ctx, &x, &y, 0.0, 1.0, 2.0, 3.0);
        aa_merge(&ctx, &z, &x, &y);
        assert_true(z.flags & AA_DISCONTINUOUS);
        r = aa_range(&z);
        assert_true(r.lo <= 0.0 && r.hi >= 3.0);
        aa_merge(&ctx, &z, &x, &x);
        assert_true(z.flags & AA_DISCONTINUOUS);
        ia_interval m = ia_merge(ia_make(0.0, 1.0), ia_make(2.0, 3.0));
        assert_true(m.flags & AA_DISCONTINUOUS);
        assert_true(m.lo <= 0.0 && m.hi >= 3.0);
    }

    /* floor over [0.2, 0.7]: exactly 0, no flag */
    assert_int_equal(aa_unary_flags(aa_floor, 0.2, 0.7, &r), 0);
    assert_true(r.lo == 0.0 && r.hi == 0.0);
    r = ia_floor(ia_make(0.2, 0.7));
    assert_int_equal(r.flags, 0);
    assert_true(r.lo == 0.0 && r.hi == 0.0);

    /* floor over [0.5, 1.5]: a jump inside */
    assert_true(aa_unary_flags(aa_floor, 0.5, 1.5, &r) & AA_DISCONTINUOUS);
    assert_true(r.lo <= 0.0 && r.hi >= 1.0);
    assert_true(ia_floor(ia_make(0.5, 1.5)).flags & AA_DISCONTINUOUS);
    assert_true(ia_ceil(ia_make(0.5, 1.5)).flags & AA_DISCONTINUOUS);
    assert_true(ia_round(ia_make(0.2, 0.7)).flags & AA_DISCONTINUOUS);
    assert_int_equal(ia_round(ia_make(0.6, 1.4)).flags, 0);
    assert_true(ia_sign(ia_make(-1.0, 1.0)).flags & AA_DISCONTINUOUS);
    assert_int_equal(ia_sign(ia_make(0.5, 1.0)).flags, 0);
    assert_true(aa_unary_flags(aa_sign, -1.0, 1.0, &r) & AA_DISCONTINUOUS);
    assert_int_equal(aa_unary_flags(aa_sign, 0.5, 1.0, &r), 0);

    /* continuous functions over ordinary ranges: no flag */
    assert_int_equal(aa_unary_flags(aa_sin, -3.0, 2.0, &r), 0);
    assert_int_equal(aa_unary_flags(aa_exp, -3.0, 2.0, &r), 0);
    assert_int_equal(aa_unary_flags(aa_sqrt, 0.5, 2.0, &r), 0);
    assert_int_equal(ia_sin(ia_make(-3.0, 2.0)).flags, 0);
    assert_int_equal(ia_exp(ia_make(-3.0, 2.0)).flags, 0);
    assert_int_equal(ia_log(ia_make(0.5, 2.0)).flags, 0);

    /* creases (AA_KINK, continuous): abs across 0, a min or max whose
     * operands' ranges overlap; none where the function is smooth over
     * the range */
    assert_int_equal(aa_unary_flags(aa_abs, -3.0, 2.0, &r), AA_KINK);
    assert_int_equal(aa_unary_flags(aa_abs, 0.5, 2.0, &r), 0);
    assert_int_equal(aa_unary_flags(aa_abs, -2.0, -0.5, &r), 0);
    assert_int_equal(ia_abs(ia_make(-3.0, 2.0)).flags, AA_KINK);
    assert_int_equal(ia_abs(ia_make(0.0, 2.0)).flags, 0);
    assert_int_equal(ia_min(ia_make(0.0, 2.0), ia_make(1.0, 3.0)).flags, AA_KINK);
    assert_int_equal(ia_max(ia_make(0.0, 2.0), ia_make(1.0, 3.0)).flags, AA_KINK);
    assert_int_equal(ia_min(ia_make(0.0, 1.0), ia_make(1.0, 3.0)).flags, 0);
    assert_int_equal(ia_max(ia_make(0.0, 1.0), ia_make(2.0, 3.0)).flags, 0);
    {
        aa_context ctx;
        aa_form x, y, z;
        two_inputs(&ctx, &x, &y, 0.0, 2.0, 1.0, 3.0);
        aa_min(&ctx, &z, &x, &y);
        assert_int_equal(z.flags, AA_KINK);
        aa_max(&ctx, &z, &x, &y);
        assert_int_equal(z.flags, AA_KINK);
        aa_add_s(&ctx, &y, &y, 2.0);          /* [3, 5]: decided */
        aa_min(&ctx, &z, &x, &y);
        assert_int_equal(z.flags, 0);
        aa_form lo, hi;
        aa_const(&lo, 0.5);
        aa_const(&hi, 1.5);
        aa_clamp(&ctx, &z, &x, &lo, &hi);
        assert_int_equal(z.flags, AA_KINK);
    }

    /* step: edge inside the range of x or not */
    {
        aa_context ctx;
        aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
        aa_form e, x, z;
        aa_const(&e, 0.5);
        aa_input(&ctx, &x, 0.0, 1.0);
        aa_step(&ctx, &z, &e, &x);
        assert_true(z.flags & AA_DISCONTINUOUS);
        r = aa_range(&z);
        assert_true(r.lo <= 0.0 && r.hi >= 1.0);
        aa_const(&e, -0.5);
        aa_step(&ctx, &z, &e, &x);
        assert_int_equal(z.flags, 0);
        r = aa_range(&z);
        assert_true(r.lo <= 1.0 && r.hi >= 1.0 && r.lo > 0.5);
        assert_true(ia_step(ia_point(0.5), ia_make(0.0, 1.0)).flags & AA_DISCONTINUOUS);
        assert_int_equal(ia_step(ia_point(2.0), ia_make(0.0, 1.0)).flags, 0);
    }

    /* a division by a range that holds 0 has a pole there, as tan has:
     * unbounded and discontinuous, and the flag survives an operation
     * that bounds the value again (atan(y / x), x across 0: the renderer
     * takes the box for a seam, not for a smooth piece that will shrink) */
    {
        aa_context ctx;
        aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
        aa_form x, y, z, a;
        aa_input(&ctx, &x, -0.5, 1.0);
        aa_input(&ctx, &y, 0.25, 0.75);
        aa_div(&ctx, &z, &y, &x);
        assert_true(z.flags & AA_UNBOUNDED);
        assert_true(z.flags & AA_DISCONTINUOUS);
        aa_atan(&ctx, &a, &z);
        assert_true(a.flags & AA_DISCONTINUOUS);
        r = aa_range(&a);
        assert_true(isfinite(r.lo) && isfinite(r.hi));
        assert_true(aa_unary_flags(aa_recip, -1.0, 2.0, &r) & AA_DISCONTINUOUS);
        /* away from the pole: no flag */
        aa_input(&ctx, &x, 0.5, 1.0);
        aa_div(&ctx, &z, &y, &x);
        assert_int_equal(z.flags, 0);
        assert_int_equal(aa_unary_flags(aa_recip, 1.0, 2.0, &r), 0);
        assert_true(ia_div(ia_make(1.0, 2.0), ia_make(-1.0, 1.0)).flags & AA_DISCONTINUOUS);
        assert_true(ia_recip(ia_make(-1.0, 1.0)).flags & AA_DISCONTINUOUS);
        assert_int_equal(ia_div(ia_make(1.0, 2.0), ia_make(0.5, 1.0)).flags, 0);
        assert_int_equal(ia_recip(ia_make(0.5, 1.0)).flags, 0);
    }

    /* smoothstep is continuous where e0 < e1 */
    {
        aa_context ctx;
        aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
        aa_form e0, e1, x, z;
        aa_const(&e0, 0.25);
        aa_const(&e1, 0.75);
        aa_input(&ctx, &x, 0.0, 1.0);
        aa_smoothstep(&ctx, &z, &e0, &e1, &x);
        assert_int_equal(z.flags & AA_DISCONTINUOUS, 0);
        r = aa_range(&z);
        assert_true(r.lo <= 0.0 && r.hi >= 1.0);
        assert_int_equal(ia_smoothstep(ia_point(0.25), ia_point(0.75), ia_make(0.0, 1.0)).flags
                         & AA_DISCONTINUOUS, 0);
    }

    /* division by a range holding 0 */
    {
        aa_context ctx;
        aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
        aa_form x, z;
        aa_input(&ctx, &x, -1.0, 2.0);
        aa_recip(&ctx, &z, &x);
        assert_true(z.flags & AA_UNBOUNDED);
        assert_true(ia_recip(ia_make(-1.0, 2.0)).flags & AA_UNBOUNDED);
        assert_true(ia_div(ia_point(1.0), ia_make(0.0, 2.0)).flags & AA_UNBOUNDED);
    }
}

/* ---- condensation: capacity 2 against 16 ---- */

/* p = x*x*x - x (which = 0) or (x*x)*(x*x) - x*x (which = 1), x = (u+v)/2 with
 * inputs u, v over [0, 1]. Returns the range; checks soundness on a grid of
 * (u, v), also symbol by symbol: with eps_u = 2u-1 and eps_v = 2v-1 the value
 * must lie in z0 + c_u*eps_u + c_v*eps_v +- (other symbols + err). */
static ia_interval condensed_poly(int capacity, int which, long *folded, long *bad)
{
    aa_context ctx;
    aa_context_init(&ctx, capacity);
    aa_form u, v, x, t, c, p;
    aa_input(&ctx, &u, 0.0, 1.0);
    aa_input(&ctx, &v, 0.0, 1.0);
    aa_lincomb(&ctx, &x, 0.5, &u, 0.5, &v, 0.0);
    aa_mul(&ctx, &t, &x, &x);
    if (which == 0) {
        aa_mul(&ctx, &c, &t, &x);
        aa_sub(&ctx, &p, &c, &x);
    } else {
        aa_form t2 = t;
        aa_mul(&ctx, &c, &t, &t2);
        aa_sub(&ctx, &p, &c, &t);
    }
    *folded = ctx.folded;
    ia_interval r = aa_range(&p);

    /* which symbols are u and v: the ones x uses */
    int su = -1, sv = -1;
    for (int i = 0; i < u.n; i++)
        if (u.c[i] != 0)
            su = i;
    for (int i = 0; i < v.n; i++)
        if (v.c[i] != 0)
            sv = i;
    long double rest = p.err;
    for (int i = 0; i < p.n; i++)
        if (i != su && i != sv)
            rest += fabsl((long double)p.c[i]);
    for (int i = 0; i <= 64; i++) {
        for (int j = 0; j <= 64; j++) {
            long double uu = i / 64.0L, vv = j / 64.0L, xx = (uu + vv) / 2;
            long double val = which == 0 ? xx * xx * xx - xx : xx * xx * xx * xx - xx * xx;
            long double eu = 2 * uu - 1, ev = 2 * vv - 1;
            long double ctr = p.x0;
            if (su >= 0 && su < p.n)
                ctr += p.c[su] * eu;
            if (sv >= 0 && sv < p.n)
                ctr += p.c[sv] * ev;
            long double slack = 1e-15L * (1 + fabsl(ctr) + rest);
            if (!(val >= r.lo && val <= r.hi) || fabsl(val - ctr) > rest + slack)
                (*bad)++;
        }
    }
    return r;
}

static void test_condensation(void **state)
{
    (void)state;
    static const char *names[2] = {"x*x*x - x", "(x*x)*(x*x) - x*x"};
    for (int which = 0; which < 2; which++) {
        long f2, f4, f16, bad = 0;
        ia_interval r2 = condensed_poly(2, which, &f2, &bad);
        ia_interval r4 = condensed_poly(4, which, &f4, &bad);
        ia_interval r16 = condensed_poly(16, which, &f16, &bad);
        printf("%s over [0,1], x = (u+v)/2: capacity 2 [%.6f, %.6f] width %.6f (folded %ld); "
               "capacity 4 width %.6f (folded %ld); capacity 16 [%.6f, %.6f] width %.6f "
               "(folded %ld)\n", names[which], r2.lo, r2.hi, width_ia(r2), f2, width_ia(r4), f4,
               r16.lo, r16.hi, width_ia(r16), f16);
        assert_int_equal(bad, 0);
        /* the true range holds 0 and min(x^3 - x) = -0.3849 or min(x^4 - x^2) = -1/4 */
        assert_true(r2.hi >= 0.0 && r16.hi >= 0.0);
        double tmin = which == 0 ? -0.38490017945975052 : -0.25;
        assert_true(r2.lo <= tmin && r16.lo <= tmin);
        /* reduced: errors were folded; capacity 16 had room for all */
        assert_true(f2 > 0);
        assert_int_equal(f16, 0);
        assert_true(width_ia(r16) <= width_ia(r2) * (1 + 1e-12));
    }
}

/* ---- closed-form sqrt and exp: the minimax error ---- */

/*
 * For a convex or concave f on [a, b] the best linear approximation has the
 * secant's slope alpha, and its error is half the spread of
 * g(t) = f(t) - alpha*t: between g at the ends and g at the tangent point.
 * sqrt: g(a) = sqrt(a) - alpha a, g max = 1/(4 alpha) with
 * alpha = 1/(sqrt a + sqrt b); exp: g(a) = e^a - alpha a, g min =
 * alpha (1 - ln alpha); inversesqrt: g(a) = a^(-1/2) - alpha a, g min =
 * 1.5 (-2 alpha)^(1/3). The new symbol's coefficient must be within 1e-9
 * (relative, plus a few ulps of the values) of that half spread: not
 * smaller (unsound) and not wider (the closed form lost tightness).
 * The tolerance allows for the rounding of f's values (64 ulps of the
 * largest), which dominates over ranges a millionth wide.
 */
static void check_minimax(const char *name, double a, double b, int is_exp)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form x, z;
    aa_input(&ctx, &x, a, b);
    if (is_exp == 2)
        aa_invsqrt(&ctx, &z, &x);
    else if (is_exp)
        aa_exp(&ctx, &z, &x);
    else
        aa_sqrt(&ctx, &z, &x);
    long double la = a, lb = b, alpha, gend, gext;
    if (is_exp == 2) {
        alpha = (1.0L / sqrtl(lb) - 1.0L / sqrtl(la)) / (lb - la);
        gend = 1.0L / sqrtl(la) - alpha * la;
        gext = 1.5L * cbrtl(-2.0L * alpha);
    } else if (is_exp) {
        alpha = (expl(lb) - expl(la)) / (lb - la);
        gend = expl(la) - alpha * la;
        gext = alpha * (1.0L - logl(alpha));
    } else {
        alpha = 1.0L / (sqrtl(la) + sqrtl(lb));
        gend = sqrtl(la) - alpha * la;
        gext = 1.0L / (4.0L * alpha);
    }
    long double want = fabsl(gext - gend) / 2.0L;
    long double scale = is_exp == 2 ? 1.0L / sqrtl(la) : is_exp ? expl(lb) : sqrtl(lb);
    /* the linear approximation is kept (one new symbol after the input) */
    assert_int_equal(z.n, 2);
    double delta = z.c[1];
    long double slope = (long double)z.c[0] / (long double)x.c[0];
    printf("%s over [%g, %g]: delta %.17g, minimax %.17Lg, slope %.17Lg (secant %.17Lg)\n",
           name, a, b, delta, want, slope, alpha);
    long double tol = 1e-9L * want + 64.0L * 0x1p-53L * scale;
    assert_true((long double)delta >= want - tol);
    assert_true((long double)delta <= want + tol);
    /* the slope is the secant's, up to the rounding of f at the ends */
    assert_true(fabsl(slope - alpha) <= 1e-12L * fabsl(alpha) + 16.0L * 0x1p-53L * scale / (lb - la));
}

static void test_closed_form_minimax(void **state)
{
    (void)state;
    static const double r[][2] = {
        {0.25, 0.5}, {1.0, 4.0}, {0.0, 1.0}, {1e-6, 2e-6}, {100.0, 100.5}, {3.0, 3.0 + 1e-6},
    };
    for (size_t i = 0; i < sizeof r / sizeof r[0]; i++)
        check_minimax("sqrt", r[i][0], r[i][1], 0);
    static const double e[][2] = {
        {-1.0, 1.0}, {0.0, 0.1}, {-20.0, -19.0}, {5.0, 5.5}, {-0.75, -0.5}, {2.0, 2.0 + 1e-6},
    };
    for (size_t i = 0; i < sizeof e / sizeof e[0]; i++)
        check_minimax("exp", e[i][0], e[i][1], 1);
    static const double q[][2] = {
        {0.25, 0.5}, {1.0, 4.0}, {1e-6, 2e-6}, {100.0, 100.5}, {3.0, 3.0 + 1e-6}, {0.5, 5.0},
    };
    for (size_t i = 0; i < sizeof q / sizeof q[0]; i++)
        check_minimax("inversesqrt", q[i][0], q[i][1], 2);
}

/* ---- ia_mul: the sign cases against the four corners ---- */

static double random_end(void)
{
    switch (rng_next() % 8) {
    case 0: return 0.0;
    case 1: return (rng_next() & 1) ? INFINITY : -INFINITY;
    case 2: return (rng_unit() - 0.5) * 0x1p-1060;          /* subnormal products */
    case 3: return (rng_unit() - 0.5) * 0x1p1000;           /* overflowing ones */
    default: return 20.0 * rng_unit() - 10.0;
    }
}

static void test_ia_mul_corners(void **state)
{
    (void)state;
    long differ = 0;
    for (int i = 0; i < 200000; i++) {
        double a = random_end(), b = random_end(), c = random_end(), d = random_end();
        ia_interval x = ia_make(fmin(a, b), fmax(a, b)), y = ia_make(fmin(c, d), fmax(c, d));
        if (i % 7 == 0)
            y = x;
        ia_interval got = ia_mul(x, y);
        double p[4][2] = {{x.lo, y.lo}, {x.lo, y.hi}, {x.hi, y.lo}, {x.hi, y.hi}};
        double lo = INFINITY, hi = -INFINITY;
        int tiny = 0;           /* a corner of nonzero factors that rounds to 0 */
        for (int k = 0; k < 4; k++) {
            lo = fmin(lo, fp_mul_dn(p[k][0], p[k][1]));
            hi = fmax(hi, fp_mul_up(p[k][0], p[k][1]));
            tiny |= p[k][0] != 0.0 && p[k][1] != 0.0 && p[k][0] * p[k][1] == 0.0;
        }
        /* never wider than the corners (which are sound) */
        assert_true(got.lo >= lo && got.hi <= hi);
        if (!tiny && !(got.lo == lo && got.hi == hi))
            differ++;
        /* the same for ia_div, whose divisor has one sign */
        if (!(y.lo > 0.0 || y.hi < 0.0))
            continue;
        got = ia_div(x, y);
        lo = INFINITY;
        hi = -INFINITY;
        tiny = 0;
        for (int k = 0; k < 4; k++) {
            lo = fmin(lo, fp_div_dn(p[k][0], p[k][1]));
            hi = fmax(hi, fp_div_up(p[k][0], p[k][1]));
            tiny |= (p[k][0] != 0.0 && p[k][0] / p[k][1] == 0.0) ||
                    (isinf(p[k][0]) && isinf(p[k][1]));
        }
        assert_true(got.lo >= lo && got.hi <= hi);
        if (!tiny && !(got.lo == lo && got.hi == hi))
            differ++;
    }
    assert_int_equal(differ, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_x_minus_x_is_zero),
        cmocka_unit_test(test_lincomb3_centred_bitwise),
        cmocka_unit_test(test_x_times_one_minus_x),
        cmocka_unit_test(test_difference_of_squares),
        cmocka_unit_test(test_power_of_two_scale_exact),
        cmocka_unit_test(test_sqr_symmetric),
        cmocka_unit_test(test_sin_cos_full_period),
        cmocka_unit_test(test_flags),
        cmocka_unit_test(test_condensation),
        cmocka_unit_test(test_closed_form_minimax),
        cmocka_unit_test(test_ia_mul_corners),
    };
    return cmocka_run_group_tests_name("aa_tightness", tests, NULL, NULL);
}

/*
 * tests/aa/test_aa_rounding.c: unit tests of common/aa/rounding.h, the
 * floating-point facts every bound of the aa library rests on.
 *
 *   fp_next_up / fp_next_down   against C's nextafter() and by hand at the edge
 *                               cases: +0, -0, the smallest subnormal, the
 *                               subnormal/normal boundary, DBL_MAX, +-inf, NaN
 *   fp_up_by / fp_down_by       k steps, k = 0
 *   bit-step fast paths         fp_next_up, fp_up_by/fp_down_by and fp_mul_dn/up
 *                               against their one-step definitions at zero,
 *                               subnormal, exponent and overflow edges
 *   fp_add_dn / fp_add_up       exact directed roundings: checked against the
 *                               exact sum recovered with TwoSum, including at
 *                               overflow, in the subnormal range and at +-inf;
 *                               and bit for bit against their one-step
 *                               definition (s, or fp_next_up/down(s) when
 *                               TwoSum says s was rounded the other way)
 *   fp_mul_dn/up, fp_div_dn/up  bound the exact product / quotient (fma, long
 *                               double), at most one step outward, and follow
 *                               the documented conventions (0 * inf = 0,
 *                               a / inf = 0, overflow -> DBL_MAX or inf)
 *   fp_two_sum_err              s + e == a + b exactly (checked in long double
 *                               where the sum is exact there)
 *   fp_rounding_bound           bounds the actual accumulated error of random
 *                               sequences of RN products and sums, including in
 *                               the subnormal range
 *
 * Random inputs come from a fixed-seed xoshiro256** generator.
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

#include "aa/rounding.h"
#include "test_rng.h"

_Static_assert(LDBL_MANT_DIG >= 64, "these checks need an extended long double");

/* ---- a small fixed-seed generator (splitmix64 seeding xoshiro256**) ---- */

static uint64_t rng_state[4];

static uint64_t splitmix64(uint64_t *x)
{
    return test_rng_next(x);
}

static void rng_seed(uint64_t seed)
{
    for (int i = 0; i < 4; i++)
        rng_state[i] = splitmix64(&seed);
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

static uint64_t rng_next(void)
{
    uint64_t *s = rng_state;
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

static double bits_to_double(uint64_t b)
{
    double d;
    memcpy(&d, &b, sizeof d);
    return d;
}

static uint64_t double_to_bits(double d)
{
    uint64_t b;
    memcpy(&b, &d, sizeof b);
    return b;
}

/* A random finite double: random bit patterns (all exponents, subnormals
 * included), NaN and inf rejected. */
static double random_finite(void)
{
    for (;;) {
        double d = bits_to_double(rng_next());
        if (isfinite(d))
            return d;
    }
}

/* A random double with a 26-bit significand and an exponent in [emin, emax],
 * random sign: products of two of them are exact in long double. */
static double random_short(int emin, int emax)
{
    uint64_t m = (rng_next() >> 38) | (1u << 25);            /* 26 bits */
    int e = emin + (int)(rng_next() % (uint64_t)(emax - emin + 1));
    double d = ldexp((double)m, e - 25);
    return (rng_next() & 1) ? -d : d;
}

/* Same bits (distinguishes -0 from +0 and compares NaNs as equal). */
static double rng_sign_d(void)
{
    return (rng_next() & 1) ? -1.0 : 1.0;
}

static int same_double(double a, double b)
{
    if (isnan(a) && isnan(b))
        return 1;
    return double_to_bits(a) == double_to_bits(b);
}

#define SMALLEST_SUBNORMAL 0x1p-1074
#define LARGEST_SUBNORMAL 0x0.fffffffffffffp-1022

/* ---- fp_next_up / fp_next_down ---- */

static void test_next_edge_cases(void **state)
{
    (void)state;
    /* zeros: both step to the smallest subnormal of the right sign */
    assert_true(same_double(fp_next_up(0.0), SMALLEST_SUBNORMAL));
    assert_true(same_double(fp_next_up(-0.0), SMALLEST_SUBNORMAL));
    assert_true(same_double(fp_next_down(0.0), -SMALLEST_SUBNORMAL));
    assert_true(same_double(fp_next_down(-0.0), -SMALLEST_SUBNORMAL));

    /* the smallest subnormals step to zero and beyond */
    assert_true(fp_next_up(-SMALLEST_SUBNORMAL) == 0.0);
    assert_true(fp_next_down(SMALLEST_SUBNORMAL) == 0.0);
    assert_true(same_double(fp_next_up(SMALLEST_SUBNORMAL), 0x1p-1073));
    assert_true(same_double(fp_next_down(-SMALLEST_SUBNORMAL), -0x1p-1073));

    /* subnormal <-> normal boundary */
    assert_true(same_double(fp_next_up(LARGEST_SUBNORMAL), DBL_MIN));
    assert_true(same_double(fp_next_down(DBL_MIN), LARGEST_SUBNORMAL));
    assert_true(same_double(fp_next_down(-LARGEST_SUBNORMAL), -DBL_MIN));
    assert_true(same_double(fp_next_up(-DBL_MIN), -LARGEST_SUBNORMAL));

    /* around 1 the step is 2^-52 above and 2^-53 below */
    assert_true(same_double(fp_next_up(1.0), 1.0 + 0x1p-52));
    assert_true(same_double(fp_next_down(1.0), 1.0 - 0x1p-53));
    assert_true(same_double(fp_next_up(-1.0), -1.0 + 0x1p-53));
    assert_true(same_double(fp_next_down(-1.0), -1.0 - 0x1p-52));

    /* the top of the range and infinities */
    assert_true(same_double(fp_next_up(DBL_MAX), INFINITY));
    assert_true(same_double(fp_next_down(-DBL_MAX), -INFINITY));
    assert_true(same_double(fp_next_up(INFINITY), INFINITY));
    assert_true(same_double(fp_next_down(-INFINITY), -INFINITY));
    assert_true(same_double(fp_next_down(INFINITY), DBL_MAX));
    assert_true(same_double(fp_next_up(-INFINITY), -DBL_MAX));
    assert_true(same_double(fp_next_down(DBL_MAX), nextafter(DBL_MAX, 0.0)));

    /* NaN stays NaN */
    assert_true(isnan(fp_next_up(NAN)));
    assert_true(isnan(fp_next_down(NAN)));
    assert_true(isnan(fp_next_up(-NAN)));
}

static void test_next_matches_nextafter(void **state)
{
    (void)state;
    rng_seed(0x5eed0001u);
    long mismatches = 0;
    for (int i = 0; i < 1000000; i++) {
        double x;
        switch (i % 4) {
        case 0:  x = random_finite(); break;                         /* any bits */
        case 1:  x = bits_to_double(rng_next() % 0x0010000000000010u); break; /* subnormal */
        case 2:  x = -bits_to_double(rng_next() % 0x0010000000000010u); break;
        default: x = random_short(-30, 30); break;
        }
        double up = fp_next_up(x), down = fp_next_down(x);
        double want_up = nextafter(x, INFINITY), want_down = nextafter(x, -INFINITY);
        /* nextafter(-min_subnormal, +inf) is -0, fp_next_up gives -0 as well;
         * compare values, and bits where the value is non-zero. */
        if (!(up == want_up && (up == 0.0 || same_double(up, want_up))) ||
            !(down == want_down && (down == 0.0 || same_double(down, want_down)))) {
            if (mismatches < 5)
                printf("next mismatch at %a: up %a (want %a), down %a (want %a)\n",
                       x, up, want_up, down, want_down);
            mismatches++;
        }
        /* strictly ordered, adjacent */
        if (!(down < x && x < up)) {
            if (mismatches < 5)
                printf("next not ordered at %a: %a %a\n", x, down, up);
            mismatches++;
        }
    }
    assert_int_equal(mismatches, 0);
}

static void test_up_by_down_by(void **state)
{
    (void)state;
    assert_true(same_double(fp_up_by(1.0, 0), 1.0));
    assert_true(same_double(fp_down_by(-2.5, 0), -2.5));
    assert_true(same_double(fp_up_by(0.0, 3), 0x3p-1074));
    assert_true(same_double(fp_down_by(0.0, 3), -0x3p-1074));
    assert_true(same_double(fp_up_by(-0x2p-1074, 4), 0x2p-1074));
    assert_true(same_double(fp_up_by(DBL_MAX, 4), INFINITY));
    assert_true(same_double(fp_down_by(-DBL_MAX, 2), -INFINITY));
    assert_true(same_double(fp_down_by(INFINITY, 1), DBL_MAX));
    assert_true(same_double(fp_up_by(1.0, 4), 1.0 + 0x4p-52));
    assert_true(same_double(fp_down_by(1.0, 4), 1.0 - 0x4p-53));

    rng_seed(0x5eed0002u);
    for (int i = 0; i < 100000; i++) {
        double x = random_finite();
        int k = (int)(rng_next() % 9);
        double a = x, b = x;
        for (int j = 0; j < k; j++) {
            a = nextafter(a, INFINITY);
            b = nextafter(b, -INFINITY);
        }
        assert_true(fp_up_by(x, k) == a);
        assert_true(fp_down_by(x, k) == b);
    }
}

/*
 * The integer fast paths of fp_next_up, fp_up_by/fp_down_by and fp_mul_dn
 * (bits plus or minus k for finite nonzero values) against their one-step
 * definitions, at the places a bit step could go wrong: crossing zero, the
 * subnormal/normal boundary, exponent boundaries, the largest double and the
 * infinities.
 */
static double ref_up_by(double x, int k)
{
    while (k-- > 0)
        x = x != x || x == INFINITY ? x : x == 0.0 ? SMALLEST_SUBNORMAL : nextafter(x, INFINITY);
    return x;
}

/* fp_mul_dn's documented meaning: 0 for a zero factor, DBL_MAX for a
 * positive overflow of finite factors, else RN stepped down once */
static double ref_mul_dn(double a, double b)
{
    if (a == 0.0 || b == 0.0)
        return 0.0;
    double p = a * b;
    if (isinf(p) && isfinite(a) && isfinite(b))
        return p > 0 ? DBL_MAX : -INFINITY;
    if (p != p || p == -INFINITY)
        return p;
    return p == 0.0 ? -SMALLEST_SUBNORMAL : nextafter(p, -INFINITY);
}

static void test_bit_steps_at_edges(void **state)
{
    (void)state;
    double edges[64];
    int ne = 0;
    for (int k = 0; k <= 5; k++)
        edges[ne++] = k * SMALLEST_SUBNORMAL;
    edges[ne++] = LARGEST_SUBNORMAL;
    edges[ne++] = DBL_MIN;
    edges[ne++] = nextafter(DBL_MIN, INFINITY);
    edges[ne++] = 1.0;
    edges[ne++] = nextafter(1.0, 0.0);
    edges[ne++] = 0x1p-1021;
    for (int k = 0; k <= 4; k++)
        edges[ne++] = DBL_MAX - k * 0x1p971;           /* the last few doubles */
    edges[ne++] = INFINITY;
    int n0 = ne;
    for (int i = 0; i < n0; i++)
        edges[ne++] = -edges[i];
    long bad = 0;
    for (int i = 0; i < ne; i++) {
        double x = edges[i];
        if (!same_double(fp_next_up(x), ref_up_by(x, 1)))
            bad++;
        for (int k = 0; k <= 6; k++) {
            if (!same_double(fp_up_by(x, k), ref_up_by(x, k)))
                bad++;
            if (!same_double(fp_down_by(x, k), -ref_up_by(-x, k)))
                bad++;
        }
    }
    /* products at the same edges: zero factors, underflow to 0 and to
     * subnormals, overflow, infinities, both signs */
    static const double f[] = {0.0, -0.0, 0x1p-600, 0x1p-537, 0x1p-300, 0.5, 1.0, 3.0,
                               0x1p500, 0x1p600, DBL_MAX, INFINITY};
    int nf = (int)(sizeof f / sizeof f[0]);
    for (int i = 0; i < nf; i++)
        for (int j = 0; j < nf; j++)
            for (int sg = 0; sg < 4; sg++) {
                double a = (sg & 1) ? -f[i] : f[i], b = (sg & 2) ? -f[j] : f[j];
                if (!same_double(fp_mul_dn(a, b), ref_mul_dn(a, b)) ||
                    !same_double(fp_mul_up(a, b), -ref_mul_dn(-a, b))) {
                    if (bad < 5)
                        printf("fp_mul_dn(%a, %a) = %a, want %a\n", a, b, fp_mul_dn(a, b),
                               ref_mul_dn(a, b));
                    bad++;
                }
            }
    assert_int_equal(bad, 0);
}

/* ---- directed operations ---- */

/*
 * r is the rounding of the exact a+b = s + e downward (dir < 0) or upward
 * (dir > 0): r <= s + e < next_up(r), resp. next_down(r) < s + e <= r.
 * r is s or a neighbour of s, so r - s and its neighbours' differences with s
 * are exact in double.
 */
static int is_directed_sum(double r, double s, double e, int dir)
{
    if (dir < 0)
        return r - s <= e && fp_next_up(r) - s > e;
    return r - s >= e && fp_next_down(r) - s < e;
}

static void test_add_directed(void **state)
{
    (void)state;
    /* exact sums are not widened: x - x stays 0, 1 + 1 stays 2 */
    assert_true(fp_add_up(1.0, 1.0) == 2.0);
    assert_true(fp_add_dn(1.0, 1.0) == 2.0);
    assert_true(fp_add_up(3.25, -3.25) == 0.0);
    assert_true(fp_add_dn(3.25, -3.25) == 0.0);
    assert_true(fp_add_up(0.0, 0.0) == 0.0);
    assert_true(fp_add_dn(-0.0, 0.0) == 0.0);
    /* inexact sums are rounded outward by exactly one step */
    assert_true(fp_add_up(1.0, 0x1p-60) == 1.0 + 0x1p-52);
    assert_true(fp_add_dn(1.0, 0x1p-60) == 1.0);
    assert_true(fp_add_dn(1.0, -0x1p-60) == 1.0 - 0x1p-53);
    assert_true(fp_add_up(1.0, -0x1p-60) == 1.0);
    /* a tie (1 + 2^-53 rounds to 1 in RN) */
    assert_true(fp_add_up(1.0, 0x1p-53) == 1.0 + 0x1p-52);
    assert_true(fp_add_dn(1.0, 0x1p-53) == 1.0);
    /* subnormal sums are exact */
    assert_true(fp_add_up(SMALLEST_SUBNORMAL, SMALLEST_SUBNORMAL) == 0x1p-1073);
    assert_true(fp_add_dn(LARGEST_SUBNORMAL, SMALLEST_SUBNORMAL) == DBL_MIN);
    assert_true(fp_add_dn(SMALLEST_SUBNORMAL, -SMALLEST_SUBNORMAL) == 0.0);
    /* overflow of finite operands: DBL_MAX on the inner side, inf outside */
    assert_true(fp_add_up(DBL_MAX, DBL_MAX) == INFINITY);
    assert_true(fp_add_dn(DBL_MAX, DBL_MAX) == DBL_MAX);
    assert_true(fp_add_dn(-DBL_MAX, -DBL_MAX) == -INFINITY);
    assert_true(fp_add_up(-DBL_MAX, -DBL_MAX) == -DBL_MAX);
    assert_true(fp_add_dn(DBL_MAX, 0x1p970) == DBL_MAX);      /* RN would round up to inf */
    assert_true(fp_add_up(DBL_MAX, 0x1p969) == INFINITY);     /* RN keeps DBL_MAX */
    /* infinite operands stand for unbounded ends */
    assert_true(fp_add_up(INFINITY, 1.0) == INFINITY);
    assert_true(fp_add_dn(INFINITY, 1.0) == INFINITY);
    assert_true(fp_add_dn(-INFINITY, 1.0) == -INFINITY);
    assert_true(fp_add_up(-INFINITY, -1.0) == -INFINITY);

    rng_seed(0x5eed0003u);
    long bad = 0;
    for (int i = 0; i < 1000000; i++) {
        double a, b;
        switch (i % 4) {
        case 0:
            a = random_finite() * 0x1p-4;       /* any exponent, no overflow */
            b = random_finite() * 0x1p-4;
            break;
        case 1: {                                /* the top of the range */
            a = ldexp(frexp(random_finite(), &(int){0}), 1024 - (int)(rng_next() % 8));
            b = ldexp(frexp(random_finite(), &(int){0}), 1024 - (int)(rng_next() % 60));
            if (!isfinite(a + b))
                continue;
            break;
        }
        case 2:                                  /* subnormal and near it */
            a = bits_to_double(rng_next() % 0x0030000000000000u) * rng_sign_d();
            b = bits_to_double(rng_next() % 0x0030000000000000u) * rng_sign_d();
            break;
        default: {
            int e = (int)(rng_next() % 1900) - 950;
            a = random_short(e - 40, e + 40);
            b = random_short(e - 40, e + 40);
            break;
        }
        }
        double s = a + b, e = fp_two_sum_err(a, b, s);
        double up = fp_add_up(a, b), dn = fp_add_dn(a, b);
        double up1 = e > 0 ? fp_next_up(s) : s, dn1 = e < 0 ? fp_next_down(s) : s;
        if (memcmp(&up, &up1, sizeof up) != 0 || memcmp(&dn, &dn1, sizeof dn) != 0) {
            if (bad < 5)
                printf("add directed not its one-step definition: %a + %a: dn %a (%a) up %a "
                       "(%a)\n", a, b, dn, dn1, up, up1);
            bad++;
        }
        if (isnan(e) || !is_directed_sum(dn, s, e, -1) || !is_directed_sum(up, s, e, +1)) {
            if (bad < 5)
                printf("add directed wrong: %a + %a: dn %a up %a (s %a e %a)\n", a, b, dn, up,
                       s, e);
            bad++;
        }
    }
    assert_int_equal(bad, 0);
}

static void test_mul_directed(void **state)
{
    (void)state;
    /* a zero operand gives exactly 0, also against infinity (the limit) */
    assert_true(fp_mul_up(0.0, 5.0) == 0.0);
    assert_true(fp_mul_dn(0.0, 5.0) == 0.0);
    assert_true(fp_mul_dn(0.0, INFINITY) == 0.0);
    assert_true(fp_mul_up(-INFINITY, 0.0) == 0.0);
    /* products step outward (not tight, but safe) */
    assert_true(fp_mul_up(3.0, 0.5) >= 1.5 && fp_mul_up(3.0, 0.5) <= fp_next_up(1.5));
    assert_true(fp_mul_dn(3.0, 0.5) <= 1.5 && fp_mul_dn(3.0, 0.5) >= fp_next_down(1.5));
    assert_true(fp_mul_dn(-3.0, 0.5) <= -1.5);
    assert_true(fp_mul_up(-3.0, 0.5) >= -1.5);
    /* overflow */
    assert_true(fp_mul_up(DBL_MAX, 2.0) == INFINITY);
    assert_true(fp_mul_dn(DBL_MAX, 2.0) == DBL_MAX);
    assert_true(fp_mul_dn(-DBL_MAX, 2.0) == -INFINITY);
    assert_true(fp_mul_up(-DBL_MAX, 2.0) == -DBL_MAX);
    /* underflow: 2^-600 * 2^-600 is far below the smallest subnormal */
    assert_true(fp_mul_up(0x1p-600, 0x1p-600) == SMALLEST_SUBNORMAL);
    assert_true(fp_mul_dn(0x1p-600, 0x1p-600) <= 0.0);
    assert_true(fp_mul_dn(-0x1p-600, 0x1p-600) == -SMALLEST_SUBNORMAL);
    assert_true(fp_mul_up(-0x1p-600, 0x1p-600) >= -0.0);
    assert_true(fp_mul_up(SMALLEST_SUBNORMAL, 0.75) >= SMALLEST_SUBNORMAL);
    assert_true(fp_mul_dn(SMALLEST_SUBNORMAL, 0.75) <= 0.75 * 0x1p-1074);
    /* infinite operands */
    assert_true(fp_mul_up(INFINITY, 2.0) == INFINITY);
    assert_true(fp_mul_dn(-INFINITY, 2.0) == -INFINITY);
    assert_true(fp_mul_dn(INFINITY, 2.0) <= INFINITY);

    rng_seed(0x5eed0004u);
    long bad = 0;
    for (int i = 0; i < 1000000; i++) {
        double a = random_finite(), b = random_finite();
        int ea, eb;
        frexp(a, &ea);
        frexp(b, &eb);
        if (ea + eb > 1020 || ea + eb < -960)
            continue;
        /* normal results: a*b == p + err exactly (fma) */
        double p = a * b, err = fma(a, b, -p);
        double up = fp_mul_up(a, b), dn = fp_mul_dn(a, b);
        if (!(up - p >= err && dn - p <= err && up <= fp_next_up(p) && dn >= fp_next_down(p))) {
            if (bad < 5)
                printf("mul directed wrong: %a * %a: dn %a up %a\n", a, b, dn, up);
            bad++;
        }
    }
    /* subnormal and overflowing products: exact in long double (26-bit
     * operands) */
    for (int i = 0; i < 300000; i++) {
        double a, b;
        if (i % 2) {
            a = random_short(-560, -500);
            b = random_short(-560, -500);
        } else {
            a = random_short(500, 530);
            b = random_short(490, 530);
        }
        long double exact = (long double)a * b;
        double up = fp_mul_up(a, b), dn = fp_mul_dn(a, b);
        if (!((long double)dn <= exact && exact <= (long double)up)) {
            if (bad < 5)
                printf("mul directed wrong: %a * %a: dn %a up %a\n", a, b, dn, up);
            bad++;
        }
        /* beyond DBL_MAX the inner bound is DBL_MAX itself, not infinity */
        if (exact > (long double)DBL_MAX && dn != DBL_MAX)
            bad++;
        if (exact < -(long double)DBL_MAX && up != -DBL_MAX)
            bad++;
    }
    assert_int_equal(bad, 0);
}

static void test_div_directed(void **state)
{
    (void)state;
    assert_true(fp_div_up(0.0, 3.0) == 0.0);
    assert_true(fp_div_dn(0.0, -3.0) == 0.0);
    assert_true(fp_div_dn(1.0, INFINITY) == 0.0);      /* the limit */
    assert_true(fp_div_up(-1.0, INFINITY) == 0.0);
    assert_true(fp_div_up(1.0, 3.0) > 1.0 / 3.0 - 0x1p-60);
    assert_true(fp_div_dn(1.0, 3.0) < fp_div_up(1.0, 3.0));
    assert_true(fp_div_up(DBL_MAX, 0.5) == INFINITY);
    assert_true(fp_div_dn(DBL_MAX, 0.5) == DBL_MAX);
    assert_true(fp_div_dn(-DBL_MAX, 0.5) == -INFINITY);
    assert_true(fp_div_up(-DBL_MAX, 0.5) == -DBL_MAX);
    assert_true(fp_div_up(SMALLEST_SUBNORMAL, 4.0) >= SMALLEST_SUBNORMAL);
    assert_true(fp_div_dn(SMALLEST_SUBNORMAL, 4.0) <= 0.0 + SMALLEST_SUBNORMAL * 0.25);
    assert_true(fp_div_dn(-SMALLEST_SUBNORMAL, 4.0) == -SMALLEST_SUBNORMAL);

    rng_seed(0x5eed0008u);
    long bad = 0;
    for (int i = 0; i < 1000000; i++) {
        double a = random_finite(), b = random_finite();
        if (b == 0.0)
            continue;
        if (i % 3 == 0)
            a = random_short(-40, 40), b = random_short(-40, 40);
        /* long double a/b errs by 2^-64 relative, far less than the distance
         * from a/b to the neighbours of the RN quotient (>= 2^-55 relative),
         * so comparing against it decides correctly */
        long double q = (long double)a / (long double)b;
        double up = fp_div_up(a, b), dn = fp_div_dn(a, b);
        if (!((long double)dn <= q && q <= (long double)up)) {
            if (bad < 5)
                printf("div directed wrong: %a / %a: dn %a up %a\n", a, b, dn, up);
            bad++;
        }
        /* at most one step beyond the RN quotient */
        double rn = a / b;
        if (isfinite(rn) && rn != 0.0 && !(up <= fp_next_up(rn) && dn >= fp_next_down(rn)))
            bad++;
    }
    assert_int_equal(bad, 0);
}

/* ---- TwoSum ---- */

static void test_two_sum(void **state)
{
    (void)state;
    /* x - x and other exact sums have no error */
    assert_true(fp_two_sum_err(3.25, -3.25, 0.0) == 0.0);
    assert_true(fp_two_sum_err(1.0, 2.0, 3.0) == 0.0);
    assert_true(fp_two_sum_err(0.0, 0.0, 0.0) == 0.0);
    assert_true(fp_two_sum_err(-0.0, 0.0, -0.0 + 0.0) == 0.0);
    /* the small addend is lost entirely: it is the error */
    assert_true(fp_two_sum_err(1.0, 0x1p-60, 1.0 + 0x1p-60) == 0x1p-60);
    assert_true(fp_two_sum_err(0x1p-60, 1.0, 1.0 + 0x1p-60) == 0x1p-60);
    assert_true(fp_two_sum_err(1e300, -1e-300, 1e300 - 1e-300) == -1e-300);
    /* a tie rounded to even: 1 + 2^-53 -> 1, error 2^-53 */
    assert_true(fp_two_sum_err(1.0, 0x1p-53, 1.0 + 0x1p-53) == 0x1p-53);
    /* subnormal sums are always exact */
    assert_true(fp_two_sum_err(SMALLEST_SUBNORMAL, SMALLEST_SUBNORMAL, 0x1p-1073) == 0.0);
    assert_true(fp_two_sum_err(LARGEST_SUBNORMAL, SMALLEST_SUBNORMAL, DBL_MIN) == 0.0);
    /* near DBL_MAX without overflow */
    {
        double a = DBL_MAX, b = -0x1p970, s = a + b;
        assert_true((long double)s + fp_two_sum_err(a, b, s) == (long double)a + b);
    }

    rng_seed(0x5eed0005u);
    long bad = 0;
    for (int i = 0; i < 1000000; i++) {
        /* exponents within 10 of each other: a + b is exact in long double,
         * and so is s + e */
        int e = (int)(rng_next() % 2000) - 1000;
        double a = random_finite(), b;
        a = ldexp(frexp(a, &(int){0}), e);
        b = ldexp(frexp(random_finite(), &(int){0}), e - (int)(rng_next() % 10));
        if (!isfinite(a) || !isfinite(b))
            continue;
        double s = a + b, err = fp_two_sum_err(a, b, s);
        if ((long double)s + (long double)err != (long double)a + (long double)b)
            bad++;
        /* the error is at most half an ulp of s */
        if (s != 0.0 && fabs(err) > 0.5 * (fp_next_up(fabs(s)) - fabs(s)))
            bad++;
    }
    /* widely separated exponents: the whole small operand is the error when
     * it is below half an ulp of the big one */
    for (int i = 0; i < 100000; i++) {
        double a = random_short(0, 50), b = random_short(-200, -60);
        double s = a + b;
        if (s != a || fp_two_sum_err(a, b, s) != b)
            bad++;
    }
    assert_int_equal(bad, 0);
}

/* ---- fp_rounding_bound ---- */

static void test_rounding_bound_formula(void **state)
{
    (void)state;
    /* zero only for nothing to bound (acc == 0, no underflow), positive
     * where a product may have underflowed, monotone in acc and n, and
     * never a subnormal number (rounding.h: those cost microcode assists) */
    assert_true(fp_rounding_bound(0.0, 0) == 0.0);
    assert_true(fp_rounding_bound(0.0, 1) >= 0x1p-1073);
    assert_true(fp_rounding_bound(0.0, 10) >= 10 * 0x1p-1073);
    assert_true(fp_rounding_bound(0x1p-1074, 0) >= 0x1p-1022);
    assert_true(fp_rounding_bound(0x1p-1000, 3) >= 0x1p-1022);
    assert_true(fp_rounding_bound(1e-300, 0) >= 0x1p-1022);
    assert_true(fp_rounding_bound(1.0, 1) >= 0x1p-52);
    assert_true(fp_rounding_bound(1.0, 1) <= 0x1p-52 * (1 + 0x1p-40));
    assert_true(isfinite(fp_rounding_bound(DBL_MAX, 100)));
    assert_true(fp_rounding_bound(DBL_MAX, 100) >= DBL_MAX * 0x1p-52);

    rng_seed(0x5eed0006u);
    long bad = 0;
    for (int i = 0; i < 1000000; i++) {
        double acc = fabs(random_finite());
        int n = (int)(rng_next() % 100000);
        double r = fp_rounding_bound(acc, n);
        /* 2u*acc + 4*n*eta, exactly, in long double */
        long double want = (long double)acc * 0x1p-52L + (long double)n * 4 * 0x1p-1075L;
        if (!((long double)r >= want))
            bad++;
        if (!(fp_rounding_bound(acc, n + 1) >= r))
            bad++;
        if (!(fp_rounding_bound(fp_next_up(acc), n) >= r))
            bad++;
    }
    assert_int_equal(bad, 0);
}

/*
 * The documented use: n RN operations (products and sums) whose results r_k
 * have absolute values summing, in RN, to acc. The sum of the exact rounding
 * errors of the n operations must not exceed fp_rounding_bound(acc, n).
 * Operands have 26-bit significands so that every exact product is exact in
 * long double; sums of two operands of close exponent are exact there too.
 */
static void run_rounding_bound_sequences(int emin, int emax, long *bad, long double *worst)
{
    for (int seq = 0; seq < 20000; seq++) {
        int n = 1 + (int)(rng_next() % 64);
        double acc = 0.0;
        long double total_err = 0.0L;
        for (int k = 0; k < n; k++) {
            int e = emin + (int)(rng_next() % (uint64_t)(emax - emin + 1));
            double a = random_short(e, e + 2), b;
            double r;
            long double exact;
            if (rng_next() & 1) {
                b = random_short(-1, 1);                         /* product */
                r = a * b;
                exact = (long double)a * (long double)b;
            } else {
                b = random_short(e - 5, e + 5);                  /* sum */
                r = a + b;
                exact = (long double)a + (long double)b;
            }
            total_err += fabsl(exact - (long double)r);
            acc += fabs(r);
        }
        double bound = fp_rounding_bound(acc, n);
        if (!(total_err <= (long double)bound))
            (*bad)++;
        if (bound > 0 && total_err / bound > *worst)
            *worst = total_err / bound;
    }
}

static void test_rounding_bound_semantics(void **state)
{
    (void)state;
    long bad = 0;
    long double worst = 0.0L;
    rng_seed(0x5eed0007u);
    run_rounding_bound_sequences(-20, 20, &bad, &worst);          /* normal */
    run_rounding_bound_sequences(-1070, -1020, &bad, &worst);     /* subnormal */
    run_rounding_bound_sequences(900, 1000, &bad, &worst);        /* large */
    printf("fp_rounding_bound: worst actual/bound ratio %.3Lf\n", worst);
    assert_int_equal(bad, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_next_edge_cases),
        cmocka_unit_test(test_next_matches_nextafter),
        cmocka_unit_test(test_up_by_down_by),
        cmocka_unit_test(test_bit_steps_at_edges),
        cmocka_unit_test(test_add_directed),
        cmocka_unit_test(test_mul_directed),
        cmocka_unit_test(test_div_directed),
        cmocka_unit_test(test_two_sum),
        cmocka_unit_test(test_rounding_bound_formula),
        cmocka_unit_test(test_rounding_bound_semantics),
    };
    return cmocka_run_group_tests_name("aa_rounding", tests, NULL, NULL);
}

/*
 * rounding.h: the floating-point facts every bound in common/aa rests on.
 *
 * aa never changes the FPU rounding mode. All arithmetic runs in IEEE 754
 * binary64 round-to-nearest-even (RN), whose error on + - * / sqrt is at most
 * half an ulp of the result (plus half the smallest subnormal on underflow).
 * A bound is made safe by stepping the RN result one representable number
 * outward (fp_next_up / fp_next_down): one full step always covers a half-ulp
 * error, including in the subnormal range. Library functions (sin, exp, ...)
 * are not correctly rounded; their results are widened by AA_LIBM_ULPS steps
 * (see the note on AA_LIBM_ULPS). docs/arithmetic.md gives the whole argument.
 */
#ifndef AA_ROUNDING_H
#define AA_ROUNDING_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/*
 * Widening applied to the results of libm functions that are not correctly
 * rounded (sin cos tan asin acos atan atan2 exp log pow). glibc's manual,
 * "Known Maximum Errors in Math Functions", lists at most 1-2 ulp for these
 * binary64 functions on x86_64 (glibc 2.36, Debian 12), and glibc's own test
 * suite rejects any ulp figure above 9 for any function. We widen by 4: twice
 * the documented bound. tests/aa/test_aa_containment.c checks the widened
 * results against a long double oracle on every run.
 */
#define AA_LIBM_ULPS 4

/* The doubles just below and above pi and pi/2 (M_PI and M_PI_2 are the
 * lower ones): exact real constants are enclosed, never rounded. */
#define AA_PI_LO   0x1.921fb54442d18p+1
#define AA_PI_HI   0x1.921fb54442d19p+1
#define AA_PI_2_LO 0x1.921fb54442d18p+0
#define AA_PI_2_HI 0x1.921fb54442d19p+0

/* The next representable double above x (+inf stays +inf, NaN stays NaN).
 * Doubles of one sign are ordered as their bit patterns, so for finite
 * nonzero x the answer is the bits plus one (x > 0) or minus one (x < 0):
 * one integer test for the usual case instead of three comparisons. */
static inline double fp_next_up(double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    if ((bits & 0x7fffffffffffffffull) - 1u < 0x7fefffffffffffffull) {
        bits += (bits >> 63) ? ~(uint64_t)0 : 1u;
        memcpy(&x, &bits, sizeof bits);
        return x;
    }
    if (x != x || x == INFINITY)
        return x;
    if (x == 0.0)
        return 0x1p-1074;               /* smallest positive subnormal */
    memcpy(&bits, &x, sizeof bits);
    if (x > 0.0)
        bits++;
    else
        bits--;
    memcpy(&x, &bits, sizeof bits);
    return x;
}

/* The next representable double below x (-inf stays -inf, NaN stays NaN). */
static inline double fp_next_down(double x)
{
    return -fp_next_up(-x);
}

/* x stepped k representable numbers up (k >= 0). Binary64 numbers of one
 * sign are ordered as their bit patterns, so for a finite nonzero x whose k
 * steps cross neither 0 nor the largest double the result is k added to
 * (x > 0) or taken from (x < 0) the bits: the same number as k single steps,
 * without the loop (libm results take AA_LIBM_ULPS = 4 steps each way). */
static inline double fp_up_by(double x, int k)
{
    uint64_t bits, mag;
    memcpy(&bits, &x, sizeof bits);
    mag = bits & 0x7fffffffffffffffull;
    if (k > 0 && mag >= (uint64_t)k && mag + (uint64_t)k < 0x7ff0000000000000ull) {
        bits = (bits >> 63) ? bits - (uint64_t)k : bits + (uint64_t)k;
        memcpy(&x, &bits, sizeof bits);
        return x;
    }
    while (k-- > 0)
        x = fp_next_up(x);
    return x;
}

/* x stepped k representable numbers down (k >= 0). */
static inline double fp_down_by(double x, int k)
{
    return -fp_up_by(-x, k);
}

/*
 * Exact rounding error of an addition (Knuth's TwoSum, 6 flops, no branch):
 * s = fl(a + b) and the returned e satisfy s + e == a + b exactly, for all
 * finite a, b without overflow. Used for affine coefficients so that an
 * addition that rounds nothing (x - x) adds nothing to the error term.
 */
static inline double fp_two_sum_err(double a, double b, double s)
{
    double bb = s - a;
    return (a - (s - bb)) + (b - bb);
}

/*
 * Directed rounding of single operations, computed in RN.
 * fp_add_dn/up are exact directed roundings: TwoSum tells whether (and in
 * which direction) the sum was rounded, so an exact sum is not widened.
 * fp_mul_* and fp_div_* step one ulp outward unless trivially exact.
 * Infinite operands stand for unbounded ends of ranges: 0 * inf is 0 and
 * a / inf is 0 (the limit), overflow of finite operands gives DBL_MAX on
 * the inner side and infinity on the outer side.
 */
/* s = RN(a + b), finite, stepped one representable number up (dir = 1)
 * or down (dir = -1) when step is 1: the bits plus or minus one by the
 * sign of s, fp_next_up's fast case (s is not 0 then: a sum that rounds
 * to 0 is exact). No branch: whether a sum was rounded, and which way, is
 * data a branch predictor cannot guess; on operands that vary, the
 * branch's mispredictions cost more than this arithmetic (issue 24). */
static inline double fp_step_sum(double s, int step, int dir)
{
    uint64_t bits;
    memcpy(&bits, &s, sizeof bits);
    int64_t sign = 1 - 2 * (int64_t)(bits >> 63);          /* +1 or -1 */
    bits += (uint64_t)((int64_t)step * sign * dir);
    memcpy(&s, &bits, sizeof bits);
    return s;
}

static inline double fp_add_dn(double a, double b)
{
    double s = a + b;
    if (!isfinite(s))
        return (s == INFINITY && isfinite(a) && isfinite(b)) ? 0x1.fffffffffffffp+1023 : s;
    return fp_step_sum(s, fp_two_sum_err(a, b, s) < 0, -1);
}

static inline double fp_add_up(double a, double b)
{
    double s = a + b;
    if (!isfinite(s))
        return (s == -INFINITY && isfinite(a) && isfinite(b)) ? -0x1.fffffffffffffp+1023 : s;
    return fp_step_sum(s, fp_two_sum_err(a, b, s) > 0, 1);
}

static inline double fp_mul_dn(double a, double b)
{
    double p = a * b;
    uint64_t bits;
    memcpy(&bits, &p, sizeof bits);
    if ((bits & 0x7fffffffffffffffull) - 1u < 0x7fefffffffffffffull) {
        /* finite nonzero: no zero operand, no overflow; one step down */
        bits += (bits >> 63) ? 1u : ~(uint64_t)0;
        memcpy(&p, &bits, sizeof bits);
        return p;
    }
    if (a == 0.0 || b == 0.0)
        return 0.0;
    if (isinf(p) && isfinite(a) && isfinite(b))
        return p > 0 ? 0x1.fffffffffffffp+1023 : -INFINITY;
    return fp_next_down(p);
}

static inline double fp_mul_up(double a, double b)
{
    return -fp_mul_dn(-a, b);
}

static inline double fp_div_dn(double a, double b)
{
    if (a == 0.0)
        return 0.0;
    if (isinf(b))
        return isinf(a) ? -INFINITY : 0.0;
    double q = a / b;
    if (isinf(q) && isfinite(a))
        return q > 0 ? 0x1.fffffffffffffp+1023 : -INFINITY;
    return fp_next_down(q);
}

static inline double fp_div_up(double a, double b)
{
    return -fp_div_dn(-a, b);
}

/*
 * Upper bound on the rounding error of products/sums whose absolute values
 * add up (in RN) to acc, of which n_uflow may have underflowed: each RN
 * operation errs by at most u*|result| (u = 2^-53), and a product whose
 * result is below 2^-1022 by another eta = 2^-1075. We return 2u*acc
 * stepped up (which also covers the RN error of computing acc itself),
 * plus 2^-1022 (>= 4 n eta for n <= 2^49) when n_uflow > 0.
 *
 * Callers count underflow only where it can happen (a product below 2^-1022
 * from nonzero operands), and tiny sums get a constant bound, so that no
 * bound is ever a subnormal number: arithmetic that produces one costs a
 * microcode assist of ~100 cycles on x86, and once a subnormal error term
 * sits in a form every later product with it pays again. A form computed
 * exactly keeps a zero error.
 */
static inline double fp_rounding_bound(double acc, int n_uflow)
{
    if (!(acc >= 0x1p-960)) {      /* tiny, zero or NaN: 2u*acc < 2^-1011 */
        if (acc != acc)
            return acc;
        return acc == 0.0 && n_uflow == 0 ? 0.0 : 0x1p-1010;
    }
    double b = fp_next_up(acc * 0x1p-52);
    return n_uflow > 0 ? fp_next_up(b + 0x1p-1022) : b;
}

/* May the product p = RN(a * b) have underflowed (lost more than u|p|)? */
static inline int fp_uflow(double p, double a, double b)
{
    return fabs(p) < 0x1p-1022 && a != 0.0 && b != 0.0;
}

#endif

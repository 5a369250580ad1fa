/*
 * interval.h: rounding-safe interval arithmetic (IA), the comparison peer of
 * affine arithmetic (Heidrich & Seidel 1998, §7.1: one UFO ray needed 1450
 * boxes with IA against 174 with AA).
 *
 * An ia_interval [lo, hi] encloses a set of reals. Every operation returns an
 * interval that contains the exact real result f(x, y) for every real x and y
 * in the operands (where f is defined), including the rounding of the
 * computation itself and the inexactness of libm (see rounding.h).
 *
 * Flags travel with the value and are OR-ed through every operation:
 *   AA_DISCONTINUOUS  the function jumps inside the operand range (step, floor,
 *                     ceil, round, mod, sign, a pole of tan or of a division
 *                     or reciprocal, a branch cut of atan2) or two branches
 *                     were merged (paper §5); unlike AA_UNBOUNDED it stays
 *                     on a function that bounds the value again (atan, a
 *                     clamp);
 *   AA_UNBOUNDED      the result is (partly) the whole line: division by a
 *                     range containing 0, overflow, a pole;
 *   AA_KINK           the function is continuous but bends sharply inside
 *                     the operand range: abs across 0, a min or max (and so
 *                     a clamp) whose operands' ranges overlap. Nothing in
 *                     the arithmetic reads it; the renderer starts a leaf's
 *                     Newton steps at its cell's centre there (a crease
 *                     fools a start on the cell's plane: intersect.c,
 *                     leaf_start). Like AA_DISCONTINUOUS it stays on.
 *
 * Domain: sqrt, log, pow, asin, acos are evaluated over the part of the
 * operand inside their domain (sqrt of [-1, 4] is [0, 2]); an operand wholly
 * outside the domain gives an empty result (lo > hi, ia_is_empty).
 */
#ifndef AA_INTERVAL_H
#define AA_INTERVAL_H

#include <math.h>
#include <stdbool.h>

#include "aa/rounding.h"

enum {
    AA_DISCONTINUOUS = 1u << 0,
    AA_UNBOUNDED     = 1u << 1,
    AA_KINK          = 1u << 2,
};

typedef struct ia_interval {
    double lo, hi;
    unsigned flags;
} ia_interval;

/* ---- construction and queries ---- */
bool ia_contains(ia_interval x, double v);
double ia_width(ia_interval x);              /* rounded up */
double ia_mid(ia_interval x);
ia_interval ia_merge(ia_interval x, ia_interval y);   /* hull + AA_DISCONTINUOUS */

/* ---- affine operations ---- */

/* ---- non-affine operations ---- */
ia_interval ia_div(ia_interval x, ia_interval y);   /* 0 in y: entire, flagged */
ia_interval ia_recip(ia_interval x);
ia_interval ia_sqr(ia_interval x);
ia_interval ia_sqrt(ia_interval x);
ia_interval ia_invsqrt(ia_interval x);              /* RenderMan inversesqrt */
ia_interval ia_exp(ia_interval x);
ia_interval ia_log(ia_interval x);
ia_interval ia_pow_int(ia_interval x, int n);
ia_interval ia_pow(ia_interval x, ia_interval y);   /* x >= 0 part, x^0 = 1 */
ia_interval ia_sin(ia_interval x);
ia_interval ia_cos(ia_interval x);
ia_interval ia_tan(ia_interval x);
ia_interval ia_asin(ia_interval x);
ia_interval ia_acos(ia_interval x);
ia_interval ia_atan(ia_interval x);
ia_interval ia_atan2(ia_interval y, ia_interval x);
ia_interval ia_abs(ia_interval x);
ia_interval ia_sign(ia_interval x);
ia_interval ia_min(ia_interval x, ia_interval y);
ia_interval ia_max(ia_interval x, ia_interval y);
ia_interval ia_floor(ia_interval x);
ia_interval ia_ceil(ia_interval x);
ia_interval ia_round(ia_interval x);                /* halves away from 0 */
ia_interval ia_mod(ia_interval x, ia_interval y);   /* x - y*floor(x/y) */
ia_interval ia_step(ia_interval edge, ia_interval x);   /* x < edge ? 0 : 1 */
ia_interval ia_smoothstep(ia_interval e0, ia_interval e1, ia_interval x);
ia_interval ia_clamp(ia_interval x, ia_interval lo, ia_interval hi);
ia_interval ia_mix(ia_interval x, ia_interval y, ia_interval a);

/* ---- the hot operations, inline (every affine operation keeps its
 * interval hull with them): construction, hull, + - * by a scalar, * ---- */

static inline double ia_min2_(double a, double b) { return a < b ? a : b; }
static inline double ia_max2_(double a, double b) { return a > b ? a : b; }
static inline double ia_min4_(double a, double b, double c, double d)
{
    return ia_min2_(ia_min2_(a, b), ia_min2_(c, d));
}
static inline double ia_max4_(double a, double b, double c, double d)
{
    return ia_max2_(ia_max2_(a, b), ia_max2_(c, d));
}

/* [lo, hi] with flags; a NaN end makes the whole line; an infinite end
 * flags the result unbounded */
static inline ia_interval ia_mk_(double lo, double hi, unsigned flags)
{
    ia_interval r = { lo, hi, flags };
    if (lo != lo || hi != hi) {
        r.lo = -INFINITY;
        r.hi = INFINITY;
    }
    if (r.lo == -INFINITY || r.hi == INFINITY)
        r.flags |= AA_UNBOUNDED;
    return r;
}

static inline ia_interval ia_make(double lo, double hi) { return ia_mk_(lo, hi, 0); } /* lo <= hi */
static inline ia_interval ia_point(double x) { return ia_mk_(x, x, 0); }
static inline ia_interval ia_entire(void)    /* [-inf, +inf], AA_UNBOUNDED */
{
    return ia_mk_(-INFINITY, INFINITY, AA_UNBOUNDED);
}
static inline ia_interval ia_empty(void)
{
    ia_interval r = { INFINITY, -INFINITY, 0 };
    return r;
}
static inline bool ia_is_empty(ia_interval x) { return !(x.lo <= x.hi); }

/* keeps the flags of both */
static inline ia_interval ia_hull(ia_interval x, ia_interval y)
{
    if (ia_is_empty(x)) { y.flags |= x.flags; return y; }
    if (ia_is_empty(y)) { x.flags |= y.flags; return x; }
    return ia_mk_(ia_min2_(x.lo, y.lo), ia_max2_(x.hi, y.hi), x.flags | y.flags);
}

/* an empty operand gives an empty result with the flags of both */
static inline ia_interval ia_empty_of_(unsigned flags)
{
    ia_interval e = ia_empty();
    e.flags = flags;
    return e;
}

static inline ia_interval ia_add(ia_interval x, ia_interval y)
{
    if (ia_is_empty(x) || ia_is_empty(y))
        return ia_empty_of_(x.flags | y.flags);
    return ia_mk_(fp_add_dn(x.lo, y.lo), fp_add_up(x.hi, y.hi), x.flags | y.flags);
}

static inline ia_interval ia_sub(ia_interval x, ia_interval y)
{
    if (ia_is_empty(x) || ia_is_empty(y))
        return ia_empty_of_(x.flags | y.flags);
    return ia_mk_(fp_add_dn(x.lo, -y.hi), fp_add_up(x.hi, -y.lo), x.flags | y.flags);
}

static inline ia_interval ia_neg(ia_interval x)
{
    if (ia_is_empty(x))
        return x;
    return ia_mk_(-x.hi, -x.lo, x.flags);
}

static inline ia_interval ia_add_s(ia_interval x, double s)
{
    return ia_add(x, ia_point(s));
}

static inline ia_interval ia_mul_s(ia_interval x, double s)
{
    if (ia_is_empty(x))
        return x;
    if (s >= 0)
        return ia_mk_(fp_mul_dn(x.lo, s), fp_mul_up(x.hi, s), x.flags);
    return ia_mk_(fp_mul_dn(x.hi, s), fp_mul_up(x.lo, s), x.flags);
}

/* The directed products are monotone in each factor (fp_mul_dn/up: RN
 * stepped outward, 0 for a zero factor, the overflow conventions), so the
 * signs of the ends tell which corners are extreme, as for exact products
 * (the nine cases of interval multiplication); only two ranges that both
 * straddle 0 need four products. */
static inline ia_interval ia_mul(ia_interval x, ia_interval y)
{
    if (ia_is_empty(x) || ia_is_empty(y))
        return ia_empty_of_(x.flags | y.flags);
    double lo, hi;
    if (x.lo >= 0.0) {
        if (y.lo >= 0.0)      { lo = fp_mul_dn(x.lo, y.lo); hi = fp_mul_up(x.hi, y.hi); }
        else if (y.hi <= 0.0) { lo = fp_mul_dn(x.hi, y.lo); hi = fp_mul_up(x.lo, y.hi); }
        else                  { lo = fp_mul_dn(x.hi, y.lo); hi = fp_mul_up(x.hi, y.hi); }
    } else if (x.hi <= 0.0) {
        if (y.lo >= 0.0)      { lo = fp_mul_dn(x.lo, y.hi); hi = fp_mul_up(x.hi, y.lo); }
        else if (y.hi <= 0.0) { lo = fp_mul_dn(x.hi, y.hi); hi = fp_mul_up(x.lo, y.lo); }
        else                  { lo = fp_mul_dn(x.lo, y.hi); hi = fp_mul_up(x.lo, y.lo); }
    } else if (y.lo >= 0.0) {
        lo = fp_mul_dn(x.lo, y.hi);
        hi = fp_mul_up(x.hi, y.hi);
    } else if (y.hi <= 0.0) {
        lo = fp_mul_dn(x.hi, y.lo);
        hi = fp_mul_up(x.lo, y.lo);
    } else {
        lo = ia_min2_(fp_mul_dn(x.lo, y.hi), fp_mul_dn(x.hi, y.lo));
        hi = ia_max2_(fp_mul_up(x.lo, y.lo), fp_mul_up(x.hi, y.hi));
    }
    return ia_mk_(lo, hi, x.flags | y.flags);
}

#endif

/*
 * affine.h: rounding-safe affine arithmetic (AA), the range analysis of
 * Heidrich & Seidel 1998 §4 (after Comba & Stolfi 1993).
 *
 * An affine form is
 *
 *     x^ = x0 + x1*e1 + ... + xn*en + err*e_err,     every e in [-1, 1],
 *
 * where the e_i are noise symbols shared between all forms of one query and
 * e_err is private to the form. A query (one (u,v) range of one surface, say)
 * owns an aa_context that hands out noise symbols: first the inputs (u and v
 * of the surface, and more where needed) via aa_input, then one fresh symbol
 * per non-affine operation for its approximation error.
 *
 * Representation: dense and fixed-capacity, AA_MAX_SYMBOLS coefficients in
 * the form itself, so no operation ever allocates. n is one past the highest
 * symbol the form uses; operations loop to n only.
 *
 * Condensation policy: the context's capacity (<= AA_MAX_SYMBOLS) caps the
 * number of symbols a query may create. While capacity lasts, each non-affine
 * operation puts its new error on a fresh shared symbol, which keeps its
 * correlation with later uses of the result. Once capacity is spent, new
 * errors are folded into the private term err (the reduced form of Messine's
 * AF1); this is always sound, it only forgets correlation. A capacity equal
 * to the number of inputs gives the fully reduced "one error term" mode.
 * AA_DEFAULT_CAPACITY was chosen from bench/aa_bench (docs/arithmetic.md).
 *
 * Soundness, including rounding: for every assignment of the input symbols,
 * the exact real result of the operation applied to the exact real operand
 * values lies within z0 + sum zi*ei +- (|new symbol coefficients| + err).
 * Every coefficient is computed in round-to-nearest and its rounding error
 * is bounded and added to err (exactly, via TwoSum, for sums and
 * differences, so that x - x is exactly 0).
 *
 * Interval hull: each form also carries [lo, hi], the interval-arithmetic
 * enclosure of the same quantity, computed alongside from the operands'
 * ranges. aa_range returns the intersection of the affine range and the
 * hull, and every non-affine operation approximates its function over that
 * intersection. Both are enclosures of the same exact values, so the
 * intersection is one too; a result is thus never wider than interval
 * arithmetic gives, and the affine part keeps the correlations.
 *
 * Flags (AA_DISCONTINUOUS, AA_UNBOUNDED) as in interval.h. An unbounded form
 * has x0 = 0, no coefficients and err = +inf.
 *
 * All operations take the context first and write the result to z, which may
 * alias any operand.
 */
#ifndef AA_AFFINE_H
#define AA_AFFINE_H

#include "aa/interval.h"

#define AA_MAX_SYMBOLS 16
#define AA_DEFAULT_CAPACITY 8

typedef struct aa_form {
    double x0;                    /* central value */
    double err;                   /* private error term, >= 0 */
    double lo, hi;                /* interval hull, see below */
    unsigned short n;             /* symbols 0..n-1 may be non-zero */
    unsigned short flags;         /* AA_DISCONTINUOUS | AA_UNBOUNDED */
    double c[AA_MAX_SYMBOLS];     /* coefficient of noise symbol i */
} aa_form;

typedef struct aa_context {
    int used;                     /* noise symbols handed out so far */
    int capacity;                 /* at most AA_MAX_SYMBOLS */
    long folded;                  /* errors folded into err for lack of symbols */
} aa_context;

/* ---- context: one per query ---- */
void aa_context_init(aa_context *ctx, int capacity);  /* clamps to [0, MAX] */
void aa_context_reset(aa_context *ctx);               /* next query: no symbols */

/* ---- construction and queries ---- */
/* (the small ones are inline: the shading VM makes a constant or asks
 * whether an operand is one for most instructions, issue 24) */
void aa_input(aa_context *ctx, aa_form *z, double lo, double hi); /* new symbol */
/* The centre aa_input gives [lo, hi] (finite, lo <= hi): its symbol e is
 * (x - mid) / radius, so x <= mid means e <= 0 and x >= mid e >= 0 (the
 * renderer's linear bounds restrict e to a child cell that way) */
static inline double aa_input_mid(double lo, double hi)
{
    double mid = 0.5 * lo + 0.5 * hi;
    if (mid < lo) mid = lo;      /* halving subnormals may round */
    if (mid > hi) mid = hi;
    return mid;
}
static inline void aa_unbounded(aa_form *z, unsigned flags)
{
    z->x0 = 0.0;
    z->err = INFINITY;
    z->lo = -INFINITY;
    z->hi = INFINITY;
    z->n = 0;
    z->flags = (unsigned short)(flags | AA_UNBOUNDED);
}
static inline void aa_const(aa_form *z, double value)   /* unbounded if not finite */
{
    if (!isfinite(value)) {
        aa_unbounded(z, 0);
        return;
    }
    z->x0 = value;
    z->err = 0.0;
    z->lo = value;
    z->hi = value;
    z->n = 0;
    z->flags = 0;
}
void aa_from_interval(aa_context *ctx, aa_form *z, ia_interval x);
ia_interval aa_range(const aa_form *x);   /* affine range (rounded outward) meet hull */
double aa_radius(const aa_form *x);                   /* sum |xi| + err, up */
/* aa_range(x), and aa_radius(x) in *radius, the sum taken once */
ia_interval aa_range_radius(const aa_form *x, double *radius);
static inline bool aa_is_point(const aa_form *x)      /* no noise at all */
{
    if ((x->flags & AA_UNBOUNDED) || x->err != 0.0)
        return false;
    for (int i = 0; i < x->n; i++)
        if (x->c[i] != 0.0)
            return false;
    return true;
}

/* An exact constant: what aa_const makes of a finite value (no symbols, no
 * error, the hull the point itself). aa_range(x) is [x->x0, x->x0]. */
static inline bool aa_is_exact_const(const aa_form *x)
{
    return x->n == 0 && x->err == 0.0 && !(x->flags & AA_UNBOUNDED) && x->lo == x->x0 &&
           x->hi == x->x0 && x->x0 - x->x0 == 0.0;          /* finite */
}

/* x - y of two exact constants, when the double difference is exact:
 * true with *d the difference, and then aa_range of aa_sub(x, y) is
 * [*d, *d] (up to the sign of a zero), so a comparison of x and y is
 * decided by *d alone: the shading VM's loop tests on counters, without
 * building the form of the difference (issue 24). False otherwise. */
static inline bool aa_exact_difference(const aa_form *x, const aa_form *y, double *d)
{
    if (!aa_is_exact_const(x) || !aa_is_exact_const(y))
        return false;
    double a = x->x0, b = -y->x0, s = a + b, bb = s - a;
    if (s - s != 0.0 || (a - (s - bb)) + (b - bb) != 0.0)     /* overflow, or rounded */
        return false;
    *d = s;
    return true;
}

/* ---- affine operations: exact up to rounding, no new symbol ---- */
void aa_add(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_sub(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_neg(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_add_s(aa_context *ctx, aa_form *z, const aa_form *x, double s);
void aa_mul_s(aa_context *ctx, aa_form *z, const aa_form *x, double s);
/* z = a*x + b*y + c, the building block of the above and of mix() */
void aa_lincomb(aa_context *ctx, aa_form *z, double a, const aa_form *x,
                double b, const aa_form *y, double c);

/* z = m[0]*x[0] + m[1]*x[1] + m[2]*x[2] + c in one pass (a row of a 3x4
 * transformation applied to a triple); z must not be one of x[0..2] */
void aa_lincomb3(aa_context *ctx, aa_form *z, const double m[3], const aa_form x[3],
                 double c);
/* z = m[0]*(x[0] - x[0].x0) + m[1]*(x[1] - x[1].x0) + m[2]*(x[2] - x[2].x0) + c:
 * bit for bit aa_lincomb3 of the three aa_add_s(x[k], -x[k].x0), without
 * them (a linearisation about the inputs' centres: noise) */
void aa_lincomb3_centred(aa_context *ctx, aa_form *z, const double m[3],
                         const aa_form x[3], double c);

/* Adds delta >= 0 (an upper bound, already rounded up) as a new error of z:
 * on a fresh noise symbol while the context has one, else on z->err. The
 * hull is left alone: the caller widens or replaces it (an enclosure of
 * the same values). */
void aa_add_new_error(aa_context *ctx, aa_form *z, double delta);

/* ---- non-affine operations: one new noise symbol each ---- */
void aa_mul(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_div(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_recip(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_sqr(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_sqrt(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_invsqrt(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_exp(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_log(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_pow_int(aa_context *ctx, aa_form *z, const aa_form *x, int n);
void aa_pow(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_sin(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_cos(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_tan(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_asin(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_acos(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_atan(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_atan2(aa_context *ctx, aa_form *z, const aa_form *y, const aa_form *x);
void aa_abs(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_sign(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_min(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_max(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_floor(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_ceil(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_round(aa_context *ctx, aa_form *z, const aa_form *x);
void aa_mod(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);
void aa_step(aa_context *ctx, aa_form *z, const aa_form *edge, const aa_form *x);
void aa_smoothstep(aa_context *ctx, aa_form *z, const aa_form *e0,
                   const aa_form *e1, const aa_form *x);
void aa_clamp(aa_context *ctx, aa_form *z, const aa_form *x,
              const aa_form *lo, const aa_form *hi);
void aa_mix(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y,
            const aa_form *a);
/* Two branches of a conditional whose test was undecided (paper §4.1):
 * one form enclosing both, flagged AA_DISCONTINUOUS (§5). */
void aa_merge(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y);

#endif

/*
 * dense.h: dense fixed-width affine forms (issue 24, DESIGN.md section 8),
 * the cheap core a batched VM arithmetic would run on: a centre,
 * AA_DENSE_W coefficients (the inputs u, v and spare symbols of the same
 * aa_context as aa_form's) and ONE private error term, no interval hull,
 * no flags, no per-coefficient error-free transform and no branch on the
 * operands' values: every loop has the fixed trip count AA_DENSE_W (which
 * the compiler unrolls and vectorises), and the rounding of an operation
 * is bounded a priori, in round-to-nearest, from the sums of the
 * magnitudes the loop computes anyway (docs/arithmetic.md, "Dense forms"):
 *
 *   a sum s = RN(p + q) errs by at most u |s| (u = 2^-53; exactly where s
 *   is subnormal); a product p = RN(a b) by at most u |p|, plus 2^-1075
 *   when it underflows; a sum of k nonnegative terms in RN is at most
 *   (1 + u)^(k-1) times too small. Each operation adds 2u (not u) times
 *   the magnitudes, which also covers a bound that underflows, a constant
 *   2^-1018 for all its products' underflow (lincomb and mul: no test per
 *   product), and raises the
 *   total by 2^-46 of itself (more than the RN error of the few sums that
 *   make it).
 *
 * Soundness: for every assignment of the symbols in [-1, 1], the exact
 * real result of the operation applied to the operands' exact values lies
 * within z0 + sum zi ei +- err (tests/aa/test_aa_dense.c checks it against
 * a long double oracle). An unbounded form has err = +inf (or NaN, from
 * 0 * inf): aa_dense_range gives the whole line.
 *
 * Not yet used by the VM: aa_bench times it against aa_form (the cost a
 * dense VM arithmetic could reach per operation).
 */
#ifndef AA_DENSE_H
#define AA_DENSE_H

#include "aa/affine.h"

#define AA_DENSE_W 4

typedef struct aa_dense {
    double x0;                  /* centre */
    double c[AA_DENSE_W];       /* coefficient of noise symbol i */
    double err;                 /* private error, >= 0; +inf: unbounded */
} aa_dense;

static inline void aa_dense_const(aa_dense *z, double v)
{
    z->x0 = v;
    for (int i = 0; i < AA_DENSE_W; i++)
        z->c[i] = 0.0;
    z->err = v - v == 0.0 ? 0.0 : INFINITY;     /* not finite: unbounded */
    if (z->err != 0.0)
        z->x0 = 0.0;
}

/* x as a dense form: coefficients of symbols >= AA_DENSE_W (and the
 * hull's narrowing) are folded into err, rounded up */
void aa_dense_from_form(aa_dense *z, const aa_form *x);
/* z as an aa_form: symbols 0..AA_DENSE_W-1, the hull its range */
void aa_dense_to_form(aa_form *z, const aa_dense *x);

/* sum |xi| + err, rounded up (+inf when unbounded) */
double aa_dense_radius(const aa_dense *x);
/* the range, rounded outward; the whole line (AA_UNBOUNDED) when unbounded */
ia_interval aa_dense_range(const aa_dense *x);

/* ---- the operations: z may alias any operand ---- */
void aa_dense_add(aa_dense *z, const aa_dense *x, const aa_dense *y);
void aa_dense_sub(aa_dense *z, const aa_dense *x, const aa_dense *y);
/* z = a x + b y + c (finite a, b, c) */
void aa_dense_lincomb(aa_dense *z, double a, const aa_dense *x, double b,
                      const aa_dense *y, double c);
/* z = x y: the quadratic part's bound on a fresh symbol of ctx while one
 * below AA_DENSE_W is left, else on err */
void aa_dense_mul(aa_context *ctx, aa_dense *z, const aa_dense *x, const aa_dense *y);

#endif

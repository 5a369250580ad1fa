/*
 * dense.c: the operations of the dense fixed-width affine forms (dense.h):
 * fixed trip counts, a priori rounding bounds in round-to-nearest, no
 * branch on the operands' values inside the loops.
 */
#include "aa/dense.h"
#include "aa/rounding.h"

#include <math.h>

#define W AA_DENSE_W
#define ETA_ALL 0x1p-1018       /* >= every 2^-1075 of one operation's products */

/* An upper bound of a sum t of at most 60 nonnegative terms, each itself
 * an upper bound, added in RN: (1 + u)^59 < 1 + 2^-46 - u. t = 0 stays 0. */
static inline double up(double t)
{
    return t * (1.0 + 0x1p-46);
}

void aa_dense_from_form(aa_dense *z, const aa_form *x)
{
    if (x->flags & AA_UNBOUNDED) {
        aa_dense_const(z, INFINITY);
        return;
    }
    double rest = 0.0;
    for (int i = W; i < x->n; i++)
        rest += fabs(x->c[i]);
    for (int i = 0; i < W; i++)
        z->c[i] = i < x->n ? x->c[i] : 0.0;
    z->x0 = x->x0;
    z->err = rest == 0.0 ? x->err : up(x->err + rest);
}

void aa_dense_to_form(aa_form *z, const aa_dense *x)
{
    ia_interval r = aa_dense_range(x);
    if (r.flags & AA_UNBOUNDED) {
        aa_unbounded(z, 0);
        return;
    }
    z->x0 = x->x0;
    z->err = x->err;
    for (int i = 0; i < W; i++)
        z->c[i] = x->c[i];
    z->n = W;
    while (z->n > 0 && z->c[z->n - 1] == 0.0)
        z->n--;
    z->flags = 0;
    z->lo = r.lo;
    z->hi = r.hi;
}

double aa_dense_radius(const aa_dense *x)
{
    double s = 0.0;
    for (int i = 0; i < W; i++)
        s += fabs(x->c[i]);
    double r = up(s + x->err);
    return r == r ? r : INFINITY;
}

/*
 * x0 -+ r in RN, moved out by w: x0 - r errs by at most u (|x0| + r)
 * (1 + u), the step by u |result| again, so w = 2^-51 (|x0| + r) (four
 * times u, itself in RN) and 2^-1022 for an underflow of w cover both; a
 * point (r = 0, its centre exact) takes no step.
 */
ia_interval aa_dense_range(const aa_dense *x)
{
    double r = aa_dense_radius(x), x0 = x->x0;
    if (!(r < INFINITY))
        return ia_entire();
    double w = ((fabs(x0) + r) * 0x1p-51 + 0x1p-1022) * (double)(r != 0.0);
    return ia_make((x0 - r) - w, (x0 + r) + w);
}

/* z = x +- y: sums only; the coefficients' rounding is 2u times the sum
 * of their magnitudes (x - x: all 0, no error but the operands' own), the
 * centre's its exact TwoSum error (a sum of constants that rounds nothing
 * stays exact) */
static inline __attribute__((always_inline)) void
add_sign(aa_dense *z, const aa_dense *x, const aa_dense *y, double sgn)
{
    double s = 0.0;
    for (int i = 0; i < W; i++) {
        double v = x->c[i] + sgn * y->c[i];
        s += fabs(v);
        z->c[i] = v;
    }
    double b = sgn * y->x0, x0 = x->x0 + b;
    double e0 = fabs(fp_two_sum_err(x->x0, b, x0));
    z->err = up(x->err + y->err + s * 0x1p-52 + e0);
    z->x0 = x0;
}

void aa_dense_add(aa_dense *z, const aa_dense *x, const aa_dense *y)
{
    add_sign(z, x, y, 1.0);
}

void aa_dense_sub(aa_dense *z, const aa_dense *x, const aa_dense *y)
{
    add_sign(z, x, y, -1.0);
}

/*
 * z = a x + b y + c: every product errs by u of its magnitude (plus 2^-1075
 * when it underflows), every sum by u of its result; all of it 2u times
 * the magnitudes (m), plus the operands' errors times |a|, |b|.
 */
void aa_dense_lincomb(aa_dense *z, double a, const aa_dense *x, double b,
                      const aa_dense *y, double c)
{
    double m = 0.0;
    for (int i = 0; i < W; i++) {
        double p = a * x->c[i], q = b * y->c[i], v = p + q;
        m += fabs(p) + fabs(q) + fabs(v);
        z->c[i] = v;
    }
    double p = a * x->x0, q = b * y->x0, s1 = p + q, x0 = s1 + c;
    m += fabs(p) + fabs(q) + fabs(s1) + fabs(x0);
    double e = fabs(a) * x->err + fabs(b) * y->err;     /* 2 products, 1 sum */
    /* any product may have underflowed, even to 0 (|a| xe, |b| ye
     * included): one eta for all of them (no test per product) */
    z->err = up(e + m * 0x1p-52 + ETA_ALL);
    z->x0 = x0;
}

/*
 * z = x y = x0 y0 + sum (x0 yi + y0 xi) ei + Q (aa_mul's argument): the
 * diagonal of Q, sum xi yi ei^2, has its midpoint sum(xi yi)/2 in the
 * centre and half its width as error; the rest of Q is at most
 * rx ry - sum |xi yi| (rx, ry: the radii, private errors included). The
 * private errors' linear terms, |x0| ye + |y0| xe, go to err with the
 * roundings; the quadratic bound rx ry - sum|xi yi|/2 on a fresh symbol.
 */
void aa_dense_mul(aa_context *ctx, aa_dense *z, const aa_dense *x, const aa_dense *y)
{
    double x0 = x->x0, y0 = y->x0, xe = x->err, ye = y->err;
    double m = 0.0, dsum = 0.0, dabs = 0.0, sx = 0.0, sy = 0.0;
    double zc[W];
    for (int i = 0; i < W; i++) {
        double xi = x->c[i], yi = y->c[i];
        double p = x0 * yi, q = y0 * xi, v = p + q, d = xi * yi;
        m += fabs(p) + fabs(q) + fabs(v);
        dsum += d;
        dabs += fabs(d);
        sx += fabs(xi);
        sy += fabs(yi);
        zc[i] = v;
    }
    double p0 = x0 * y0, mid = 0.5 * dsum, c0 = p0 + mid;
    /* roundings: the 3W products and sums above, p0, mid's W products,
     * W - 1 sums and halving, c0 (W + 2 covers the d's share) */
    m += fabs(p0) + fabs(c0) + (double)(W + 2) * dabs;
    /* rx ry from above, sum |xi yi| / 2 from below */
    double rx = up(sx + xe), ry = up(sy + ye);
    double q = up(rx * ry) - 0.5 * dabs * (1.0 - 0x1p-46);
    q = q > 0.0 ? q : 0.0;
    double lin = fabs(x0) * ye + fabs(y0) * xe;
    /* any product may have underflowed, even to 0 (the private errors'
     * and rx ry too): one eta for all of them */
    double e = up(lin + m * 0x1p-52 + ETA_ALL);
    double delta = up(q + q * 0x1p-51);          /* q's own rounding */
    int k = (ctx->used < ctx->capacity && ctx->used < W) ? ctx->used : -1;
    if (k >= 0 && zc[k] == 0.0)       /* fresh: no operand has it */
        ctx->used++;
    else
        k = -1;
    if (k < 0) {
        e = up(e + delta);
        ctx->folded++;
    }
    for (int i = 0; i < W; i++)
        z->c[i] = i == k ? delta : zc[i];
    z->x0 = c0;
    z->err = e;
}

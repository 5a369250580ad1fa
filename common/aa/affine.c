/*
 * affine.c: affine forms, the noise symbol context, and the operations that
 * are affine or nearly so: linear combinations, products, branch merges.
 * The approximations of non-affine library functions live in affine_funcs.c.
 *
 * Rounding (docs/arithmetic.md): coefficients are computed in round-to-
 * nearest. The exact error of every sum is known from TwoSum; the error of
 * a product is at most 2^-53 of its magnitude (plus an underflow term).
 * These errors are summed, bounded from above, and added to the form's
 * private error term err, so the form stays a guaranteed enclosure.
 */
#include "aa/affine_internal.h"
#include "aa/rounding.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

/* ---------------------------------------------------------------------- */
/* context                                                                 */
/* ---------------------------------------------------------------------- */

/* The context's invariant: the symbols handed out fit its capacity, which
 * fits a form (every form's n <= AA_MAX_SYMBOLS follows from it). */
static inline void check_context(const aa_context *ctx)
{
    (void)ctx;   /* without asserts */
    assert(ctx->used >= 0 && ctx->used <= ctx->capacity);
    assert(ctx->capacity <= AA_MAX_SYMBOLS);
}

void aa_context_init(aa_context *ctx, int capacity)
{
    if (capacity < 0)
        capacity = 0;
    if (capacity > AA_MAX_SYMBOLS)
        capacity = AA_MAX_SYMBOLS;
    ctx->used = 0;
    ctx->capacity = capacity;
    ctx->folded = 0;
    check_context(ctx);
}

void aa_context_reset(aa_context *ctx)
{
    ctx->used = 0;
}

/* A fresh noise symbol, or -1 when the context's capacity is spent. */
static inline int fresh_symbol(aa_context *ctx)
{
    check_context(ctx);
    if (ctx->used >= ctx->capacity)
        return -1;
    return ctx->used++;
}

/* ---------------------------------------------------------------------- */
/* construction and queries                                                */
/* ---------------------------------------------------------------------- */

/* aa_unbounded, aa_const and aa_is_point are inline in affine.h */

/* c[i] = 0 for n <= i < k (and past k: stale anyway), c[0..n) kept:
 * before a new symbol k is written. Usually k == n (the form uses the
 * last symbol) and nothing is done; else a fixed trip count compiles to a
 * few vector blends, where a loop from n to k compiled to a call of
 * memset (issue 24). */
static inline void zero_from(double *c, int n, int k)
{
    if (n >= k)
        return;
    for (int i = 0; i < AA_MAX_SYMBOLS; i++)
        c[i] = i < n ? c[i] : 0.0;
}

/* aa_add_new_error, inlined where the operations of this file end with it */
static inline __attribute__((always_inline)) void
new_error(aa_context *ctx, aa_form *z, double delta)
{
    assert(!(delta < 0.0));                 /* an upper bound of an error */
    assert(z->n <= AA_MAX_SYMBOLS);
    if (delta == 0.0 || (z->flags & AA_UNBOUNDED))
        return;
    if (!(delta < INFINITY)) {
        aa_unbounded(z, z->flags);
        return;
    }
    int k = fresh_symbol(ctx);
    if (k < 0) {
        z->err = fp_add_up(z->err, delta);
        ctx->folded++;
        return;
    }
    assert(k < AA_MAX_SYMBOLS);
    zero_from(z->c, z->n, k);
    z->c[k] = delta;
    if (k + 1 > z->n)
        z->n = (unsigned short)(k + 1);
}

void aa_add_new_error(aa_context *ctx, aa_form *z, double delta)
{
    new_error(ctx, z, delta);
}

void aa_input(aa_context *ctx, aa_form *z, double lo, double hi)
{
    if (!(lo <= hi) || !isfinite(lo) || !isfinite(hi)) {
        aa_unbounded(z, 0);
        return;
    }
    double mid = aa_input_mid(lo, hi);
    double rad = fmax(fp_add_up(hi, -mid), fp_add_up(mid, -lo));
    aa_const(z, mid);
    z->lo = lo;
    z->hi = hi;
    int k = fresh_symbol(ctx);
    if (k < 0) {
        z->err = rad;
        ctx->folded++;
        return;
    }
    zero_from(z->c, 0, k);
    z->c[k] = rad;
    z->n = (unsigned short)(k + 1);
}

void aa_set_interval(aa_context *ctx, aa_form *z, ia_interval r, unsigned flags)
{
    if (ia_is_empty(r) || !isfinite(r.lo) || !isfinite(r.hi)) {
        aa_unbounded(z, flags);
        return;
    }
    double mid = 0.5 * r.lo + 0.5 * r.hi;     /* ia_mid of finite ends */
    double rad = fmax(fp_add_up(r.hi, -mid), fp_add_up(mid, -r.lo));
    aa_const(z, mid);
    z->lo = r.lo;
    z->hi = r.hi;
    z->flags = (unsigned short)(flags & ~AA_UNBOUNDED);
    new_error(ctx, z, rad);
}

void aa_from_interval(aa_context *ctx, aa_form *z, ia_interval x)
{
    aa_set_interval(ctx, z, x, x.flags);
}

/* The end of aa_radius, from the RN sum r of the |xi| (in symbol order)
 * and the count of nonzero ones; shared with aa_mul, which sums them in
 * its own loop. */
static double radius_from_sum(const aa_form *x, double r, int terms)
{
    if (x->err != 0.0) {
        r += x->err;
        terms++;
    }
    if (terms <= 1)
        return r;
    if (!(r >= 0x1p-960))              /* no subnormal products (rounding.h) */
        return r != r ? r : 0x1p-958;
    return fp_next_up(r + r * ((double)(terms + 1) * 0x1p-53));
}

/* Sum of |xi| + err, rounded up. The n terms are added in round-to-
 * nearest; each addition errs by at most 2^-53 of its (nonnegative)
 * result, so the exact sum is at most the computed one times (1 + 2^-53)^n,
 * which (n + 1) * 2^-53 relative, stepped up, covers. A form with one term
 * (an input, a fresh min-range result) comes back exactly. */
static inline __attribute__((always_inline)) double radius(const aa_form *x)
{
    if (x->flags & AA_UNBOUNDED)
        return INFINITY;
    int n = x->n;
    double r = 0.0;
    int terms = 0;
    for (int i = 0; i < n; i++) {
        double a = fabs(x->c[i]);
        r += a;
        terms += a != 0.0;
    }
    return radius_from_sum(x, r, terms);
}

double aa_radius(const aa_form *x)
{
    return radius(x);
}

static inline __attribute__((always_inline)) ia_interval range_r(const aa_form *x, double r)
{
    if (x->flags & AA_UNBOUNDED) {
        ia_interval e = ia_entire();
        e.flags |= x->flags;
        return e;
    }
    double lo = fp_add_dn(x->x0, -r), hi = fp_add_up(x->x0, r);
    if (x->lo > lo)
        lo = x->lo;
    if (x->hi < hi)
        hi = x->hi;
    if (!(lo <= hi)) {        /* disjoint: possible only outside a domain */
        lo = x->lo;
        hi = x->hi;
    }
    ia_interval out = { lo, hi, x->flags };
    if (!(lo > -INFINITY && hi < INFINITY)) {     /* infinite or NaN ends */
        out = ia_make(lo, hi);
        out.flags |= x->flags;
    }
    return out;
}

ia_interval aa_range_r(const aa_form *x, double r)
{
    return range_r(x, r);
}

ia_interval aa_range(const aa_form *x)
{
    return range_r(x, radius(x));
}

ia_interval aa_range_radius(const aa_form *x, double *r)
{
    *r = radius(x);
    return range_r(x, *r);
}

/* ---------------------------------------------------------------------- */
/* linear combinations                                                     */
/* ---------------------------------------------------------------------- */

/* How a product by the factor a rounds (every case sound for any operand):
 * FACTOR_EXACT: 0, +-1 and powers of two of magnitude >= 1 change at most
 * the sign and exponent, so the product is exact (overflow aside, which
 * gives infinity and an unbounded result); FACTOR_POW2: powers of two below
 * 1 are exact unless the product underflows; FACTOR_INEXACT: any other
 * factor errs by at most 2^-53 of the product's magnitude, plus 2^-1075 when
 * it underflows (rounding.h). Classifying the factor once per operation
 * takes the per-coefficient bookkeeping out of add, sub, neg and x*2. */
enum { FACTOR_EXACT, FACTOR_POW2, FACTOR_INEXACT };

static inline int factor_kind(double a)
{
    uint64_t bits;
    memcpy(&bits, &a, sizeof bits);
    unsigned e = (unsigned)(bits >> 52) & 0x7ffu;
    if (a == 0.0)
        return FACTOR_EXACT;
    if ((bits & 0xfffffffffffffull) != 0 || e == 0 || e == 0x7ffu)
        return FACTOR_INEXACT;
    return e >= 0x3ffu ? FACTOR_EXACT : FACTOR_POW2;
}

/* Upper bound on a sum of |TwoSum errors| accumulated in RN. */
static double sum_err_bound(double es)
{
    return es == 0.0 ? 0.0 : fp_next_up(es * (1.0 + 0x1p-45));
}

/* a + b for a, b >= 0, rounded up; exact when either is 0 */
static inline double add_up_nn(double a, double b)
{
    return a == 0.0 ? b : b == 0.0 ? a : fp_add_up(a, b);
}

/* a*[lo, hi] (a finite, a != 0) before rounding: the ends of a hull */
static inline void scale_ends(double a, double lo, double hi, double *l, double *h)
{
    if (a > 0.0) { *l = a * lo; *h = a * hi; }
    else { *l = a * hi; *h = a * lo; }
}

/* 1 when the product p = RN(a*v) of a factor of kind k may have underflowed
 * (branch-free, for the loops below) */
static inline int uflow_k(int k, double p, double v)
{
    return (k != FACTOR_EXACT) & (fabs(p) < 0x1p-1022) & (v != 0.0);
}

/* The coefficient loops of aa_lincomb: the symbols both operands use, then
 * the rest of the longer one (no per-coefficient selects). track (a
 * constant at each call) says whether any factor needs the products'
 * rounding bookkeeping; add, sub and neg do without it. */
/* z[i] = a x[i] for the i in [from, to) that only one operand has */
static inline __attribute__((always_inline)) void
lincomb_tail(int track, double a, const double *xc, int from, int to, double *zc, int ka,
             double wa, double *ap, int *uf)
{
    for (int i = from; i < to; i++) {
        double xi = xc[i], p = a * xi;
        if (track) {
            *ap += wa * fabs(p);
            *uf |= uflow_k(ka, p, xi);
        }
        zc[i] = p;
    }
}

static inline __attribute__((always_inline)) void
lincomb_loops(int track, double a, const double *xc, int xn, double b,
              const double *yc, int yn, double *zc, int ka, int kb,
              double wa, double wb, double *es_out, double *ap_out, int *uf_out)
{
    int m = xn < yn ? xn : yn;
    double es = 0.0, ap = 0.0;
    int uf = 0;
    for (int i = 0; i < m; i++) {
        double xi = xc[i], yi = yc[i];
        double p = a * xi, q = b * yi, s = p + q;
        es += fabs(fp_two_sum_err(p, q, s));
        if (track) {
            ap += wa * fabs(p) + wb * fabs(q);
            uf |= uflow_k(ka, p, xi) | uflow_k(kb, q, yi);
        }
        zc[i] = s;
    }
    lincomb_tail(track, a, xc, m, xn, zc, ka, wa, &ap, &uf);
    lincomb_tail(track, b, yc, m, yn, zc, kb, wb, &ap, &uf);
    *es_out = es;
    *ap_out = ap;
    *uf_out = uf;
}

/* The end of every linear combination: z's fields, the hull's NaN ends
 * (inf - inf) as the whole line, unbounded when the centre or the error
 * overflowed. */
static inline __attribute__((always_inline)) void
finish_form(aa_form *z, double x0, double err, double lo, double hi, int n, unsigned flags)
{
    z->x0 = x0;
    z->err = err;
    z->lo = lo == lo ? lo : -INFINITY;
    z->hi = hi == hi ? hi : INFINITY;
    z->n = (unsigned short)n;
    z->flags = (unsigned short)flags;
    if (!isfinite(x0) || !isfinite(err))
        aa_unbounded(z, flags);
}

/*
 * z = a*x for a power of two a (FACTOR_EXACT or FACTOR_POW2, a != 0) and
 * a bounded x: every product is exact unless it is subnormal (an exact
 * factor's never is), so z is exactly a times x, its private error and
 * its hull included, with no rounding bookkeeping (issue 24: on dented
 * 20 of the 27 multiplications a box are by 2, 1/2 or a power of two
 * weight, and the general path's hull bound, sums and error bounds were
 * most of their ~340 instructions). The centre's + 0.0 turns a -0 into
 * 0, as the general path's sums do. Returns false, writing nothing a
 * caller keeps, when a product is subnormal: the general path then
 * accounts for its loss (and for an overflow, as before). want_hull
 * false leaves the hull [-inf, inf].
 */
static inline __attribute__((always_inline)) bool
scale_exact(aa_form *z, double a, const aa_form *x, unsigned flags, bool want_hull)
{
    int n = x->n;
    const double *xc = x->c;
    double *zc = z->c;
    double x0 = a * x->x0, err = fabs(a) * x->err;
    double lo = -INFINITY, hi = INFINITY;
    if (want_hull)
        scale_ends(a, x->lo, x->hi, &lo, &hi);
    if (a < 1.0 && a > -1.0) {    /* FACTOR_POW2: a product may be subnormal */
        double slo = a > 0.0 ? x->lo : x->hi, shi = a > 0.0 ? x->hi : x->lo;
        int uf = (fabs(x0) < 0x1p-1022) & (x->x0 != 0.0);
        uf |= (err < 0x1p-1022) & (x->err != 0.0);
        if (want_hull)
            uf |= ((fabs(lo) < 0x1p-1022) & (slo != 0.0)) |
                  ((fabs(hi) < 0x1p-1022) & (shi != 0.0));
        for (int i = 0; i < n; i++)
            uf |= (fabs(a * xc[i]) < 0x1p-1022) & (xc[i] != 0.0);
        if (uf)
            return false;
    } else {                      /* FACTOR_EXACT: a product may overflow */
        double big = 0.0;
        for (int i = 0; i < n; i++)
            big += fabs(a * xc[i]);
        if (!(big < INFINITY))
            return false;
    }
    /* (z may be x: nothing is written before the products are known exact) */
    for (int i = 0; i < n; i++)
        zc[i] = a * xc[i];
    finish_form(z, x0 + 0.0, err, lo + 0.0, hi + 0.0, n, flags);
    return true;
}

/*
 * z = a*x + b*y + c. Coefficients in RN: the exact error of each sum from
 * TwoSum (so x - x is exactly 0), 2^-53 of each product by an inexact
 * factor, 2^-1075 per product that underflowed, all summed and bounded from
 * above once (lincomb_loops; the bookkeeping a factor does not need is
 * multiplied away: wa, wb are 0 or 1). want_hull false leaves the hull
 * [-inf, inf] for a caller that sets its own (aa_apply_linear, aa_merge).
 */
static inline __attribute__((always_inline)) void
lincomb(aa_form *z, double a, const aa_form *x, double b, const aa_form *y, double c,
        bool want_hull)
{
    static const aa_form zero = { .x0 = 0.0 };
    if (y == NULL) {
        y = &zero;
        b = 0.0;
    }
    unsigned flags = x->flags | y->flags;
    if (((x->flags & AA_UNBOUNDED) && a != 0.0) ||
        ((y->flags & AA_UNBOUNDED) && b != 0.0) || !isfinite(a) ||
        !isfinite(b) || !isfinite(c)) {
        aa_unbounded(z, flags);
        return;
    }
    flags &= ~AA_UNBOUNDED;
    int ka = factor_kind(a), kb = factor_kind(b);
    if (b == 0.0 && c == 0.0 && a != 0.0 && ka != FACTOR_INEXACT &&
        scale_exact(z, a, x, flags, want_hull))
        return;
    double wa = ka == FACTOR_INEXACT ? 1.0 : 0.0, wb = kb == FACTOR_INEXACT ? 1.0 : 0.0;
    int xn = (a == 0.0) ? 0 : x->n, yn = (b == 0.0) ? 0 : y->n;
    int n = xn > yn ? xn : yn;
    double x0 = x->x0, y0 = y->x0;
    double xe = a == 0.0 ? 0.0 : x->err, ye = b == 0.0 ? 0.0 : y->err;
    /* the hull a*[x] + b*[y] + c in RN: two products and two sums err by
     * at most 3u times the sum of the magnitudes, plus the products'
     * underflow; hb = fp_rounding_bound(3 * that) is at least twice it.
     * Moving the RN end out by 2*hb, itself in RN, errs by at most
     * u*(|end| + 2*hb) <= hb more, so the end moves out by >= hb. */
    double hlo = -INFINITY, hhi = INFINITY;
    if (want_hull) {
        double l1 = 0.0, h1 = 0.0, l2 = 0.0, h2 = 0.0;
        int huf = 0;
        if (a != 0.0) {
            scale_ends(a, x->lo, x->hi, &l1, &h1);
            huf |= uflow_k(ka, l1, a > 0.0 ? x->lo : x->hi) |
                   uflow_k(ka, h1, a > 0.0 ? x->hi : x->lo);
        }
        if (b != 0.0) {
            scale_ends(b, y->lo, y->hi, &l2, &h2);
            huf |= uflow_k(kb, l2, b > 0.0 ? y->lo : y->hi) |
                   uflow_k(kb, h2, b > 0.0 ? y->hi : y->lo);
        }
        double hb = 2.0 * fp_rounding_bound(3.0 * (fabs(l1) + fabs(h1) + fabs(l2) + fabs(h2) +
                                                   fabs(c)), huf);
        hlo = (l1 + l2 + c) - hb;
        hhi = (h1 + h2 + c) + hb;
    }

    double es = 0.0;      /* sum of exact errors of the additions */
    double ap = 0.0;      /* sum of |inexact products| */
    int uf = 0;           /* a product may have underflowed */
    if (ka == FACTOR_EXACT && kb == FACTOR_EXACT)      /* add, sub, neg */
        lincomb_loops(0, a, x->c, xn, b, y->c, yn, z->c, 0, 0, 0, 0, &es, &ap, &uf);
    else
        lincomb_loops(1, a, x->c, xn, b, y->c, yn, z->c, ka, kb, wa, wb, &es, &ap, &uf);
    double p = a * x0, q = b * y0;
    double s1 = p + q, s2 = s1 + c;
    es += fabs(fp_two_sum_err(p, q, s1)) + fabs(fp_two_sum_err(s1, c, s2));
    ap += wa * fabs(p) + wb * fabs(q);
    uf |= uflow_k(ka, p, x0) | uflow_k(kb, q, y0);

    double err = 0.0;
    if (xe != 0.0)
        err = ka == FACTOR_EXACT ? xe * fabs(a) : fp_mul_up(fabs(a), xe);
    if (ye != 0.0)
        err = add_up_nn(err, kb == FACTOR_EXACT ? ye * fabs(b) : fp_mul_up(fabs(b), ye));
    err = add_up_nn(err, add_up_nn(sum_err_bound(es), fp_rounding_bound(ap, uf)));

    finish_form(z, s2, err, hlo, hhi, n, flags);
}

void aa_lincomb(aa_context *ctx, aa_form *z, double a, const aa_form *x,
                double b, const aa_form *y, double c)
{
    (void)ctx;
    lincomb(z, a, x, b, y, c, true);
}

/*
 * The shapes of lincomb that the shading VM runs most (issue 24: on
 * dented, constant x form, x + y and x - y were 2/3 of aa_lincomb's time):
 * lincomb inlined with the factors that make them constant, so that the
 * compiler drops the classification of the factors, the product
 * bookkeeping a factor +-1 does not need, the second operand's loop and
 * hull when there is none. What is left is the same operations in the
 * same order on the same values (the build has no contraction and no
 * fast-math), hence bit for bit aa_lincomb's result with those arguments
 * (test_aa_fastpath compares them on random operands).
 */
/*
 * z = a*x + c: lincomb(a, x, 0, NULL, c), written out for a finite nonzero
 * a and c and a bounded x (the rest goes to lincomb): the terms of the
 * absent second operand are the zeros they were (the same sums, in the
 * same order, down to the + 0.0 that turns a -0 into 0), and the product
 * bookkeeping is done only for the factors that need it (issue 24).
 */
static inline __attribute__((always_inline)) void
scale(aa_form *z, double a, const aa_form *x, double c, bool want_hull)
{
    if (a == 0.0 || !isfinite(a) || !isfinite(c) || (x->flags & AA_UNBOUNDED)) {
        lincomb(z, a, x, 0.0, NULL, c, want_hull);
        return;
    }
    unsigned flags = x->flags;
    int ka = factor_kind(a);
    if (c == 0.0 && ka != FACTOR_INEXACT && scale_exact(z, a, x, flags, want_hull))
        return;
    double wa = ka == FACTOR_INEXACT ? 1.0 : 0.0;
    int n = x->n;
    double x0 = x->x0, xe = x->err;
    double hlo = -INFINITY, hhi = INFINITY;
    if (want_hull) {
        double l1, h1;
        scale_ends(a, x->lo, x->hi, &l1, &h1);
        int huf = uflow_k(ka, l1, a > 0.0 ? x->lo : x->hi) |
                  uflow_k(ka, h1, a > 0.0 ? x->hi : x->lo);
        double hb = 2.0 * fp_rounding_bound(3.0 * (fabs(l1) + fabs(h1) + 0.0 + 0.0 + fabs(c)),
                                            huf);
        hlo = (l1 + 0.0 + c) - hb;
        hhi = (h1 + 0.0 + c) + hb;
    }
    const double *xc = x->c;
    double *zc = z->c;
    double ap = 0.0;
    int uf = 0;
    if (ka == FACTOR_EXACT) {
        for (int i = 0; i < n; i++)
            zc[i] = a * xc[i];
    } else {
        for (int i = 0; i < n; i++) {
            double xi = xc[i], p = a * xi;
            ap += wa * fabs(p);
            uf |= uflow_k(ka, p, xi);
            zc[i] = p;
        }
    }
    double p = a * x0, s1 = p + 0.0, s2 = s1 + c;
    double es = fabs(fp_two_sum_err(p, 0.0, s1)) + fabs(fp_two_sum_err(s1, c, s2));
    ap += wa * fabs(p) + 0.0;
    uf |= uflow_k(ka, p, x0);
    double err = 0.0;
    if (xe != 0.0)
        err = ka == FACTOR_EXACT ? xe * fabs(a) : fp_mul_up(fabs(a), xe);
    err = add_up_nn(err, add_up_nn(sum_err_bound(es), fp_rounding_bound(ap, uf)));
    finish_form(z, s2, err, hlo, hhi, n, flags);
}

static void lincomb_scale(aa_form *z, double a, const aa_form *x, double c)
{
    scale(z, a, x, c, true);
}

/*
 * z = x + b*y for b = +-1: lincomb(1, x, b, y, 0) written out (issue 24):
 * the products by +-1 are exact and need no bookkeeping, the tail of the
 * longer operand is one loop, the centre's sum with c = 0 is kept as it
 * was (s1 + 0.0). The same operations on the same values in the same
 * order, hence the same bits (test_aa_fastpath).
 */
static inline __attribute__((always_inline)) void
add_sign(aa_form *z, const aa_form *x, const aa_form *y, double b)
{
    unsigned flags = x->flags | y->flags;
    if (flags & AA_UNBOUNDED) {
        aa_unbounded(z, flags);
        return;
    }
    int xn = x->n, yn = y->n;
    int m = xn < yn ? xn : yn, n = xn > yn ? xn : yn;
    double x0 = x->x0, y0 = y->x0, xe = x->err, ye = y->err;
    double l1 = x->lo, h1 = x->hi, l2, h2;
    scale_ends(b, y->lo, y->hi, &l2, &h2);
    double hb = 2.0 * fp_rounding_bound(3.0 * (fabs(l1) + fabs(h1) + fabs(l2) + fabs(h2) + 0.0),
                                        0);
    double hlo = (l1 + l2 + 0.0) - hb, hhi = (h1 + h2 + 0.0) + hb;
    const double *xc = x->c, *yc = y->c;
    double *zc = z->c;
    double es = 0.0;
    for (int i = 0; i < m; i++) {
        double p = xc[i], q = b * yc[i], s = p + q;
        es += fabs(fp_two_sum_err(p, q, s));
        zc[i] = s;
    }
    const double *tc = xn > yn ? xc : yc;      /* the longer one's own symbols */
    double tb = xn > yn ? 1.0 : b;
    for (int i = m; i < n; i++)
        zc[i] = tb * tc[i];
    double q = b * y0, s1 = x0 + q, s2 = s1 + 0.0;
    es += fabs(fp_two_sum_err(x0, q, s1)) + fabs(fp_two_sum_err(s1, 0.0, s2));
    double err = 0.0;
    if (xe != 0.0)
        err = xe;
    if (ye != 0.0)
        err = add_up_nn(err, ye);
    err = add_up_nn(err, sum_err_bound(es));
    finish_form(z, s2, err, hlo, hhi, n, flags);
}

/*
 * One row of a transformation: every coefficient (and the centre) is a sum
 * of at most three products (four terms with c) in RN, whose error is at
 * most gamma_3 = 3u/(1 - 3u) times the sum of the terms' magnitudes plus
 * the products' underflow (u = 2^-53). fp_rounding_bound(3 * sum) gives
 * 6u * sum + 2^-1022, which covers both. The errors, all nonnegative, are
 * added in RN and the total is raised by 2^-50 of itself (more than the RN
 * error of those few additions) and one step: one rounding for the lot.
 */
/*
 * centred: x_k - centre(x_k) in place of x_k, bit for bit what
 * aa_add_s(ctx, &y_k, &x_k, -x_k.x0) followed by the plain row gives
 * (y_k: the same coefficients and err, centre 0, the hull x_k's moved by
 * -x0 and widened as aa_lincomb widens it; centred_hull), without the
 * three copies.
 */
static inline __attribute__((always_inline)) void
centred_hull(const aa_form *x, double *lo, double *hi)
{
    /* lincomb(y, 1, x, 0, NULL, -x0): hull (x.lo + 0 + c) - hb, hb from
     * the magnitudes |x.lo| + |x.hi| + 0 + 0 + |c| (a factor 1: exact) */
    double c = -x->x0;
    if (c == 0.0) {               /* lincomb's exact path (scale_exact) */
        *lo = x->lo + 0.0;
        *hi = x->hi + 0.0;
        *lo = *lo == *lo ? *lo : -INFINITY;
        *hi = *hi == *hi ? *hi : INFINITY;
        return;
    }
    double hb = 2.0 * fp_rounding_bound(3.0 * (fabs(x->lo) + fabs(x->hi) + 0.0 + 0.0 +
                                               fabs(c)), 0);
    double l = (x->lo + 0.0 + c) - hb, h = (x->hi + 0.0 + c) + hb;
    *lo = l == l ? l : -INFINITY;
    *hi = h == h ? h : INFINITY;
}

static inline __attribute__((always_inline)) void
lincomb3(aa_form *z, const double m[3], const aa_form x[3], double c, bool centred)
{
    assert(z < x || z >= x + 3);
    unsigned flags = 0;
    bool unbounded = !isfinite(c);
    int n = 0;
    for (int k = 0; k < 3; k++) {
        flags |= x[k].flags;
        if (!isfinite(m[k]) || (m[k] != 0.0 && (x[k].flags & AA_UNBOUNDED)))
            unbounded = true;
        if (m[k] != 0.0 && x[k].n > n)
            n = x[k].n;
    }
    if (unbounded) {
        aa_unbounded(z, flags);
        return;
    }
    flags &= ~AA_UNBOUNDED;

    double terms = 0.0, x0 = c, centre = fabs(c), perr = 0.0;
    double lo = c, hi = c, hull = fabs(c);
    int uf = 0, cuf = 0, huf = 0;
    int zn = 0;                   /* z->c[0..zn) hold partial sums; n at the end */
    double *zc = z->c;
    for (int k = 0; k < 3; k++) {
        double a = m[k];
        if (a == 0.0)
            continue;
        const aa_form *xk = &x[k];
        const double *xc = xk->c;
        int xn = xk->n, both = xn < zn ? xn : zn;
        double R = 0.0;
        for (int j = 0; j < both; j++) {        /* add to the partial sums */
            double v = xc[j], p = a * v;
            zc[j] += p;
            R += fabs(v);
            uf |= (fabs(p) < 0x1p-1022) & (v != 0.0);
        }
        for (int j = both; j < xn; j++) {       /* the first term of these */
            double v = xc[j], p = a * v;
            zc[j] = p;
            R += fabs(v);
            uf |= (fabs(p) < 0x1p-1022) & (v != 0.0);
        }
        if (xn > zn)
            zn = xn;
        double fa = fabs(a);
        terms += fa * R;
        double xk0 = centred ? 0.0 : xk->x0, xklo = xk->lo, xkhi = xk->hi;
        if (centred)
            centred_hull(xk, &xklo, &xkhi);
        double p = a * xk0;
        x0 += p;
        centre += fabs(p);
        cuf += fp_uflow(p, a, xk0);
        double pe = fa * xk->err;
        perr += pe;
        cuf += fp_uflow(pe, fa, xk->err);
        double l, h;
        scale_ends(a, xklo, xkhi, &l, &h);
        lo += l;
        hi += h;
        hull += fabs(l) + fabs(h);
        huf += fabs(l) < 0x1p-1022 || fabs(h) < 0x1p-1022;
    }
    /* (cuf also counts private errors whose product underflowed: their
     * eta is in the centre's bound, the relative raise below does not
     * cover an absolute loss) */
    double e = perr + fp_rounding_bound(3.0 * terms, uf) +
               fp_rounding_bound(3.0 * centre, cuf);
    z->x0 = x0;
    z->err = e == 0.0 ? 0.0 : fp_next_up(e + e * 0x1p-50);
    double hb = fp_rounding_bound(3.0 * hull, huf);
    lo = fp_add_dn(lo, -hb);
    hi = fp_add_up(hi, hb);
    z->lo = lo == lo ? lo : -INFINITY;
    z->hi = hi == hi ? hi : INFINITY;
    z->n = (unsigned short)n;
    z->flags = (unsigned short)flags;
    if (!isfinite(x0) || !isfinite(z->err))
        aa_unbounded(z, flags);
}

void aa_lincomb3(aa_context *ctx, aa_form *z, const double m[3], const aa_form x[3],
                 double c)
{
    (void)ctx;
    lincomb3(z, m, x, c, false);
}

void aa_lincomb3_centred(aa_context *ctx, aa_form *z, const double m[3],
                         const aa_form x[3], double c)
{
    (void)ctx;
    lincomb3(z, m, x, c, true);
}

/* aa_lincomb(1, x, +-1, y, 0), written out as add_sign */
void aa_add(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    (void)ctx;
    add_sign(z, x, y, 1.0);
}

void aa_sub(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    (void)ctx;
    add_sign(z, x, y, -1.0);
}

void aa_neg(aa_context *ctx, aa_form *z, const aa_form *x)
{
    (void)ctx;
    lincomb_scale(z, -1.0, x, 0.0);
}

void aa_add_s(aa_context *ctx, aa_form *z, const aa_form *x, double s)
{
    (void)ctx;
    lincomb_scale(z, 1.0, x, s);
}

void aa_mul_s(aa_context *ctx, aa_form *z, const aa_form *x, double s)
{
    if (s == 0.0) {                       /* 0 * x = 0, even unbounded x */
        unsigned flags = x->flags & ~AA_UNBOUNDED;
        aa_const(z, 0.0);
        z->flags = (unsigned short)flags;
        return;
    }
    (void)ctx;
    lincomb_scale(z, s, x, 0.0);
}

void aa_apply_linear(aa_context *ctx, aa_form *z, const aa_form *x,
                     double alpha, double zeta, double delta, ia_interval hull,
                     unsigned flags)
{
    scale(z, alpha, x, zeta, false);                 /* the hull is given */
    if (!(z->flags & AA_UNBOUNDED)) {
        z->lo = hull.lo;
        z->hi = hull.hi;
    }
    z->flags |= (unsigned short)(flags & ~AA_UNBOUNDED);
    new_error(ctx, z, delta);
}

/* ---------------------------------------------------------------------- */
/* products                                                                */
/* ---------------------------------------------------------------------- */

/*
 * x*y = x0*y0 + sum (x0*yi + y0*xi) ei + Q, Q the quadratic part.
 * Q's diagonal sum xi*yi*ei^2 lies in [min(0, .), max(0, .)] per term: its
 * midpoint sum(xi*yi)/2 moves to the centre, its half-width sum|xi*yi|/2
 * stays as error. The rest of Q is bounded by rx*ry - sum|xi*yi| (rx, ry
 * the radii including the private terms). So the new error is
 * rx*ry - sum|xi*yi|/2. With x == y this gives x^2 over [-1,1] as [0,1].
 */
void aa_mul(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    unsigned flags = x->flags | y->flags;
    if (x == y) {                         /* x*x: the Chebyshev square */
        aa_sqr(ctx, z, x);
        return;
    }
    bool xp = aa_is_point(x), yp = !xp && aa_is_point(y);
    if (xp || yp) {
        const aa_form *p = xp ? x : y;
        const aa_form *o = xp ? y : x;
        if (p->x0 == 0.0) {
            aa_const(z, 0.0);
            z->flags = (unsigned short)(flags & ~AA_UNBOUNDED);
            return;
        }
        double k = p->x0;
        lincomb_scale(z, k, o, 0.0);
        z->flags |= (unsigned short)flags;
        return;
    }
    if ((x->flags | y->flags) & AA_UNBOUNDED) {
        aa_unbounded(z, flags);
        return;
    }
    if (x->n == 0 && y->n == 0) {         /* no shared symbols: see affine_funcs.c */
        ia_interval r = ia_mul(aa_range(x), aa_range(y));
        aa_context none;
        aa_context_init(&none, 0);
        aa_set_interval(&none, z, r, r.flags);
        return;
    }
    int xn = x->n, yn = y->n;
    int m = xn < yn ? xn : yn, n = xn > yn ? xn : yn;
    double x0 = x->x0, y0 = y->x0, xe = x->err, ye = y->err;
    const double *xc = x->c, *yc = y->c;
    double *zc = z->c;

    /* as aa_lincomb: the symbols both use, then the rest of the longer;
     * the operands' radii are summed on the way (in symbol order, the
     * same numbers as aa_radius) */
    double es = 0.0, ap = 0.0, dsum = 0.0, dabs = 0.0, sx = 0.0, sy = 0.0;
    int uf = 0, tx = 0, ty = 0;
    for (int i = 0; i < m; i++) {
        double xi = xc[i], yi = yc[i];
        double p = x0 * yi, q = y0 * xi, s = p + q;
        double d = xi * yi;
        es += fabs(fp_two_sum_err(p, q, s));
        ap += fabs(p) + fabs(q);
        dsum += d;
        dabs += fabs(d);
        sx += fabs(xi);
        sy += fabs(yi);
        tx += xi != 0.0;
        ty += yi != 0.0;
        uf |= fp_uflow(p, x0, yi) | fp_uflow(q, y0, xi) | fp_uflow(d, xi, yi);
        zc[i] = s;
    }
    for (int i = m; i < xn; i++) {        /* yi = 0: p = 0, d = 0 */
        double xi = xc[i], q = y0 * xi;
        ap += fabs(q);
        sx += fabs(xi);
        tx += xi != 0.0;
        uf |= fp_uflow(q, y0, xi);
        zc[i] = q;
    }
    for (int i = m; i < yn; i++) {        /* xi = 0 */
        double yi = yc[i], p = x0 * yi;
        ap += fabs(p);
        sy += fabs(yi);
        ty += yi != 0.0;
        uf |= fp_uflow(p, x0, yi);
        zc[i] = p;
    }
    /* z's coefficients are written, x's and y's other fields not yet */
    double rx = radius_from_sum(x, sx, tx), ry = radius_from_sum(y, sy, ty);
    ia_interval hull = ia_mul(range_r(x, rx), range_r(y, ry));
    double p0 = x0 * y0, mid = 0.5 * dsum, s0 = p0 + mid;
    uf |= fp_uflow(p0, x0, y0) | (fabs(mid) < 0x1p-1022 && dsum != 0.0);
    es += fabs(fp_two_sum_err(p0, mid, s0));
    /* errors: 2n + 1 products above, the n products d and their RN sum
     * (at most (n+1) * 2^-53 * dabs), and the halving */
    ap += fabs(p0) + (double)(n + 2) * dabs;

    double err = fp_add_up(fp_mul_up(fabs(x0), ye), fp_mul_up(fabs(y0), xe));
    err = fp_add_up(err, sum_err_bound(es));
    err = fp_add_up(err, fp_rounding_bound(ap, uf));

    /* lower bound of sum|xi*yi|/2 */
    double dlow = dabs - dabs * (double)(n + 2) * 0x1p-52 - 0x1p-1022;   /* >= n * 2^-1074; normal */
    dlow = dlow > 0.0 ? fp_next_down(fp_next_down(dlow) * 0.5) : 0.0;
    double delta = fp_add_up(fp_mul_up(rx, ry), -(dlow > 0.0 ? dlow : 0.0));
    if (delta < 0.0)
        delta = 0.0;

    z->x0 = s0;
    z->err = err;
    z->lo = hull.lo;
    z->hi = hull.hi;
    z->n = (unsigned short)n;
    z->flags = (unsigned short)(flags & ~AA_UNBOUNDED);
    if (!isfinite(s0) || !isfinite(err) || !isfinite(delta) || !isfinite(ap)) {
        aa_unbounded(z, flags);
        return;
    }
    new_error(ctx, z, delta);
}

/* ---------------------------------------------------------------------- */
/* merging two branches (paper §4.1 and §5)                                */
/* ---------------------------------------------------------------------- */

/*
 * x = m + d and y = m - d with m = (x + y)/2, d = (x - y)/2. Both lie in
 * m +- max|d|, so z = m with a new error max|d| = |d0| + radius(d). The
 * shared symbols of x and y stay correlated through m.
 */
void aa_merge(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    unsigned flags = x->flags | y->flags | AA_DISCONTINUOUS;
    if ((x->flags | y->flags) & AA_UNBOUNDED) {
        aa_unbounded(z, flags);
        return;
    }
    aa_form d;
    ia_interval hull = ia_hull(aa_range(x), aa_range(y));
    lincomb(&d, 0.5, x, -0.5, y, 0.0, false);
    lincomb(z, 0.5, x, 0.5, y, 0.0, false);
    z->lo = hull.lo;
    z->hi = hull.hi;
    z->flags = (unsigned short)(flags & ~AA_UNBOUNDED);
    aa_add_new_error(ctx, z, fp_add_up(fabs(d.x0), aa_radius(&d)));
}

void aa_meet_hull(aa_form *z, ia_interval r)
{
    if ((z->flags & AA_UNBOUNDED) || ia_is_empty(r))
        return;
    if (r.lo > z->lo)
        z->lo = r.lo;
    if (r.hi < z->hi)
        z->hi = r.hi;
}

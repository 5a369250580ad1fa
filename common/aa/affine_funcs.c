/*
 * affine_funcs.c: affine approximations of the non-affine library functions
 * (Heidrich & Seidel 1998 §4; Comba & Stolfi 1993; the approximations in
 * Heidrich's TR-1997-3 follow the same two patterns).
 *
 * Each function f over the operand range [a, b] is replaced by
 *
 *     f(x) = alpha*x + zeta +- delta,
 *
 * and delta goes on a new noise symbol. Two ways to get a guaranteed
 * (zeta, delta) for a chosen alpha, i.e. bounds of g(t) = f(t) - alpha*t:
 *
 * 1. Chebyshev on convex pieces (sqr, recip, sqrt, invsqrt, exp, log, pow,
 *    asin, acos, atan, smoothstep, abs). [a, b] is split at the inflection
 *    points of f, which for these functions are exactly representable
 *    (0, or 0.5 for smoothstep's Hermite ramp). alpha is the secant slope,
 *    which makes the approximation the Chebyshev (minimax) one for a convex
 *    f. On a convex piece g's maximum is at an end point, and g is above
 *    its tangent at any point t0 of the piece, so the tangent line's values
 *    at the piece's ends bound g from below; t0 is where f'(t0) = alpha,
 *    which makes that bound tight. Concave pieces are the mirror image.
 *    Every value is an interval enclosure (interval.c), so the bounds hold
 *    whatever the rounding, and t0 need not be accurate to be safe.
 *
 * 2. Taylor with an enclosed remainder (sin, cos, tan), whose inflection
 *    points k*pi are not representable: with c the centre and r the radius,
 *    g(t) = g(c) + (f'(c) - alpha)(t - c) + f''(xi)(t - c)^2/2, and f'' is
 *    enclosed over the whole range by interval arithmetic.
 *
 * Either way the result is compared with the min-range approximation
 * (alpha = 0, the interval result on a new symbol), which is kept when the
 * linear one is much wider (AA_MINRANGE_RATIO): for wide ranges of periodic
 * or saturating functions the interval bound is the better one (sin over a
 * full period gives exactly [-1, 1]).
 *
 * Discontinuous functions (floor, ceil, round, sign, step, mod) are exact
 * on ranges without a jump; across a jump they are approximated with
 * alpha = 1 (floor(t) = t - 1/2 +- 1/2) when many jumps are crossed and by
 * the interval otherwise, and flagged AA_DISCONTINUOUS (paper §5).
 */
#include "aa/affine_internal.h"
#include "aa/rounding.h"

#include <limits.h>
#include <math.h>

/* ---------------------------------------------------------------------- */
/* the two approximation schemes                                           */
/* ---------------------------------------------------------------------- */

/* A function for the Chebyshev scheme: enclosures of f and f' at a point,
 * and an estimate of the point of [p, q] where f' equals alpha. */
typedef struct convex_fn {
    ia_interval (*f)(double t, const void *arg);
    ia_interval (*df)(double t, const void *arg);
    double (*tangent_point)(double alpha, double p, double q, const void *arg);
    const void *arg;
} convex_fn;

typedef struct piece {
    double p, q;
    int convex;          /* +1 convex, -1 concave, 0 linear */
} piece;

/* f at the ends of the operand range, computed once per approximation
 * (the secant's slope needs them, and so do the bounds of the pieces that
 * end there): libm calls are most of the cost of exp, log, atan, ... */
typedef struct ends_memo {
    double a, b;
    ia_interval fa, fb;
} ends_memo;

static ia_interval f_memo(const convex_fn *fn, const ends_memo *m, double t)
{
    if (m && t == m->a) return m->fa;
    if (m && t == m->b) return m->fb;
    return fn->f(t, fn->arg);
}

/* enclosure of g(t) = f(t) - alpha*t */
static ia_interval g_at(const convex_fn *fn, const ends_memo *m, double alpha, double t)
{
    return ia_sub(f_memo(fn, m, t), ia_mul_s(ia_point(t), alpha));
}

static ia_interval g_bounds_on_piece(const convex_fn *fn, const ends_memo *m, double alpha,
                                     const piece *pc)
{
    ia_interval gp = g_at(fn, m, alpha, pc->p), gq = g_at(fn, m, alpha, pc->q);
    ia_interval ends = ia_hull(gp, gq);
    if (pc->convex == 0 || pc->p == pc->q)
        return ends;
    double t0 = fn->tangent_point(alpha, pc->p, pc->q, fn->arg);
    if (!(t0 >= pc->p && t0 <= pc->q))    /* NaN or outside: clamp */
        t0 = t0 < pc->p ? pc->p : (t0 > pc->q ? pc->q : 0.5 * (pc->p + pc->q));
    ia_interval f0 = f_memo(fn, m, t0);
    ia_interval g0 = ia_sub(f0, ia_mul_s(ia_point(t0), alpha));
    /* exp is its own derivative: one libm call, not two */
    ia_interval d0 = fn->df == fn->f ? f0 : fn->df(t0, fn->arg);
    ia_interval slope = ia_sub(d0, ia_point(alpha));
    ia_interval lp = ia_add(g0, ia_mul(slope, ia_sub(ia_point(pc->p), ia_point(t0))));
    ia_interval lq = ia_add(g0, ia_mul(slope, ia_sub(ia_point(pc->q), ia_point(t0))));
    if (pc->convex > 0) {
        double lo = fmin(lp.lo, lq.lo);
        return ia_make(fmin(lo, ends.lo), ends.hi);
    }
    double hi = fmax(lp.hi, lq.hi);
    return ia_make(ends.lo, fmax(hi, ends.hi));
}

/* From bounds [gl, gh] of g: zeta = the midpoint, delta = the half width,
 * rounded up. Returns false when they are not finite. */
static bool center_radius(ia_interval g, double *zeta, double *delta)
{
    if (ia_is_empty(g) || !isfinite(g.lo) || !isfinite(g.hi))
        return false;
    *zeta = ia_mid(g);
    *delta = fmax(fp_add_up(g.hi, -*zeta), fp_add_up(*zeta, -g.lo));
    return isfinite(*delta);
}

/*
 * The linear approximation keeps its correlation with the operand, which
 * later operations can cancel (log(exp(x)) - x stays near 0); the
 * min-range one does not. So the linear one is kept unless its range is
 * wider than the interval's by more than this factor (sin over a full
 * period: the interval [-1, 1] wins by far).
 */
#define AA_MINRANGE_RATIO 1.5

/*
 * Writes z: the linear approximation (alpha, zeta, delta) if ok and not
 * too wide, else the min-range one (the interval `fallback`).
 */
static void finish(aa_context *ctx, aa_form *z, const aa_form *x, bool ok,
                   double alpha, double zeta, double delta,
                   ia_interval fallback, unsigned flags, double xr)
{
    if (ok) {
        double w_aff = fp_add_up(fp_mul_up(fabs(alpha), xr), delta);
        double w_int = 0.5 * ia_width(fallback);
        if (isfinite(w_aff) && !(w_int * AA_MINRANGE_RATIO < w_aff)) {
            aa_apply_linear(ctx, z, x, alpha, zeta, delta, fallback, flags);
            return;
        }
    }
    aa_set_interval(ctx, z, fallback, flags | fallback.flags);
}

/* Chebyshev approximation of fn over pieces covering [a, b]. */
static void approx_convex(aa_context *ctx, aa_form *z, const aa_form *x,
                          const convex_fn *fn, const piece *pieces, int npieces,
                          double a, double b, ia_interval fallback,
                          unsigned flags, double xr)
{
    double alpha, zeta = 0.0, delta = 0.0;
    bool ok = isfinite(a) && isfinite(b) && a <= b;
    ends_memo memo;
    if (ok && a < b) {
        memo = (ends_memo){ a, b, fn->f(a, fn->arg), fn->f(b, fn->arg) };
        alpha = (ia_mid(memo.fb) - ia_mid(memo.fa)) / (b - a);
    } else {
        alpha = 0.0;            /* a point: the interval is exact enough */
        ok = false;
    }
    if (ok && isfinite(alpha)) {
        ia_interval g = ia_empty();
        for (int i = 0; i < npieces; i++)
            g = ia_hull(g, g_bounds_on_piece(fn, &memo, alpha, &pieces[i]));
        ok = center_radius(g, &zeta, &delta);
    } else {
        ok = false;
    }
    finish(ctx, z, x, ok, alpha, zeta, delta, fallback, flags, xr);
}

/* Splits [a, b] at an exact inflection point s: convexity `below` left of
 * s and -below right of it. Returns the number of pieces. */
static int split_at(double a, double b, double s, int below, piece out[2])
{
    int k = 0;
    if (a < s || (a == s && b == s))
        out[k++] = (piece){ a, fmin(b, s), below };
    if (b > s)
        out[k++] = (piece){ fmax(a, s), b, -below };
    return k;
}

/* Taylor scheme: f and f' enclosed at points, f'' over the whole range. */
static void approx_taylor(aa_context *ctx, aa_form *z, const aa_form *x,
                          ia_interval (*f)(ia_interval),
                          ia_interval (*df)(ia_interval), ia_interval f2,
                          double a, double b, ia_interval fallback,
                          unsigned flags, double xr)
{
    bool ok = isfinite(a) && isfinite(b) && a < b && isfinite(f2.lo) &&
              isfinite(f2.hi);
    double alpha = 0.0, zeta = 0.0, delta = 0.0;
    if (ok) {
        double c = 0.5 * a + 0.5 * b;
        double r = fmax(fp_add_up(b, -c), fp_add_up(c, -a));
        ia_interval dc = df(ia_point(c));
        alpha = ia_mid(dc);
        ia_interval gc = ia_sub(f(ia_point(c)), ia_mul_s(ia_point(c), alpha));
        /* the two interval products of the remainder in closed form, the
         * same numbers ia_mul gives: d*[-r, r] = +-r*max|d|, and
         * f2*[0, h] = [min(0, f2.lo*h), max(0, f2.hi*h)] (directed
         * products are monotone in each factor) */
        ia_interval d = ia_sub(dc, ia_point(alpha));
        double lr = fp_mul_up(fmax(fabs(d.lo), fabs(d.hi)), r);
        double h = fp_mul_up(0.5, fp_mul_up(r, r));
        ia_interval rem = ia_make(f2.lo < 0.0 ? fp_mul_dn(f2.lo, h) : 0.0,
                                  f2.hi > 0.0 ? fp_mul_up(f2.hi, h) : 0.0);
        ia_interval g = ia_add(ia_add(gc, ia_make(-lr, lr)), rem);
        ok = isfinite(alpha) && center_radius(g, &zeta, &delta);
    }
    finish(ctx, z, x, ok, alpha, zeta, delta, fallback, flags, xr);
}

/*
 * Operands without shared noise symbols (n == 0: x0 +- err, the error
 * private) have no correlation a linear approximation could keep: whatever
 * it would put on a new symbol stays unrelated to everything else. So the
 * interval result, on the private error term, is as tight, spends no noise
 * symbol and costs one interval operation. Constants, uniform values and
 * the flat normal of a polygon (normalize(N) in most displacement shaders)
 * go this way.
 */
static void private_result(aa_form *z, ia_interval r)
{
    aa_context none;
    aa_context_init(&none, 0);
    aa_set_interval(&none, z, r, r.flags);
}

#define PRIVATE1(z, x, f)                                                   \
    do {                                                                    \
        if ((x)->n == 0) {                                                  \
            private_result((z), f(aa_range(x)));                            \
            return;                                                         \
        }                                                                   \
    } while (0)
#define PRIVATE2(z, x, y, f)                                                \
    do {                                                                    \
        if ((x)->n == 0 && (y)->n == 0) {                                   \
            private_result((z), f(aa_range(x), aa_range(y)));               \
            return;                                                         \
        }                                                                   \
    } while (0)

/* The operand's range, with the flags the result inherits. */
static ia_interval operand_range(const aa_form *x, unsigned *flags, double *rad)
{
    *flags = x->flags & ~AA_UNBOUNDED;
    *rad = aa_radius(x);
    return aa_range_r(x, *rad);
}

/* ---------------------------------------------------------------------- */
/* point enclosures and tangent points of the smooth functions             */
/* ---------------------------------------------------------------------- */

static ia_interval f_recip(double t, const void *arg) { (void)arg; return ia_recip(ia_point(t)); }
static ia_interval d_recip(double t, const void *arg)
{
    (void)arg;
    return ia_neg(ia_recip(ia_sqr(ia_point(t))));
}
static double t_recip(double al, double p, double q, const void *arg)
{
    (void)arg; (void)p;
    double m = sqrt(-1.0 / al);
    return q <= 0 ? -m : m;
}

static ia_interval f_invsqrt(double t, const void *arg) { (void)arg; return ia_invsqrt(ia_point(t)); }
static ia_interval d_invsqrt(double t, const void *arg)
{
    (void)arg;  /* -1/2 t^(-3/2) */
    ia_interval s = ia_invsqrt(ia_point(t));
    return ia_mul_s(ia_mul(s, ia_sqr(s)), -0.5);
}
static double t_invsqrt(double al, double p, double q, const void *arg)
{
    (void)p; (void)q; (void)arg;
    return pow(-2.0 * al, -2.0 / 3.0);
}

static ia_interval f_exp(double t, const void *arg) { (void)arg; return ia_exp(ia_point(t)); }
static double t_exp(double al, double p, double q, const void *arg)
{
    (void)p; (void)q; (void)arg;
    return log(al);
}

static ia_interval f_log(double t, const void *arg) { (void)arg; return ia_log(ia_point(t)); }
static ia_interval d_log(double t, const void *arg) { (void)arg; return ia_recip(ia_point(t)); }
static double t_log(double al, double p, double q, const void *arg)
{
    (void)p; (void)q; (void)arg;
    return 1.0 / al;
}

/* pow with an integer (arg: int n) or real (arg: double p) exponent */
static ia_interval f_pown(double t, const void *arg)
{
    return ia_pow_int(ia_point(t), *(const int *)arg);
}
static ia_interval d_pown(double t, const void *arg)
{
    int n = *(const int *)arg;
    return ia_mul_s(ia_pow_int(ia_point(t), n - 1), (double)n);
}
static double t_pown(double al, double p, double q, const void *arg)
{
    (void)p;
    int n = *(const int *)arg;
    double m = pow(fabs(al / n), 1.0 / (n - 1));
    return q <= 0 ? -m : m;
}

static ia_interval f_powr(double t, const void *arg)
{
    return ia_pow(ia_point(t), ia_point(*(const double *)arg));
}
static ia_interval d_powr(double t, const void *arg)
{
    double e = *(const double *)arg;
    ia_interval e1 = ia_sub(ia_point(e), ia_point(1.0));
    return ia_mul_s(ia_pow(ia_point(t), e1), e);
}
static double t_powr(double al, double p, double q, const void *arg)
{
    (void)p; (void)q;
    double e = *(const double *)arg;
    return pow(al / e, 1.0 / (e - 1.0));
}

static ia_interval f_asin(double t, const void *arg) { (void)arg; return ia_asin(ia_point(t)); }
static ia_interval f_acos(double t, const void *arg) { (void)arg; return ia_acos(ia_point(t)); }
/* 1/sqrt(1 - t^2) */
static ia_interval d_asin(double t, const void *arg)
{
    (void)arg;
    return ia_invsqrt(ia_sub(ia_point(1.0), ia_sqr(ia_point(t))));
}
static ia_interval d_acos(double t, const void *arg) { return ia_neg(d_asin(t, arg)); }
static double t_asin(double al, double p, double q, const void *arg)
{
    (void)p; (void)arg;  /* 1 - t^2 = 1/alpha^2 */
    double m = sqrt(fmax(0.0, 1.0 - 1.0 / (al * al)));
    return q <= 0 ? -m : m;
}

static ia_interval f_atan(double t, const void *arg) { (void)arg; return ia_atan(ia_point(t)); }
static ia_interval d_atan(double t, const void *arg)
{
    (void)arg;
    return ia_recip(ia_add_s(ia_sqr(ia_point(t)), 1.0));
}
static double t_atan(double al, double p, double q, const void *arg)
{
    (void)p; (void)arg;
    double m = sqrt(fmax(0.0, 1.0 / al - 1.0));
    return q <= 0 ? -m : m;
}

/* smoothstep's ramp over t: 0 below 0, 3t^2 - 2t^3 on [0, 1], 1 above */
static ia_interval f_ramp(double t, const void *arg)
{
    (void)arg;
    return ia_smoothstep(ia_point(0.0), ia_point(1.0), ia_point(t));
}
static ia_interval d_ramp(double t, const void *arg)
{
    (void)arg;
    if (t <= 0.0 || t >= 1.0)
        return ia_point(0.0);
    ia_interval pt = ia_point(t);
    return ia_mul_s(ia_mul(pt, ia_sub(ia_point(1.0), pt)), 6.0);
}
static double t_ramp(double al, double p, double q, const void *arg)
{
    (void)q; (void)arg;  /* 6t(1-t) = alpha */
    double s = sqrt(fmax(0.0, 1.0 - 2.0 * al / 3.0));
    return p < 0.5 ? 0.5 * (1.0 - s) : 0.5 * (1.0 + s);
}

/* ---------------------------------------------------------------------- */
/* smooth functions                                                        */
/* ---------------------------------------------------------------------- */

/*
 * The square in closed form: the Chebyshev scheme above specialised to
 * f(t) = t^2 on [a, b] (the most frequent non-affine operation: every
 * length, dot product and distance). alpha = a + b (in RN; any alpha is
 * sound), g(t) = t^2 - alpha t is convex with its least value -alpha^2/4 at
 * alpha/2 and its largest on [a, b] at an end point, so g lies in
 * [-alpha^2/4, max(g(a), g(b))], each end rounded outward.
 */
void aa_sqr(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_sqr);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    double a = r.lo, b = r.hi;
    bool ok = isfinite(a) && isfinite(b) && a < b;
    double alpha = 0.0, zeta = 0.0, delta = 0.0;
    if (ok) {
        alpha = a + b;
        double ga = fp_add_up(fp_mul_up(a, a), -fp_mul_dn(alpha, a));
        double gb = fp_add_up(fp_mul_up(b, b), -fp_mul_dn(alpha, b));
        double glo = -fp_mul_up(fp_mul_up(alpha, alpha), 0.25);
        ok = isfinite(alpha) && center_radius(ia_make(glo, fmax(ga, gb)), &zeta, &delta);
    }
    finish(ctx, z, x, ok, alpha, zeta, delta, ia_sqr(r), fl, xr);
}

void aa_recip(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_recip);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    static const convex_fn fn = { f_recip, d_recip, t_recip, NULL };
    if (r.lo <= 0 && r.hi >= 0) {
        aa_unbounded(z, fl | AA_DISCONTINUOUS);    /* a pole, as tan's */
        return;
    }
    piece pc = { r.lo, r.hi, r.lo > 0 ? +1 : -1 };
    approx_convex(ctx, z, x, &fn, &pc, 1, r.lo, r.hi, ia_recip(r), fl, xr);
}

/*
 * x / y. By a point y = c (a shader's uniform: s / bwidth), x scaled by
 * q = fl(1/c): for a normal q, |1/c - q| <= ulp(q)/2 <= 2^-53 |q|, which
 * times the largest |x| goes to the private error term; the scale
 * rounds as any scale does, and the hull is met with the intervals'
 * quotient (outward). Else x times y's reciprocal (a form of y's
 * symbols).
 */
void aa_div(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    if (aa_is_point(y) && !(x->flags & AA_UNBOUNDED) && isfinite(y->x0)) {
        double c = y->x0, q = 1.0 / c;
        ia_interval xr = aa_range(x);
        double m = fmax(fabs(xr.lo), fabs(xr.hi));
        double e = fp_mul_up(fp_mul_up(fabs(q), 0x1p-53), m);
        if (c != 0.0 && isfinite(q) && fabs(q) >= 0x1p-1000 && isfinite(e)) {
            unsigned fl = (x->flags | y->flags) & ~AA_UNBOUNDED;
            aa_mul_s(ctx, z, x, q);
            /* the quotient's own error stays private (no new symbol: the
             * reciprocal's interval, which this replaces, had none) */
            z->err = fp_add_up(z->err, e);
            z->lo = fp_add_dn(z->lo, -e);
            z->hi = fp_add_up(z->hi, e);
            z->flags |= (unsigned short)fl;
            aa_meet_hull(z, ia_div(xr, ia_point(c)));
            return;
        }
    }
    aa_form inv;
    aa_recip(ctx, &inv, y);
    if (inv.flags & AA_UNBOUNDED) {
        aa_unbounded(z, x->flags | y->flags | inv.flags);   /* a pole: discontinuous */
        return;
    }
    aa_mul(ctx, z, x, &inv);
}

/*
 * sqrt in closed form (the Chebyshev scheme specialised, as aa_sqr): on
 * [a, b], 0 <= a < b, alpha = 1/(sqrt(a) + sqrt(b)) (the secant slope, in
 * RN; any alpha > 0 is sound). g(t) = sqrt(t) - alpha*t is concave, so its
 * least value on [a, b] is at an end, and its largest over all t >= 0 is
 * 1/(4 alpha), at t = 1/(4 alpha^2) (g' = 1/(2 sqrt t) - alpha = 0). sqrt
 * is correctly rounded: one step each way encloses it.
 */
void aa_sqrt(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_sqrt);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    if (r.hi < 0 || !isfinite(r.hi)) {
        aa_set_interval(ctx, z, ia_sqrt(r), fl);
        return;
    }
    double a = fmax(r.lo, 0.0), b = r.hi;
    ia_interval fallback = ia_sqrt(r);
    bool ok = a < b;
    double alpha = 0.0, zeta = 0.0, delta = 0.0;
    if (ok) {
        double sa = sqrt(a), sb = sqrt(b);
        alpha = 1.0 / (sa + sb);
        double sa_dn = sa == 0.0 ? 0.0 : fp_next_down(sa), sb_dn = fp_next_down(sb);
        double ga = fp_add_dn(sa_dn, -fp_mul_up(alpha, a));
        double gb = fp_add_dn(sb_dn, -fp_mul_up(alpha, b));
        ok = isfinite(alpha) && alpha > 0.0 &&
             center_radius(ia_make(fmin(ga, gb), fp_div_up(0.25, alpha)), &zeta, &delta);
    }
    finish(ctx, z, x, ok, alpha, zeta, delta, fallback, fl, xr);
}

/*
 * inversesqrt in closed form on finite [a, b], 0 < a < b: alpha = the
 * secant slope (RN, < 0; any alpha is sound). g(t) = t^(-1/2) - alpha*t is
 * convex, so its largest value on [a, b] is at an end, and its least over
 * all t > 0 is 1.5 s at t = s^-2, s = (-2 alpha)^(1/3) (g' = -t^(-3/2)/2 -
 * alpha = 0 there, and g = s - alpha s^-2 = s + s/2). s is bounded below
 * without trusting cbrt's accuracy: its result stepped 16 ulps down is used
 * once its cube, rounded up, is at most -2 alpha (else the generic scheme).
 * ia_invsqrt([a, b]) is [f(b).lo, f(a).hi], from the same two evaluations.
 */
static bool invsqrt_closed(double a, double b, ia_interval fa, ia_interval fb,
                           double *alpha, double *zeta, double *delta)
{
    *alpha = (ia_mid(fb) - ia_mid(fa)) / (b - a);
    double m = -2.0 * *alpha;
    if (!(isfinite(*alpha) && *alpha < 0.0 && isfinite(m)))
        return false;
    double s = fp_down_by(cbrt(m), 16);
    if (!(s > 0.0 && fp_mul_up(fp_mul_up(s, s), s) <= m))
        return false;
    double ga = fp_add_up(fa.hi, -fp_mul_dn(*alpha, a));
    double gb = fp_add_up(fb.hi, -fp_mul_dn(*alpha, b));
    return center_radius(ia_make(fp_mul_dn(1.5, s), fmax(ga, gb)), zeta, delta);
}

void aa_invsqrt(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_invsqrt);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    static const convex_fn fn = { f_invsqrt, d_invsqrt, t_invsqrt, NULL };
    if (r.lo <= 0) {                       /* pole at 0 or out of domain */
        aa_set_interval(ctx, z, ia_invsqrt(r), fl);
        return;
    }
    if (isfinite(r.hi) && r.lo < r.hi) {
        ia_interval fa = f_invsqrt(r.lo, NULL), fb = f_invsqrt(r.hi, NULL);
        double alpha, zeta, delta;
        if (invsqrt_closed(r.lo, r.hi, fa, fb, &alpha, &zeta, &delta)) {
            finish(ctx, z, x, true, alpha, zeta, delta, ia_mk_(fb.lo, fa.hi, r.flags), fl, xr);
            return;
        }
    }
    piece pc = { r.lo, r.hi, +1 };
    approx_convex(ctx, z, x, &fn, &pc, 1, r.lo, r.hi, ia_invsqrt(r), fl, xr);
}

/*
 * exp in closed form on finite [a, b], a < b: alpha = the secant slope (RN;
 * any alpha > 0 is sound). g(t) = e^t - alpha*t is convex, so its largest
 * value on [a, b] is at an end, and its least over all t is
 * alpha*(1 - ln alpha), at t = ln alpha; ln alpha is enclosed as a libm
 * result (AA_LIBM_ULPS). exp is increasing and ia_exp bounds each end on
 * its own (the same libm call and clipping at a point as in the interval),
 * so ia_exp([a, b]) is [exp(a).lo, exp(b).hi]: three libm calls in all.
 */
void aa_exp(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_exp);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    if (!(isfinite(r.lo) && isfinite(r.hi) && r.lo < r.hi)) {
        static const convex_fn fn = { f_exp, f_exp, t_exp, NULL };
        piece pc = { r.lo, r.hi, +1 };
        approx_convex(ctx, z, x, &fn, &pc, 1, r.lo, r.hi, ia_exp(r), fl, xr);
        return;
    }
    double a = r.lo, b = r.hi;
    ia_interval fa = f_exp(a, NULL), fb = f_exp(b, NULL);
    ia_interval fallback = ia_mk_(fa.lo, fb.hi, r.flags);
    double alpha = (ia_mid(fb) - ia_mid(fa)) / (b - a), zeta = 0.0, delta = 0.0;
    bool ok = isfinite(alpha) && alpha > 0.0;
    if (ok) {
        double ga = fp_add_up(fa.hi, -fp_mul_dn(alpha, a));
        double gb = fp_add_up(fb.hi, -fp_mul_dn(alpha, b));
        double ln_hi = fp_up_by(log(alpha), AA_LIBM_ULPS);
        double glo = fp_mul_dn(alpha, fp_add_dn(1.0, -ln_hi));
        ok = center_radius(ia_make(glo, fmax(ga, gb)), &zeta, &delta);
    }
    finish(ctx, z, x, ok, alpha, zeta, delta, fallback, fl, xr);
}

void aa_log(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_log);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    static const convex_fn fn = { f_log, d_log, t_log, NULL };
    if (r.lo <= 0) {
        aa_set_interval(ctx, z, ia_log(r), fl);
        return;
    }
    piece pc = { r.lo, r.hi, -1 };
    approx_convex(ctx, z, x, &fn, &pc, 1, r.lo, r.hi, ia_log(r), fl, xr);
}

void aa_pow_int(aa_context *ctx, aa_form *z, const aa_form *x, int n)
{
    if (n == 0) {
        unsigned fl = x->flags & ~AA_UNBOUNDED;
        aa_const(z, 1.0);
        z->flags = (unsigned short)fl;
        return;
    }
    if (n == 1) {
        if (z != x)
            *z = *x;
        return;
    }
    if (n == 2) {
        aa_sqr(ctx, z, x);
        return;
    }
    if (x->n == 0) {
        private_result(z, ia_pow_int(aa_range(x), n));
        return;
    }
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    ia_interval fallback = ia_pow_int(r, n);
    if (n < -(1 << 20) || n > (1 << 20) || (n < 0 && r.lo <= 0 && r.hi >= 0)) {
        aa_set_interval(ctx, z, fallback, fl);
        return;
    }
    convex_fn fn = { f_pown, d_pown, t_pown, &n };
    piece pcs[2];
    int k;
    bool even = n % 2 == 0;
    if (n > 0)        /* odd: concave below 0, convex above; even: convex */
        k = even ? (pcs[0] = (piece){ r.lo, r.hi, +1 }, 1)
                 : split_at(r.lo, r.hi, 0.0, -1, pcs);
    else              /* t > 0 convex; t < 0: convex if even, concave if odd */
        k = (pcs[0] = (piece){ r.lo, r.hi, (r.lo > 0 || even) ? +1 : -1 }, 1);
    approx_convex(ctx, z, x, &fn, pcs, k, r.lo, r.hi, fallback, fl, xr);
}

static bool is_int_value(double v, int *n)
{
    if (!(fabs(v) <= (double)(INT_MAX / 2)) || floor(v) != v)
        return false;
    *n = (int)v;
    return true;
}

void aa_pow(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    int n;
    if (aa_is_point(y) && is_int_value(y->x0, &n)) {
        unsigned yf = y->flags;
        aa_pow_int(ctx, z, x, n);
        z->flags |= (unsigned short)(yf & ~AA_UNBOUNDED);
        return;
    }
    PRIVATE2(z, x, y, ia_pow);
    unsigned fl = (x->flags | y->flags) & ~AA_UNBOUNDED;
    double xr = aa_radius(x);
    ia_interval rx = aa_range_r(x, xr), ry = aa_range(y);
    ia_interval fallback = ia_pow(rx, ry);
    if (aa_is_point(y)) {
        double e = y->x0;
        if (rx.hi < 0 || (e < 0 && rx.lo <= 0)) {
            aa_set_interval(ctx, z, fallback, fl);
            return;
        }
        double a = fmax(rx.lo, 0.0);
        convex_fn fn = { f_powr, d_powr, t_powr, &e };
        piece pc = { a, rx.hi, (e > 1.0 || e < 0.0) ? +1 : -1 };
        approx_convex(ctx, z, x, &fn, &pc, 1, a, rx.hi, fallback, fl, xr);
        return;
    }
    if (rx.lo > 0 && isfinite(rx.hi)) {   /* x^y = exp(y log x) */
        aa_form l;
        aa_log(ctx, &l, x);
        aa_mul(ctx, &l, &l, y);
        aa_exp(ctx, z, &l);
        aa_meet_hull(z, fallback);
        ia_interval got = aa_range(z);
        if (!(ia_width(fallback) < ia_width(got)))
            return;
    }
    aa_set_interval(ctx, z, fallback, fl | fallback.flags);
}

/*
 * sin and cos: the Taylor scheme (approx_taylor) in closed form, as aa_sqr
 * is the Chebyshev scheme's (issue 24: the interval enclosures of f and f'
 * at the centre were half of an affine sin's ~2,400 instructions). With c
 * the centre of the operand's range [a, b] and r >= max|t - c| on it,
 * g(t) = f(t) - alpha t is
 *     g(c) + (f'(c) - alpha)(t - c) + f''(xi)(t - c)^2 / 2,
 * f'' = -f (both), enclosed over [a, b] by the negated interval result.
 * alpha is libm's f'(c) and g(c) = f(c) - alpha c is taken in round to
 * nearest; their errors are bounded a priori: libm's values within
 * AA_LIBM_ULPS = 4 ulps (rounding.h), at most 2^-50 of the value or
 * 2^-1072 for a subnormal one, the product and the difference within
 * 2^-53 of theirs, so 2^-49 (|f(c)| + |alpha c| + |g(c)|) + 2^-1000
 * bounds |g(c) - fl(g(c))|, and |f'(c) - alpha| r is at most
 * (2^-49 |alpha| + 2^-1000) r; each of these sums, taken in round to
 * nearest, errs by far less than the factor 2 the 2^-49 leaves (it needs
 * 2^-50 + 2^-52). The ends of g's enclosure then round outward.
 */
static void approx_sincos(aa_context *ctx, aa_form *z, const aa_form *x, bool is_cos)
{
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    ia_interval fallback = is_cos ? ia_cos(r) : ia_sin(r);
    double a = r.lo, b = r.hi;
    bool ok = isfinite(a) && isfinite(b) && a < b;
    double alpha = 0.0, zeta = 0.0, delta = 0.0;
    if (ok) {
        double c = 0.5 * a + 0.5 * b;
        double rad = fmax(fp_add_up(b, -c), fp_add_up(c, -a));
        double sc = sin(c), cc = cos(c);
        double f = is_cos ? cc : sc;
        alpha = is_cos ? -sc : cc;
        double p = alpha * c, g0 = f - p;
        double e = (fabs(f) + fabs(p) + fabs(g0)) * 0x1p-49 + 0x1p-1000;
        double lr = (fabs(alpha) * 0x1p-49 + 0x1p-1000) * rad;
        double h = fp_mul_up(0.5, fp_mul_up(rad, rad));
        /* f'' = -f over [a, b]: in -fallback; times (t - c)^2 / 2 in [0, h] */
        double rlo = fallback.hi > 0.0 ? fp_mul_dn(-fallback.hi, h) : 0.0;
        double rhi = fallback.lo < 0.0 ? fp_mul_up(-fallback.lo, h) : 0.0;
        double spread = fp_add_up(e, lr);
        ia_interval g = ia_make(fp_add_dn(fp_add_dn(g0, -spread), rlo),
                                fp_add_up(fp_add_up(g0, spread), rhi));
        ok = isfinite(alpha) && isfinite(spread) && center_radius(g, &zeta, &delta);
    }
    finish(ctx, z, x, ok, alpha, zeta, delta, fallback, fl, xr);
}

void aa_sin(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_sin);
    approx_sincos(ctx, z, x, false);
}

void aa_cos(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_cos);
    approx_sincos(ctx, z, x, true);
}

/* tan' = 1 + tan^2 */
static ia_interval d_tan(ia_interval x)
{
    return ia_add_s(ia_sqr(ia_tan(x)), 1.0);
}

void aa_tan(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_tan);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    ia_interval fallback = ia_tan(r);
    if (fallback.flags & AA_UNBOUNDED) {  /* a pole: whole line, flagged */
        aa_unbounded(z, fl | fallback.flags);
        return;
    }
    /* tan'' = 2 tan (1 + tan^2) */
    ia_interval f2 = ia_mul_s(ia_mul(fallback, d_tan(r)), 2.0);
    approx_taylor(ctx, z, x, ia_tan, d_tan, f2, r.lo, r.hi, fallback, fl, xr);
}

void aa_asin(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_asin);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    ia_interval fallback = ia_asin(r);
    if (ia_is_empty(fallback)) {
        aa_unbounded(z, fl);
        return;
    }
    double a = fmax(r.lo, -1.0), b = fmin(r.hi, 1.0);
    static const convex_fn fn = { f_asin, d_asin, t_asin, NULL };
    piece pcs[2];
    int k = split_at(a, b, 0.0, -1, pcs);   /* concave below 0 */
    approx_convex(ctx, z, x, &fn, pcs, k, a, b, fallback, fl, xr);
}

void aa_acos(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_acos);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    ia_interval fallback = ia_acos(r);
    if (ia_is_empty(fallback)) {
        aa_unbounded(z, fl);
        return;
    }
    double a = fmax(r.lo, -1.0), b = fmin(r.hi, 1.0);
    static const convex_fn fn = { f_acos, d_acos, t_asin, NULL };
    piece pcs[2];
    int k = split_at(a, b, 0.0, +1, pcs);   /* convex below 0 */
    approx_convex(ctx, z, x, &fn, pcs, k, a, b, fallback, fl, xr);
}

void aa_atan(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_atan);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    static const convex_fn fn = { f_atan, d_atan, t_atan, NULL };
    piece pcs[2];
    int k = split_at(r.lo, r.hi, 0.0, +1, pcs);  /* convex below 0 */
    approx_convex(ctx, z, x, &fn, pcs, k, r.lo, r.hi, ia_atan(r), fl, xr);
}

/* z = w + [c.lo, c.hi] for a constant known only as an interval (pi/2) */
static void add_interval_constant(aa_context *ctx, aa_form *z, const aa_form *w,
                                  ia_interval c)
{
    double mid = ia_mid(c);
    double rad = fmax(fp_add_up(c.hi, -mid), fp_add_up(mid, -c.lo));
    ia_interval hull = ia_add(ia_make(w->lo, w->hi), c);
    aa_lincomb(ctx, z, 1.0, w, 0.0, NULL, mid);
    z->err = fp_add_up(z->err, rad);
    z->lo = hull.lo;
    z->hi = hull.hi;
}

/* atan2 away from the branch cut: atan(y/x) for x > 0, and
 * +-pi/2 - atan(x/y) for y > 0 or y < 0. */
void aa_atan2(aa_context *ctx, aa_form *z, const aa_form *y, const aa_form *x)
{
    PRIVATE2(z, y, x, ia_atan2);
    unsigned fl = (x->flags | y->flags) & ~AA_UNBOUNDED;
    ia_interval rx = aa_range(x), ry = aa_range(y);
    ia_interval fallback = ia_atan2(ry, rx);
    bool bounded = !((x->flags | y->flags) & AA_UNBOUNDED);
    aa_form t;
    if (bounded && rx.lo > 0) {
        aa_div(ctx, &t, y, x);
        aa_atan(ctx, &t, &t);
    } else if (bounded && (ry.lo > 0 || ry.hi < 0)) {
        aa_div(ctx, &t, x, y);
        aa_atan(ctx, &t, &t);
        aa_neg(ctx, &t, &t);
        ia_interval half_pi = ia_make(AA_PI_2_LO, AA_PI_2_HI);
        add_interval_constant(ctx, &t, &t, ry.lo > 0 ? half_pi : ia_neg(half_pi));
    } else {
        aa_set_interval(ctx, z, fallback, fl | fallback.flags);
        return;
    }
    if (!(t.flags & AA_UNBOUNDED) &&
        ia_width(aa_range(&t)) <= ia_width(fallback)) {
        *z = t;
        z->flags = (unsigned short)(fl | (t.flags & ~AA_UNBOUNDED));
        aa_meet_hull(z, fallback);
        return;
    }
    aa_set_interval(ctx, z, fallback, fl | fallback.flags);
}

/* ---------------------------------------------------------------------- */
/* continuous piecewise functions                                          */
/* ---------------------------------------------------------------------- */

/* |t| on a range around 0: g(t) = |t| - alpha*t with |alpha| <= 1 is >= 0
 * and 0 at t = 0; its maximum is at an end point. */
void aa_abs(aa_context *ctx, aa_form *z, const aa_form *x)
{
    PRIVATE1(z, x, ia_abs);
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    if (r.lo >= 0) {
        if (z != x)
            *z = *x;
        return;
    }
    if (r.hi <= 0) {
        aa_neg(ctx, z, x);
        return;
    }
    ia_interval fallback = ia_abs(r);
    fl |= AA_KINK;                       /* across 0: the crease */
    if (!isfinite(r.lo) || !isfinite(r.hi)) {
        aa_set_interval(ctx, z, fallback, fl);
        return;
    }
    double alpha = (r.hi + r.lo) / (r.hi - r.lo);
    alpha = fmax(-1.0, fmin(1.0, alpha));
    ia_interval ga = ia_sub(ia_point(-r.lo), ia_mul_s(ia_point(r.lo), alpha));
    ia_interval gb = ia_sub(ia_point(r.hi), ia_mul_s(ia_point(r.hi), alpha));
    ia_interval g = ia_make(0.0, fmax(ga.hi, gb.hi));
    double zeta, delta;
    bool ok = center_radius(g, &zeta, &delta);
    finish(ctx, z, x, ok, alpha, zeta, delta, fallback, fl, xr);
}

/* min(x, y) = (x + y - |x - y|)/2, max(x, y) = (x + y + |x - y|)/2, with
 * rx and ry the operands' aa_range (not both without symbols) */
static void min_max_r(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y,
                      double sign, ia_interval rx, ia_interval ry)
{
    unsigned fl = x->flags | y->flags;
    if (rx.hi <= ry.lo || ry.hi <= rx.lo) {   /* ordered: no new error */
        bool x_low = rx.hi <= ry.lo;
        const aa_form *pick = (sign < 0) == x_low ? x : y;
        if (z != pick)
            *z = *pick;
        z->flags = (unsigned short)fl;
        return;
    }
    if (fl & AA_UNBOUNDED) {
        ia_interval r = sign < 0 ? ia_min(rx, ry) : ia_max(rx, ry);
        aa_set_interval(ctx, z, r, fl | r.flags);
        return;
    }
    aa_form d;
    aa_sub(ctx, &d, x, y);
    aa_abs(ctx, &d, &d);
    aa_form s;
    aa_add(ctx, &s, x, y);
    aa_lincomb(ctx, z, 0.5, &s, 0.5 * sign, &d, 0.0);
    z->flags |= (unsigned short)(fl & ~AA_UNBOUNDED);
    aa_meet_hull(z, sign < 0 ? ia_min(rx, ry) : ia_max(rx, ry));
}

static void min_max(aa_context *ctx, aa_form *z, const aa_form *x,
                    const aa_form *y, double sign)
{
    if (x->n == 0 && y->n == 0) {
        private_result(z, sign < 0 ? ia_min(aa_range(x), aa_range(y)) : ia_max(aa_range(x), aa_range(y)));
        return;
    }
    min_max_r(ctx, z, x, y, sign, aa_range(x), aa_range(y));
}

void aa_min(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    min_max(ctx, z, x, y, -1.0);
}

void aa_max(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    min_max(ctx, z, x, y, +1.0);
}

void aa_clamp(aa_context *ctx, aa_form *z, const aa_form *x,
              const aa_form *lo, const aa_form *hi)
{
    unsigned fl = x->flags | lo->flags | hi->flags;
    if (fl & AA_UNBOUNDED) {
        /* max then min would stay unbounded ([lo, inf] is still infinite):
         * clamp the ranges at once, bounded again when lo and hi are */
        ia_interval r = ia_clamp(aa_range(x), aa_range(lo), aa_range(hi));
        aa_set_interval(ctx, z, r, fl | r.flags);
        return;
    }
    if (x->n == 0) {
        aa_form t;
        aa_max(ctx, &t, x, lo);
        aa_min(ctx, z, &t, hi);
        return;
    }
    /* max(x, lo), then min(that, hi): the same operations, each range
     * computed once, and no copy where x lies between lo and hi (a
     * normalize's clamp to [-1, 1]; issue 24) */
    ia_interval rx = aa_range(x), rl = aa_range(lo), rh = aa_range(hi);
    if (!(rx.hi <= rl.lo) && rl.hi <= rx.lo) {       /* the max is x */
        ia_interval rt = rx;                         /* x's range, the max's flags */
        rt.flags |= lo->flags;
        if (rt.hi <= rh.lo || rh.hi <= rt.lo) {      /* and the min decided too */
            const aa_form *pick = rt.hi <= rh.lo ? x : hi;
            if (z != pick)
                *z = *pick;
            z->flags = (unsigned short)fl;
            return;
        }
        aa_form t = *x;
        t.flags = (unsigned short)(x->flags | lo->flags);
        min_max_r(ctx, z, &t, hi, -1.0, rt, rh);
        return;
    }
    aa_form t;
    min_max_r(ctx, &t, x, lo, +1.0, rx, rl);
    if (t.n == 0 && hi->n == 0)                      /* the max was lo */
        aa_min(ctx, z, &t, hi);
    else
        min_max_r(ctx, z, &t, hi, -1.0, aa_range(&t), rh);
}

/* mix(x, y, a) = x + a*(y - x) */
void aa_mix(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y,
            const aa_form *a)
{
    if (x->n == 0 && y->n == 0 && a->n == 0) {
        private_result(z, ia_mix(aa_range(x), aa_range(y), aa_range(a)));
        return;
    }
    ia_interval hull = ia_mix(aa_range(x), aa_range(y), aa_range(a));
    aa_form d;
    aa_sub(ctx, &d, y, x);
    if (aa_is_point(a)) {
        unsigned af = a->flags;
        aa_lincomb(ctx, z, 1.0, x, a->x0, &d, 0.0);
        z->flags |= (unsigned short)af;
        aa_meet_hull(z, hull);
        return;
    }
    aa_mul(ctx, &d, &d, a);
    aa_add(ctx, z, x, &d);
    aa_meet_hull(z, hull);
}

/* smoothstep(e0, e1, x) = ramp((x - e0)/(e1 - e0)) for constant edges, the
 * ramp's inflection at exactly 1/2. Other edges: the interval result. */
void aa_smoothstep(aa_context *ctx, aa_form *z, const aa_form *e0,
                   const aa_form *e1, const aa_form *x)
{
    /* three points, x on a flat side of e0 < e1 (below e0, or at e1 or
     * above): 0 or 1 exactly, as the interval path below gives it (issue
     * 24, session 29: the filter-width fades of filtered noise,
     * smoothstep(0.2, 0.75, fw) with fw a point in every box run, took
     * 950 instructions a call that way, 3.7 % of the corpus's fbm_du; at
     * x = e0 that path's hull is [0, -0], so it stays there) */
    if (aa_is_point(x) && aa_is_point(e0) && aa_is_point(e1) && e0->x0 < e1->x0 &&
        (x->x0 < e0->x0 || x->x0 >= e1->x0)) {
        unsigned short fl = (unsigned short)((x->flags | e0->flags | e1->flags) & ~AA_UNBOUNDED);
        aa_const(z, x->x0 < e0->x0 ? 0.0 : 1.0);
        z->flags = fl;
        return;
    }
    if (e0->n == 0 && e1->n == 0 && x->n == 0) {
        private_result(z, ia_smoothstep(aa_range(e0), aa_range(e1), aa_range(x)));
        return;
    }
    unsigned fl = (x->flags | e0->flags | e1->flags) & ~AA_UNBOUNDED;
    ia_interval r0 = aa_range(e0), r1 = aa_range(e1), rx = aa_range(x);
    ia_interval fallback = ia_smoothstep(r0, r1, rx);
    if (!aa_is_point(e0) || !aa_is_point(e1) || !(e1->x0 > e0->x0) ||
        (x->flags & AA_UNBOUNDED)) {
        aa_set_interval(ctx, z, fallback, fl | fallback.flags);
        return;
    }
    aa_form t, w;
    aa_add_s(ctx, &t, x, -e0->x0);
    aa_const(&w, e1->x0);
    aa_add_s(ctx, &w, &w, -e0->x0);      /* e1 - e0, rounding in w.err */
    aa_div(ctx, &t, &t, &w);
    double tr = aa_radius(&t);
    ia_interval rt = aa_range_r(&t, tr);
    static const convex_fn fn = { f_ramp, d_ramp, t_ramp, NULL };
    piece pcs[2];
    int k = split_at(rt.lo, rt.hi, 0.5, +1, pcs);   /* convex below 1/2 */
    approx_convex(ctx, z, &t, &fn, pcs, k, rt.lo, rt.hi, fallback, fl, tr);
}

/* ---------------------------------------------------------------------- */
/* discontinuous functions (paper §5)                                      */
/* ---------------------------------------------------------------------- */

/*
 * floor, ceil and round are t plus a bounded offset: floor(t) in t - [0, 1],
 * ceil(t) in t + [0, 1], round(t) in t + [-1/2, 1/2]. Across one jump the
 * interval [k, k+1] is tighter; across several, the offset form keeps the
 * correlation with t (so t - floor(t) stays within [0, 1]).
 */
static void stepped(aa_context *ctx, aa_form *z, const aa_form *x,
                    ia_interval (*fi)(ia_interval), double offset)
{
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    ia_interval v = fi(r);
    if (v.lo == v.hi && isfinite(v.lo)) {      /* no jump inside */
        aa_const(z, v.lo);
        z->flags = (unsigned short)fl;
        return;
    }
    if (!isfinite(r.lo) || !isfinite(r.hi) || v.hi - v.lo <= 1.0) {
        aa_set_interval(ctx, z, v, fl | v.flags);
        return;
    }
    aa_apply_linear(ctx, z, x, 1.0, offset, 0.5, v, fl | AA_DISCONTINUOUS);
}

void aa_floor(aa_context *ctx, aa_form *z, const aa_form *x) { stepped(ctx, z, x, ia_floor, -0.5); }
void aa_ceil(aa_context *ctx, aa_form *z, const aa_form *x)  { stepped(ctx, z, x, ia_ceil, 0.5); }
void aa_round(aa_context *ctx, aa_form *z, const aa_form *x) { stepped(ctx, z, x, ia_round, 0.0); }

void aa_sign(aa_context *ctx, aa_form *z, const aa_form *x)
{
    unsigned fl;
    double xr;
    ia_interval r = operand_range(x, &fl, &xr);
    ia_interval v = ia_sign(r);
    if (v.lo == v.hi) {
        aa_const(z, v.lo);
        z->flags = (unsigned short)fl;
        return;
    }
    aa_set_interval(ctx, z, v, fl | v.flags);
}

void aa_step(aa_context *ctx, aa_form *z, const aa_form *edge, const aa_form *x)
{
    unsigned fl = (x->flags | edge->flags) & ~AA_UNBOUNDED;
    aa_form d;
    aa_sub(ctx, &d, x, edge);
    ia_interval v = ia_step(ia_point(0.0), aa_range(&d));
    if (v.lo == v.hi) {
        aa_const(z, v.lo);
        z->flags = (unsigned short)fl;
        return;
    }
    aa_set_interval(ctx, z, v, fl | v.flags);
}

/* mod(x, y) = x - y*floor(x/y): exact x - k*y where floor(x/y) is one k. */
void aa_mod(aa_context *ctx, aa_form *z, const aa_form *x, const aa_form *y)
{
    unsigned fl = (x->flags | y->flags) & ~AA_UNBOUNDED;
    ia_interval rx = aa_range(x), ry = aa_range(y);
    ia_interval v = ia_mod(rx, ry);
    if (!((x->flags | y->flags) & AA_UNBOUNDED) && !(ry.lo <= 0 && ry.hi >= 0)) {
        ia_interval k = ia_floor(ia_div(rx, ry));
        if (k.lo == k.hi && isfinite(k.lo)) {
            aa_lincomb(ctx, z, 1.0, x, -k.lo, y, 0.0);
            z->flags = (unsigned short)fl;
            aa_meet_hull(z, v);
            return;
        }
    }
    aa_set_interval(ctx, z, v, fl | v.flags);
}

/*
 * interval.c: rounding-safe interval arithmetic (see interval.h).
 *
 * Method (docs/arithmetic.md): every bound is computed in round-to-nearest
 * and then moved outward. For + and - the exact rounding error is known
 * (TwoSum), so the bound moves only when the sum was inexact: that is true
 * directed rounding. For * / sqrt the result moves one step outward unless it
 * is trivially exact (a zero operand). libm results move AA_LIBM_ULPS steps.
 * Functions are evaluated at the points where they reach their extremes on
 * the operand range (end points, critical points, corners); the critical
 * point tests of the periodic functions carry an explicit tolerance so that
 * a critical point that rounding puts just outside the range still counts.
 */
#include "aa/interval.h"
#include "aa/rounding.h"

#include <float.h>
#include <limits.h>
#include <math.h>

/* ---------------------------------------------------------------------- */
/* small helpers                                                           */
/* ---------------------------------------------------------------------- */

#define min2 ia_min2_
#define max2 ia_max2_
#define min4 ia_min4_
#define max4 ia_max4_
#define mk ia_mk_

/* libm result v widened to an enclosure of the exact function value. */
static double lm_dn(double v) { return fp_down_by(v, AA_LIBM_ULPS); }
static double lm_up(double v) { return fp_up_by(v, AA_LIBM_ULPS); }

/* ---------------------------------------------------------------------- */
/* construction                                                            */
/* ---------------------------------------------------------------------- */

bool ia_contains(ia_interval x, double v) { return x.lo <= v && v <= x.hi; }
double ia_width(ia_interval x) { return fp_add_up(x.hi, -x.lo); }

double ia_mid(ia_interval x)
{
    if (isinf(x.lo) || isinf(x.hi))
        return (isinf(x.lo) && isinf(x.hi)) ? 0.0 : (isinf(x.lo) ? x.hi : x.lo);
    double m = 0.5 * x.lo + 0.5 * x.hi;   /* no overflow */
    return m;
}


ia_interval ia_merge(ia_interval x, ia_interval y)
{
    ia_interval r = ia_hull(x, y);
    r.flags |= AA_DISCONTINUOUS;
    return r;
}

/* Empty operands give empty results, with the flags of both. */
#define RETURN_IF_EMPTY1(x) \
    do { if (ia_is_empty(x)) return (x); } while (0)
#define RETURN_IF_EMPTY2(x, y)                                              \
    do {                                                                    \
        if (ia_is_empty(x) || ia_is_empty(y)) {                             \
            ia_interval e_ = ia_empty();                                    \
            e_.flags = (x).flags | (y).flags;                               \
            return e_;                                                      \
        }                                                                   \
    } while (0)

/* ---------------------------------------------------------------------- */
/* affine operations                                                       */
/* ---------------------------------------------------------------------- */

/* ---------------------------------------------------------------------- */
/* products, quotients, powers                                             */
/* ---------------------------------------------------------------------- */

ia_interval ia_recip(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.lo <= 0.0 && x.hi >= 0.0) {
        ia_interval r = ia_entire();        /* a pole, as tan's */
        r.flags |= x.flags | AA_DISCONTINUOUS;
        return r;
    }
    return mk(fp_div_dn(1.0, x.hi), fp_div_up(1.0, x.lo), x.flags);
}

ia_interval ia_div(ia_interval x, ia_interval y)
{
    RETURN_IF_EMPTY2(x, y);
    if (y.lo <= 0.0 && y.hi >= 0.0) {
        ia_interval r = ia_entire();        /* a pole, as tan's */
        r.flags |= x.flags | y.flags | AA_DISCONTINUOUS;
        return r;
    }
    /* y has one sign: the signs of x's ends pick the extreme corners, as
     * for exact quotients; each picked corner's directed quotient bounds
     * that corner (an infinity over an infinity by the whole line), so
     * the result is sound, and it is the four corners' hull unless a
     * corner is such an inf/inf or a nonzero quotient that rounds to 0 */
    double lo, hi;
    if (y.lo > 0.0) {
        if (x.lo >= 0.0)      { lo = fp_div_dn(x.lo, y.hi); hi = fp_div_up(x.hi, y.lo); }
        else if (x.hi <= 0.0) { lo = fp_div_dn(x.lo, y.lo); hi = fp_div_up(x.hi, y.hi); }
        else                  { lo = fp_div_dn(x.lo, y.lo); hi = fp_div_up(x.hi, y.lo); }
    } else {
        if (x.lo >= 0.0)      { lo = fp_div_dn(x.hi, y.hi); hi = fp_div_up(x.lo, y.lo); }
        else if (x.hi <= 0.0) { lo = fp_div_dn(x.hi, y.lo); hi = fp_div_up(x.lo, y.hi); }
        else                  { lo = fp_div_dn(x.hi, y.hi); hi = fp_div_up(x.lo, y.hi); }
    }
    return mk(lo, hi, x.flags | y.flags);
}

ia_interval ia_sqr(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.lo >= 0)
        return mk(fp_mul_dn(x.lo, x.lo), fp_mul_up(x.hi, x.hi), x.flags);
    if (x.hi <= 0)
        return mk(fp_mul_dn(x.hi, x.hi), fp_mul_up(x.lo, x.lo), x.flags);
    return mk(0.0, max2(fp_mul_up(x.lo, x.lo), fp_mul_up(x.hi, x.hi)), x.flags);
}

/* sqrt is correctly rounded (IEEE 754), so one step is enough. */
static double sqrt_dn(double v)
{
    double s = sqrt(v);
    return (s == 0.0 || s == INFINITY) ? s : fp_next_down(s);
}

static double sqrt_up(double v)
{
    double s = sqrt(v);
    return (s == 0.0 || s == INFINITY) ? s : fp_next_up(s);
}

ia_interval ia_sqrt(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.hi < 0) {
        ia_interval e = ia_empty();
        e.flags = x.flags;
        return e;
    }
    return mk(max2(0.0, sqrt_dn(max2(x.lo, 0.0))), sqrt_up(x.hi), x.flags);
}

/* 1/sqrt(v): two correctly rounded operations, two steps each way. */
ia_interval ia_invsqrt(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.hi <= 0) {
        ia_interval e = ia_empty();
        e.flags = x.flags;
        return e;
    }
    double lo = max2(0.0, fp_down_by(1.0 / sqrt(x.hi), 2));
    double hi = x.lo <= 0 ? INFINITY : fp_up_by(1.0 / sqrt(x.lo), 2);
    return mk(lo, hi, x.flags);
}

ia_interval ia_exp(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    double ea = exp(x.lo);     /* a point calls libm once (same values) */
    double lo = max2(0.0, lm_dn(ea));
    double hi = x.hi == INFINITY ? INFINITY : lm_up(x.hi == x.lo ? ea : exp(x.hi));
    if (x.hi <= 0 && hi > 1.0)
        hi = 1.0;                      /* exp(t) <= 1 for t <= 0 */
    if (x.lo >= 0 && lo < 1.0)
        lo = 1.0;
    return mk(lo, hi, x.flags);
}

ia_interval ia_log(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.hi <= 0) {
        ia_interval e = ia_empty();
        e.flags = x.flags;
        return e;
    }
    double lb = log(x.hi);
    double lo = x.lo <= 0 ? -INFINITY : lm_dn(x.lo == x.hi ? lb : log(x.lo));
    double hi = lm_up(lb);
    if (x.hi <= 1.0 && hi > 0.0)
        hi = 0.0;                      /* log(t) <= 0 for t <= 1 */
    if (x.lo >= 1.0 && lo < 0.0)
        lo = 0.0;
    return mk(lo, hi, x.flags);
}

/* Enclosure of t^n for a double t, n != 0 (pow is exact for small cases
 * but in general within a few ulp). */
static double pown_dn(double t, double n)
{
    double p = pow(t, n);
    if (isinf(p))                      /* overflow: |t^n| is at least ~DBL_MAX */
        return (p > 0 && isfinite(t)) ? lm_dn(DBL_MAX) : p;
    return lm_dn(p);
}

static double pown_up(double t, double n)
{
    double p = pow(t, n);
    if (isinf(p))
        return (p < 0 && isfinite(t)) ? lm_up(-DBL_MAX) : p;
    return lm_up(p);
}

ia_interval ia_pow_int(ia_interval x, int n)
{
    RETURN_IF_EMPTY1(x);
    if (n == 0)
        return mk(1.0, 1.0, x.flags);
    if (n == 1)
        return x;
    if (n == 2)
        return ia_sqr(x);
    double dn = (double)n;
    bool even = (n % 2) == 0;
    if (even) {
        /* depends on |t| only: increasing in |t| for n > 0, decreasing
         * for n < 0 */
        double a, b;                   /* range of |t| */
        if (x.lo >= 0) { a = x.lo; b = x.hi; }
        else if (x.hi <= 0) { a = -x.hi; b = -x.lo; }
        else { a = 0.0; b = max2(-x.lo, x.hi); }
        double lo, hi;
        if (n > 0) {
            lo = max2(0.0, pown_dn(a, dn));
            hi = pown_up(b, dn);
        } else {
            lo = max2(0.0, pown_dn(b, dn));
            hi = a == 0.0 ? INFINITY : pown_up(a, dn);
        }
        return mk(lo, hi, x.flags);
    }
    if (n > 0)                          /* odd, increasing */
        return mk(pown_dn(x.lo, dn), pown_up(x.hi, dn), x.flags);
    if (x.lo <= 0 && x.hi >= 0) {       /* odd negative: pole at 0 */
        ia_interval r = ia_entire();
        r.flags |= x.flags;
        return r;
    }
    return mk(pown_dn(x.hi, dn), pown_up(x.lo, dn), x.flags); /* decreasing */
}

/* true if y is one integer that fits an int */
static bool is_int_point(ia_interval y, int *n)
{
    if (y.lo != y.hi || !(fabs(y.lo) <= (double)(INT_MAX / 2)))
        return false;
    if (floor(y.lo) != y.lo)
        return false;
    *n = (int)y.lo;
    return true;
}

/* x^y over x >= 0. ln(x^y) = y*ln(x) is bilinear in (y, ln x) on the box,
 * so the extremes sit at the corners; exp is monotone. */
ia_interval ia_pow(ia_interval x, ia_interval y)
{
    RETURN_IF_EMPTY2(x, y);
    int n;
    if (is_int_point(y, &n)) {
        ia_interval r = ia_pow_int(x, n);
        r.flags |= y.flags;
        return r;
    }
    if (x.hi < 0) {
        ia_interval e = ia_empty();
        e.flags = x.flags | y.flags;
        return e;
    }
    double a = max2(x.lo, 0.0), b = x.hi;
    double c[4] = { pow(a, y.lo), pow(a, y.hi), pow(b, y.lo), pow(b, y.hi) };
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < 4; i++) {
        /* an overflow (inf from a finite base) is only known to exceed
         * about DBL_MAX */
        double low_c = (isinf(c[i]) && (i < 2 ? a : b) != 0.0 && isfinite(i < 2 ? a : b))
                           ? DBL_MAX : c[i];
        lo = min2(lo, low_c);
        hi = max2(hi, c[i]);
    }
    unsigned flags = x.flags | y.flags;
    if (a == 0.0 && y.lo <= 0.0 && y.hi >= 0.0) {
        /* 0^y jumps: 0 for y > 0, 1 at y = 0, +inf for y < 0 */
        flags |= AA_DISCONTINUOUS;
        lo = min2(lo, 0.0);
        hi = max2(hi, y.lo < 0 ? INFINITY : 1.0);
    }
    lo = (lo == 0.0 || isinf(lo)) ? lo : max2(0.0, lm_dn(lo));
    hi = isinf(hi) ? hi : lm_up(hi);
    return mk(lo, hi, flags);
}

/* ---------------------------------------------------------------------- */
/* trigonometry                                                            */
/* ---------------------------------------------------------------------- */

/*
 * Does [a, b] possibly contain offset + k*period for some integer k?
 * (t - offset)/period is computed with a relative error of a few ulps of
 * max(|a|,|b|,offset)/period; the tolerance below is far larger than that,
 * so a true critical point is never missed (a spurious one only loosens).
 */
static bool may_contain_lattice(double a, double b, double offset, double period)
{
    double m = max2(fabs(a), fabs(b)) + fabs(offset) + period;
    double tol = m * 0x1p-44 / period + 0x1p-40;
    double ta = (a - offset) / period - tol;
    double tb = (b - offset) / period + tol;
    return floor(tb) >= ceil(ta);
}

/* Beyond this magnitude a non-degenerate range gets the function's full
 * range: the lattice test above would need more precision than doubles. */
#define TRIG_EXACT_LIMIT 0x1p40

ia_interval ia_sin(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (!isfinite(x.lo) || !isfinite(x.hi) || x.hi - x.lo >= 2 * AA_PI_LO ||
        (x.lo != x.hi && max2(fabs(x.lo), fabs(x.hi)) > TRIG_EXACT_LIMIT))
        return mk(-1.0, 1.0, x.flags & ~AA_UNBOUNDED);
    double sa = sin(x.lo), sb = x.hi == x.lo ? sa : sin(x.hi);
    double lo = lm_dn(min2(sa, sb)), hi = lm_up(max2(sa, sb));
    if (x.lo != x.hi) {   /* a point has no inner extremum: libm's value, widened */
        if (may_contain_lattice(x.lo, x.hi, M_PI_2, 2 * M_PI))
            hi = 1.0;
        if (may_contain_lattice(x.lo, x.hi, -M_PI_2, 2 * M_PI))
            lo = -1.0;
    }
    return mk(max2(lo, -1.0), min2(hi, 1.0), x.flags);
}

ia_interval ia_cos(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (!isfinite(x.lo) || !isfinite(x.hi) || x.hi - x.lo >= 2 * AA_PI_LO ||
        (x.lo != x.hi && max2(fabs(x.lo), fabs(x.hi)) > TRIG_EXACT_LIMIT))
        return mk(-1.0, 1.0, x.flags & ~AA_UNBOUNDED);
    double ca = cos(x.lo), cb = x.hi == x.lo ? ca : cos(x.hi);
    double lo = lm_dn(min2(ca, cb)), hi = lm_up(max2(ca, cb));
    if (x.lo != x.hi) {   /* a point has no inner extremum: libm's value, widened */
        if (may_contain_lattice(x.lo, x.hi, 0.0, 2 * M_PI))
            hi = 1.0;
        if (may_contain_lattice(x.lo, x.hi, M_PI, 2 * M_PI))
            lo = -1.0;
    }
    return mk(max2(lo, -1.0), min2(hi, 1.0), x.flags);
}

ia_interval ia_tan(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (!isfinite(x.lo) || !isfinite(x.hi) || x.hi - x.lo >= AA_PI_LO ||
        (x.lo != x.hi && max2(fabs(x.lo), fabs(x.hi)) > TRIG_EXACT_LIMIT) ||
        may_contain_lattice(x.lo, x.hi, M_PI_2, M_PI)) {
        ia_interval r = ia_entire();
        r.flags |= x.flags | AA_DISCONTINUOUS;
        return r;
    }
    double ta = tan(x.lo), tb = x.hi == x.lo ? ta : tan(x.hi);
    return mk(lm_dn(ta), lm_up(tb), x.flags);  /* increasing */
}

ia_interval ia_asin(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.hi < -1.0 || x.lo > 1.0) {
        ia_interval e = ia_empty();
        e.flags = x.flags;
        return e;
    }
    double a = max2(x.lo, -1.0), b = min2(x.hi, 1.0);
    double sa = asin(a), sb = b == a ? sa : asin(b);
    return mk(max2(lm_dn(sa), -AA_PI_2_HI), min2(lm_up(sb), AA_PI_2_HI), x.flags);
}

ia_interval ia_acos(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.hi < -1.0 || x.lo > 1.0) {
        ia_interval e = ia_empty();
        e.flags = x.flags;
        return e;
    }
    double a = max2(x.lo, -1.0), b = min2(x.hi, 1.0);
    double ca = acos(a), cb = b == a ? ca : acos(b);
    return mk(max2(lm_dn(cb), 0.0), min2(lm_up(ca), AA_PI_HI), x.flags);
}

ia_interval ia_atan(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    double ta = atan(x.lo), tb = x.hi == x.lo ? ta : atan(x.hi);
    return mk(max2(lm_dn(ta), -AA_PI_2_HI), min2(lm_up(tb), AA_PI_2_HI),
              x.flags & ~AA_UNBOUNDED);
}

/* atan2 is continuous on a box that neither contains the origin nor crosses
 * the branch cut (the negative x axis); there the angle's extremes are taken
 * at the box's corners. */
ia_interval ia_atan2(ia_interval y, ia_interval x)
{
    RETURN_IF_EMPTY2(y, x);
    unsigned flags = (x.flags | y.flags) & ~AA_UNBOUNDED;
    bool origin = x.lo <= 0 && x.hi >= 0 && y.lo <= 0 && y.hi >= 0;
    bool cut = x.lo < 0 && y.lo < 0 && y.hi >= 0;
    if (origin || cut)
        return mk(-AA_PI_HI, AA_PI_HI, flags | AA_DISCONTINUOUS);
    double c[4] = { atan2(y.lo, x.lo), atan2(y.lo, x.hi),
                    atan2(y.hi, x.lo), atan2(y.hi, x.hi) };
    double lo = min4(c[0], c[1], c[2], c[3]);
    double hi = max4(c[0], c[1], c[2], c[3]);
    return mk(max2(lm_dn(lo), -AA_PI_HI), min2(lm_up(hi), AA_PI_HI), flags);
}

/* ---------------------------------------------------------------------- */
/* piecewise and discontinuous functions                                   */
/* ---------------------------------------------------------------------- */

ia_interval ia_abs(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    if (x.lo >= 0)
        return x;
    if (x.hi <= 0)
        return ia_neg(x);
    return mk(0.0, max2(-x.lo, x.hi), x.flags | AA_KINK);
}

static double sign_of(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

/* A step function's interval: constant pieces are exact, a jump inside the
 * range sets AA_DISCONTINUOUS. */
static ia_interval stepped(double lo, double hi, unsigned flags)
{
    ia_interval r = mk(lo, hi, flags);
    if (lo != hi)
        r.flags |= AA_DISCONTINUOUS;
    r.flags &= ~AA_UNBOUNDED;
    if (isinf(lo) || isinf(hi))
        r.flags |= AA_UNBOUNDED;
    return r;
}

ia_interval ia_sign(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    return stepped(sign_of(x.lo), sign_of(x.hi), x.flags);
}

/* AA_KINK where the operands' ranges overlap: the min or max may take
 * either inside them */
static unsigned kink_of(ia_interval x, ia_interval y)
{
    return x.hi <= y.lo || y.hi <= x.lo ? 0u : (unsigned)AA_KINK;
}

ia_interval ia_min(ia_interval x, ia_interval y)
{
    RETURN_IF_EMPTY2(x, y);
    return mk(min2(x.lo, y.lo), min2(x.hi, y.hi), x.flags | y.flags | kink_of(x, y));
}

ia_interval ia_max(ia_interval x, ia_interval y)
{
    RETURN_IF_EMPTY2(x, y);
    return mk(max2(x.lo, y.lo), max2(x.hi, y.hi), x.flags | y.flags | kink_of(x, y));
}

ia_interval ia_floor(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    return stepped(floor(x.lo), floor(x.hi), x.flags);
}

ia_interval ia_ceil(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    return stepped(ceil(x.lo), ceil(x.hi), x.flags);
}

ia_interval ia_round(ia_interval x)
{
    RETURN_IF_EMPTY1(x);
    return stepped(round(x.lo), round(x.hi), x.flags);
}

/* mod(x, y) = x - y*floor(x/y), in [0, y) for y > 0 and (y, 0] for y < 0.
 * Where floor(x/y) is one integer k over the whole box, mod is x - k*y. */
ia_interval ia_mod(ia_interval x, ia_interval y)
{
    RETURN_IF_EMPTY2(x, y);
    unsigned flags = x.flags | y.flags;
    if (y.lo <= 0 && y.hi >= 0) {
        ia_interval r = ia_entire();
        r.flags |= flags;
        return r;
    }
    ia_interval k = ia_floor(ia_div(x, y));
    ia_interval bound = y.lo > 0 ? mk(0.0, y.hi, 0) : mk(y.lo, 0.0, 0);
    if (k.lo == k.hi && isfinite(k.lo)) {
        ia_interval r = ia_sub(x, ia_mul_s(y, k.lo));
        r.lo = max2(r.lo, bound.lo);
        r.hi = min2(r.hi, bound.hi);
        r.flags = flags;
        return r;
    }
    bound.flags = flags | AA_DISCONTINUOUS;
    return bound;
}

ia_interval ia_step(ia_interval edge, ia_interval x)
{
    RETURN_IF_EMPTY2(edge, x);
    ia_interval d = ia_sub(x, edge);
    unsigned flags = (x.flags | edge.flags) & ~AA_UNBOUNDED;
    if (d.lo >= 0)
        return mk(1.0, 1.0, flags);
    if (d.hi < 0)
        return mk(0.0, 0.0, flags);
    return mk(0.0, 1.0, flags | AA_DISCONTINUOUS);
}

/* smoothstep at one point (x, e0, e1), enclosed. */
static ia_interval smoothstep_point(double x, double e0, double e1)
{
    ia_interval d = ia_sub(ia_point(x), ia_point(e0));
    ia_interval w = ia_sub(ia_point(e1), ia_point(e0));
    if (d.hi < 0)
        return mk(0.0, 0.0, 0);                         /* x < e0 */
    if (x >= e1 && d.lo >= 0)
        return mk(1.0, 1.0, 0);                         /* x >= e1 >= e0 */
    if (!(w.lo > 0))
        return mk(0.0, 1.0, 0);                         /* e0 ~ e1: a step */
    ia_interval t = ia_div(d, w);
    t.lo = max2(t.lo, 0.0);
    t.hi = min2(t.hi, 1.0);
    /* H(t) = t^2 (3 - 2t) is increasing on [0, 1] */
    ia_interval h = ia_mul(ia_sqr(t), ia_sub(ia_point(3.0), ia_mul_s(t, 2.0)));
    return mk(max2(h.lo, 0.0), min2(h.hi, 1.0), 0);
}

/* smoothstep is nondecreasing in x and nonincreasing in e0 and e1, so its
 * extremes over the box are at (x.lo, e0.hi, e1.hi) and (x.hi, e0.lo, e1.lo). */
ia_interval ia_smoothstep(ia_interval e0, ia_interval e1, ia_interval x)
{
    RETURN_IF_EMPTY2(e0, e1);
    RETURN_IF_EMPTY1(x);
    unsigned flags = (x.flags | e0.flags | e1.flags) & ~AA_UNBOUNDED;
    ia_interval lo = smoothstep_point(x.lo, e0.hi, e1.hi);
    ia_interval hi = x.lo == x.hi && e0.lo == e0.hi && e1.lo == e1.hi
                         ? lo : smoothstep_point(x.hi, e0.lo, e1.lo);   /* all points: once */
    ia_interval r = mk(lo.lo, hi.hi, flags);
    /* where e1 <= e0 is possible, smoothstep degenerates to a step */
    if (e0.hi >= e1.lo && r.lo != r.hi)
        r.flags |= AA_DISCONTINUOUS;
    return r;
}

ia_interval ia_clamp(ia_interval x, ia_interval lo, ia_interval hi)
{
    return ia_min(ia_max(x, lo), hi);
}

ia_interval ia_mix(ia_interval x, ia_interval y, ia_interval a)
{
    ia_interval one_minus_a = ia_sub(ia_point(1.0), a);
    return ia_add(ia_mul(x, one_minus_a), ia_mul(y, a));
}

/*
 * tests/aa/test_aa_containment.c: the containment property test of common/aa.
 *
 * For every operation of interval.h (mode "interval") and of affine.h (mode
 * "affine") it draws AAFARM_PROPERTY_CASES (default 100000) random operand
 * ranges, runs the operation, and checks at about a dozen sample points per
 * range that the exact result, computed by a long double oracle, lies inside
 * what the operation returned. It also checks the flags: AA_DISCONTINUOUS set
 * where a jump lies clearly inside the operand range and not set where a
 * continuous function meets no jump; AA_UNBOUNDED set on division by a range
 * containing 0.
 *
 * Range kinds: moderate [-10,10], sub-ranges of [0,1], tiny (relative width
 * ~1e-12, and absolutely tiny near 0 down to subnormals), huge (1e6..1e300 and
 * DBL_MAX), straddling 0, degenerate (width 0), and "critical" ranges placed at
 * the places where each operation is delicate (poles of tan, 0 for 1/x and
 * log, +-1 for asin, integers and half-integers for floor/round, the overflow
 * threshold of exp, edges of step/smoothstep, multiples of y for mod, ...).
 *
 * Interval mode: operands [lo,hi] are doubles; samples are doubles in [lo,hi]
 * (both ends, the points 1/8 and 7/8 in, random points, points a few ulps
 * from the ends, and the delicate points inside the range); the oracle
 * evaluates f at the exact sample in long double (glibc's sinl, expl, ...).
 *
 * Affine mode checks dependency tracking too. Each case gets a context of
 * capacity 2, 4, 16 or AA_MAX_SYMBOLS (small ones exercise condensation into
 * the private error term), 1..8 inputs made by aa_input, and operands built as
 * affine combinations of those inputs (aa_lincomb, aa_mul_s, aa_add_s) that
 * share at least input 0; some operands also carry the result of a non-affine
 * operation (sqr, mul, sin of inputs), so that they hold an extra symbol or a
 * private error term. Sometimes y is the very same form as x, and sometimes
 * the result aliases the first operand. A sample is an assignment of every
 * noise symbol that existed before the operation, and of each operand's
 * private error symbol, taken from the dyadic grid {-1, -3/4, ..., 1}: the
 * centre, the corners that make each operand extreme, the same corners scaled
 * by 3/4 (inner points), random corners and random grid points, and, for unary
 * operations, a point solved to land on a delicate value. With X the operand's
 * value (x0 + sum c_i*eps_i + err*eps_err), the result z must satisfy
 *
 *    |f(X, Y) - (z0 + sum_{i old} z_i*eps_i)|  <=  sum_{i new} |z_i| + z.err
 *
 * and f(X, Y) must lie in aa_range(z).
 *
 * The oracle's own error, and how it is kept honest:
 *  - Interval mode: samples are exact. f is evaluated in long double, whose
 *    functions err by a few long double ulps (2^-63 relative); a point is
 *    counted only if f +- tol misses the result, tol = 4..16 long double ulps
 *    of f (or of the magnitudes of the terms for sums: x+y, mix, lincomb).
 *  - Affine mode: products c_i*eps_i are exact in long double (53-bit c_i
 *    times a 3-bit dyadic eps), except for solved points where one product
 *    rounds; the sum of m terms errs by at most e_x = (m+3)*2^-63*sum|terms|.
 *    The same bound, on the result side, widens the allowed range. If
 *    f(X, Y) +- tol misses the allowed range, the oracle is recomputed as the
 *    hull of f over the corners {X-e_x, X, X+e_x} x {Y-e_y, Y, Y+e_y} (x the
 *    third operand), each +- tol, with inputs clamped to the domain, then
 *    widened by the hull's own width (curvature), with the rigorous Lipschitz
 *    enclosure f(X) +- e_x for sin, cos, atan, abs and identities, and with
 *    the whole possible range where the perturbation may cross a pole or a
 *    jump (tan, 1/x, log/invsqrt at 0, mod, atan2's branch cut). A violation
 *    is counted only if that whole hull misses the allowed range; a point
 *    rescued by the hull is reported as a "near miss" (information only).
 *
 * Domains (RenderMan shading language conventions): sqrt x>=0, log x>0,
 * invsqrt x>0, asin/acos [-1,1], pow x>=0 (any x where y is a degenerate
 * integer: then pow is pow_int); samples outside are skipped. 1/x, x/y and
 * pow_int(x, n<0) at x (y) == 0 exactly, pow(0, y<0) and atan2(0, 0) are
 * skipped as well. mod with a divisor range containing 0 is only checked for
 * its AA_UNBOUNDED flag.
 *
 * Usage: test_aa_containment [interval|affine] [op-name]
 * Environment: AAFARM_PROPERTY_CASES (cases per operation and mode, default
 * 100000), AAFARM_PROPERTY_SEED (default 0xaafa2024), AAFARM_PROPERTY_DETAILS
 * (violations printed in full per operation and mode, default 4). The seed is printed;
 * every operation/mode pair derives its own stream from it, so one pair can
 * be rerun alone with the same results.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "test_rng.h"

_Static_assert(LDBL_MANT_DIG >= 64, "the oracle needs an extended long double");

#define PI_L   3.141592653589793238462643383279502884L
#define PI_2_L 1.570796326794896619231321691639751442L
#define PI_D   3.141592653589793
#define PI_2_D 1.5707963267948966
#define LD_ULP 0x1p-63L          /* relative ulp of a 64-bit significand */

#define DEFAULT_CASES 100000L
#define DEFAULT_SEED 0xaafa2024u
#define DEFAULT_DETAILS 4        /* violations printed in full per op and mode */

/* ======================================================================
 * Random numbers: splitmix64 seeding xoshiro256**
 * ====================================================================== */

typedef struct rng {
    uint64_t s[4];
} rng;

static uint64_t splitmix64(uint64_t *x)
{
    return test_rng_next(x);
}

static void rng_seed(rng *r, uint64_t seed)
{
    for (int i = 0; i < 4; i++)
        r->s[i] = splitmix64(&seed);
}

static uint64_t rotl64(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

static uint64_t rng_next(rng *r)
{
    uint64_t *s = r->s;
    uint64_t result = rotl64(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl64(s[3], 45);
    return result;
}

/* uniform in [0, 1) */
static double rng_unit(rng *r)
{
    return (double)(rng_next(r) >> 11) * 0x1p-53;
}

/* uniform integer in [0, n) */
static int rng_below(rng *r, int n)
{
    return (int)(rng_next(r) % (uint64_t)n);
}

static bool rng_chance(rng *r, double p)
{
    return rng_unit(r) < p;
}

static double rng_sign(rng *r)
{
    return (rng_next(r) & 1) ? -1.0 : 1.0;
}

/* a*(1-t) + b*t clamped to [a, b]; never overflows for finite a <= b */
static double lerp(double a, double b, double t)
{
    double v = a * (1.0 - t) + b * t;
    if (v < a)
        v = a;
    if (v > b)
        v = b;
    return v;
}

static double rng_uniform(rng *r, double a, double b)
{
    return lerp(a, b, rng_unit(r));
}

/* 10^u with u uniform in [e_lo, e_hi] */
static double rng_log10(rng *r, double e_lo, double e_hi)
{
    return pow(10.0, e_lo + (e_hi - e_lo) * rng_unit(r));
}

static void sort2(double *a, double *b)
{
    if (*a > *b) {
        double t = *a;
        *a = *b;
        *b = t;
    }
}

static double mid_of(double lo, double hi)
{
    return lo * 0.5 + hi * 0.5;
}

/* ======================================================================
 * The operations
 * ====================================================================== */

enum op_id {
    OP_MAKE, OP_HULL, OP_INPUT, OP_FROM_INTERVAL,
    OP_ADD, OP_SUB, OP_NEG, OP_ADD_S, OP_MUL_S, OP_LINCOMB,
    OP_MUL, OP_DIV, OP_RECIP, OP_SQR, OP_SQRT, OP_INVSQRT, OP_EXP, OP_LOG,
    OP_POW_INT, OP_POW, OP_SIN, OP_COS, OP_TAN, OP_ASIN, OP_ACOS, OP_ATAN,
    OP_ATAN2, OP_ABS, OP_SIGN, OP_MIN, OP_MAX, OP_FLOOR, OP_CEIL, OP_ROUND,
    OP_MOD, OP_STEP, OP_SMOOTHSTEP, OP_CLAMP, OP_MIX, OP_MERGE, OP_LINCOMB3,
    OP_COUNT
};

enum { MODE_IA = 1, MODE_AA = 2 };

typedef struct op_info {
    const char *name;
    int arity;
    unsigned modes;
} op_info;

static const op_info OPS[OP_COUNT] = {
    [OP_MAKE]          = {"make", 1, MODE_IA},
    [OP_HULL]          = {"hull", 2, MODE_IA},
    [OP_INPUT]         = {"input", 1, MODE_AA},
    [OP_FROM_INTERVAL] = {"from_interval", 1, MODE_AA},
    [OP_ADD]           = {"add", 2, MODE_IA | MODE_AA},
    [OP_SUB]           = {"sub", 2, MODE_IA | MODE_AA},
    [OP_NEG]           = {"neg", 1, MODE_IA | MODE_AA},
    [OP_ADD_S]         = {"add_s", 1, MODE_IA | MODE_AA},
    [OP_MUL_S]         = {"mul_s", 1, MODE_IA | MODE_AA},
    [OP_LINCOMB]       = {"lincomb", 2, MODE_AA},
    [OP_LINCOMB3]      = {"lincomb3", 3, MODE_AA},
    [OP_MUL]           = {"mul", 2, MODE_IA | MODE_AA},
    [OP_DIV]           = {"div", 2, MODE_IA | MODE_AA},
    [OP_RECIP]         = {"recip", 1, MODE_IA | MODE_AA},
    [OP_SQR]           = {"sqr", 1, MODE_IA | MODE_AA},
    [OP_SQRT]          = {"sqrt", 1, MODE_IA | MODE_AA},
    [OP_INVSQRT]       = {"invsqrt", 1, MODE_IA | MODE_AA},
    [OP_EXP]           = {"exp", 1, MODE_IA | MODE_AA},
    [OP_LOG]           = {"log", 1, MODE_IA | MODE_AA},
    [OP_POW_INT]       = {"pow_int", 1, MODE_IA | MODE_AA},
    [OP_POW]           = {"pow", 2, MODE_IA | MODE_AA},
    [OP_SIN]           = {"sin", 1, MODE_IA | MODE_AA},
    [OP_COS]           = {"cos", 1, MODE_IA | MODE_AA},
    [OP_TAN]           = {"tan", 1, MODE_IA | MODE_AA},
    [OP_ASIN]          = {"asin", 1, MODE_IA | MODE_AA},
    [OP_ACOS]          = {"acos", 1, MODE_IA | MODE_AA},
    [OP_ATAN]          = {"atan", 1, MODE_IA | MODE_AA},
    [OP_ATAN2]         = {"atan2", 2, MODE_IA | MODE_AA},
    [OP_ABS]           = {"abs", 1, MODE_IA | MODE_AA},
    [OP_SIGN]          = {"sign", 1, MODE_IA | MODE_AA},
    [OP_MIN]           = {"min", 2, MODE_IA | MODE_AA},
    [OP_MAX]           = {"max", 2, MODE_IA | MODE_AA},
    [OP_FLOOR]         = {"floor", 1, MODE_IA | MODE_AA},
    [OP_CEIL]          = {"ceil", 1, MODE_IA | MODE_AA},
    [OP_ROUND]         = {"round", 1, MODE_IA | MODE_AA},
    [OP_MOD]           = {"mod", 2, MODE_IA | MODE_AA},
    [OP_STEP]          = {"step", 2, MODE_IA | MODE_AA},
    [OP_SMOOTHSTEP]    = {"smoothstep", 3, MODE_IA | MODE_AA},
    [OP_CLAMP]         = {"clamp", 3, MODE_IA | MODE_AA},
    [OP_MIX]           = {"mix", 3, MODE_IA | MODE_AA},
    [OP_MERGE]         = {"merge", 2, MODE_IA | MODE_AA},
};

/* One random case: operand target ranges and scalar parameters. */
typedef struct tcase {
    int op;
    double lo[3], hi[3];
    int n;                  /* pow_int exponent; pow: the integer y if y_int */
    bool y_int;             /* pow: y is the degenerate integer n */
    double s;               /* add_s, mul_s */
    double la, lb, lc;      /* lincomb: la*x + lb*y + lc */
} tcase;

/* ======================================================================
 * Generating operand ranges
 * ====================================================================== */

enum { K_MODERATE, K_UNIT, K_TINY_REL, K_TINY_ABS, K_HUGE, K_STRADDLE,
       K_POINT, K_CRITICAL, K_COUNT };
static const int KIND_WEIGHT[K_COUNT] = {20, 6, 10, 7, 10, 10, 7, 30};

static double moderate_bound(int op)
{
    switch (op) {
    case OP_ASIN: case OP_ACOS: return 1.2;
    default: return 10.0;
    }
}

static double rand_scalar(rng *r)
{
    switch (rng_below(r, 10)) {
    case 0: return 0.0;
    case 1: return rng_sign(r);
    case 2: return 0.5 * rng_sign(r);
    case 3: return rng_sign(r) * rng_log10(r, -300, 300);
    case 4: return rng_sign(r) * rng_log10(r, -12, 12);
    default: return rng_uniform(r, -10.0, 10.0);
    }
}

/* An integer exponent for pow_int / integer pow. */
static int rand_exponent(rng *r)
{
    switch (rng_below(r, 8)) {
    case 0: return 0;
    case 1: return rng_chance(r, 0.5) ? 1 : -1;
    case 2: return 2;
    case 3: return (rng_chance(r, 0.5) ? 1 : -1) * (20 + rng_below(r, 45));
    default: return rng_below(r, 20) - 7;
    }
}

/* Offset from a critical point: 0, or scale times 2^-60..2^0. */
static double crit_offset(rng *r, double c)
{
    if (rng_chance(r, 0.12))
        return 0.0;
    if (c == 0.0)
        return rng_log10(r, -310, 0.5);
    return fabs(c) * pow(2.0, -60.0 * rng_unit(r));
}

/* A range near c: straddling it, starting or ending at it, or just beside. */
static void range_near(rng *r, double c, double *lo, double *hi)
{
    double a = crit_offset(r, c), b = crit_offset(r, c);
    if (c != 0.0 && fabs(c) < 1.0) {
        /* also absolute offsets for critical points of magnitude < 1 */
        if (rng_chance(r, 0.5))
            a = a / fabs(c) * 0.5;
        if (rng_chance(r, 0.5))
            b = b / fabs(c) * 0.5;
    }
    switch (rng_below(r, 4)) {
    case 0: *lo = c - a; *hi = c + b; break;
    case 1: *lo = c; *hi = c + b; break;
    case 2: *lo = c - a; *hi = c; break;
    default: {
        double s = rng_sign(r);
        *lo = c + s * a;
        *hi = c + s * (a + b);
        break;
    }
    }
    sort2(lo, hi);
}

/* The delicate place for argument `arg` of the case's operation; earlier
 * arguments of the case are already set. */
static double critical_point(rng *r, const tcase *tc, int arg)
{
    static const double exp_points[] = {0.0, 1.0, 709.782712893384, -708.3964185322641,
                                        -745.1332191019412, -744.44007192138126, 88.72};
    static const double int_points[] = {4503599627370496.0, 4503599627370495.5,
                                        9007199254740992.0, 2251799813685248.5,
                                        2147483647.5, 9.2233720368547758e18};
    double m0 = mid_of(tc->lo[0], tc->hi[0]);
    switch (tc->op) {
    case OP_TAN:
        return (double)(rng_below(r, 15) - 7) * PI_2_D;
    case OP_SIN: case OP_COS:
        if (rng_chance(r, 0.1))
            return (double)(rng_below(r, 2000001) - 1000000) * PI_2_D;
        return (double)(rng_below(r, 19) - 9) * PI_2_D;
    case OP_FLOOR: case OP_CEIL: case OP_ROUND:
        if (rng_chance(r, 0.15))
            return rng_sign(r) * int_points[rng_below(r, 6)];
        return (double)(rng_below(r, 13) - 6) + (rng_chance(r, 0.5) ? 0.5 : 0.0);
    case OP_ASIN: case OP_ACOS:
        return (double)(rng_below(r, 3) - 1);
    case OP_EXP:
        return exp_points[rng_below(r, 7)];
    case OP_LOG: case OP_SQRT:
        return rng_chance(r, 0.7) ? 0.0 : 1.0;
    case OP_POW:
        if (arg == 0)
            return rng_chance(r, 0.7) ? 0.0 : 1.0;
        switch (rng_below(r, 4)) {
        case 0: return 0.0;
        case 1: return 0.5 * rng_sign(r);
        default: return (double)(rng_below(r, 7) - 3);
        }
    case OP_ATAN2:
        if (arg == 0)
            return 0.0;                                   /* y */
        return rng_chance(r, 0.3) ? 0.0 : -rng_uniform(r, 0.01, 10.0);   /* x */
    case OP_STEP:
        if (arg == 0)
            return rng_chance(r, 0.5) ? (double)(rng_below(r, 5) - 2) : rng_uniform(r, -10, 10);
        return m0;
    case OP_SMOOTHSTEP:
        if (arg == 0)
            return rng_uniform(r, -5, 5);
        if (arg == 1)
            return m0;
        return rng_chance(r, 0.5) ? m0 : mid_of(tc->lo[1], tc->hi[1]);
    case OP_MOD:
        if (arg == 1) {                                   /* y, drawn first */
            static const double ys[] = {0.0, 1.0, 0.5, 2.0 * PI_D, 0.1, 3.0, 1e-3};
            return rng_sign(r) * ys[rng_below(r, 7)];
        } else {
            double ym = mid_of(tc->lo[1], tc->hi[1]);
            double k = rng_chance(r, 0.1) ? rng_sign(r) * rng_log10(r, 3, 15)
                                          : (double)(rng_below(r, 13) - 6);
            return nearbyint(k) * ym;
        }
    case OP_MIN: case OP_MAX: case OP_HULL: case OP_MERGE:
        return arg == 0 ? 0.0 : m0;
    case OP_CLAMP:
        if (arg == 0)
            return 0.0;
        if (arg == 1)
            return m0;
        return rng_chance(r, 0.5) ? m0 : mid_of(tc->lo[1], tc->hi[1]);
    case OP_MIX:
        if (arg == 2)
            return (double)rng_below(r, 3) * 0.5;
        return 0.0;
    case OP_ADD:
        return arg == 0 ? 0.0 : -m0;
    case OP_SUB:
        return arg == 0 ? 0.0 : m0;
    default:
        return 0.0;          /* div/recip/log/sign/abs/sqr/pow_int/...: zero */
    }
}

static int pick_kind(rng *r)
{
    int total = 0, k;
    for (k = 0; k < K_COUNT; k++)
        total += KIND_WEIGHT[k];
    int x = rng_below(r, total);
    for (k = 0; k < K_COUNT; k++) {
        if (x < KIND_WEIGHT[k])
            return k;
        x -= KIND_WEIGHT[k];
    }
    return K_MODERATE;
}

static void range_of_kind(rng *r, const tcase *tc, int arg, int kind, double *lo, double *hi)
{
    double c, w, a, b;
    switch (kind) {
    case K_MODERATE:
        w = moderate_bound(tc->op);
        *lo = rng_uniform(r, -w, w);
        *hi = rng_uniform(r, -w, w);
        break;
    case K_UNIT:
        *lo = rng_unit(r);
        *hi = rng_unit(r);
        break;
    case K_TINY_REL:
        c = rng_sign(r) * rng_log10(r, -3, 4);
        w = fabs(c) * rng_log10(r, -15, -11);
        *lo = c - w * rng_unit(r);
        *hi = c + w * rng_unit(r);
        break;
    case K_TINY_ABS:
        c = rng_chance(r, 0.25) ? 0.0 : rng_sign(r) * rng_log10(r, -300, -8);
        w = rng_log10(r, -318, -10);
        *lo = c - w * rng_unit(r);
        *hi = c + w * rng_unit(r);
        break;
    case K_HUGE:
        a = rng_log10(r, 6, 300);
        b = rng_log10(r, 6, 300);
        if (rng_chance(r, 0.05))
            b = DBL_MAX;
        switch (rng_below(r, 3)) {
        case 0: *lo = a; *hi = b; break;
        case 1: *lo = -a; *hi = -b; break;
        default: *lo = -a; *hi = b; break;
        }
        break;
    case K_STRADDLE:
        *lo = -rng_log10(r, -6, 3);
        *hi = rng_log10(r, -6, 3);
        break;
    case K_POINT:
        range_of_kind(r, tc, arg, rng_chance(r, 0.5) ? K_CRITICAL : K_MODERATE, lo, hi);
        if (rng_chance(r, 0.5))
            *hi = *lo;
        else
            *lo = *hi;
        break;
    default:
        range_near(r, critical_point(r, tc, arg), lo, hi);
        break;
    }
    sort2(lo, hi);
}

/* Per-operation adjustments that keep enough ranges inside the domain. */
static void domain_bias(rng *r, const tcase *tc, int arg, double *lo, double *hi)
{
    double t;
    switch (tc->op) {
    case OP_SQRT: case OP_LOG: case OP_INVSQRT:
        if (*hi <= 0.0 && rng_chance(r, 0.7)) {
            t = -*hi;
            *hi = -*lo;
            *lo = t;
        }
        break;
    case OP_POW:
        if (arg == 0 && *hi <= 0.0 && rng_chance(r, 0.7)) {
            t = -*hi;
            *hi = -*lo;
            *lo = t;
        }
        if (arg == 1 && fmax(fabs(*lo), fabs(*hi)) > 1e3 && rng_chance(r, 0.7)) {
            *lo = rng_uniform(r, -10, 10);
            *hi = rng_uniform(r, -10, 10);
            sort2(lo, hi);
        }
        break;
    case OP_ASIN: case OP_ACOS:
        if ((*lo < -1.5 || *hi > 1.5) && rng_chance(r, 0.6)) {
            *lo = rng_uniform(r, -1.1, 1.1);
            *hi = rng_uniform(r, -1.1, 1.1);
            sort2(lo, hi);
        }
        break;
    case OP_DIV: case OP_MOD:
        if (arg == 1 && *lo < 0.0 && *hi > 0.0 && rng_chance(r, 0.6))
            *lo = *hi * 0.5;
        break;
    case OP_RECIP:
        if (*lo < 0.0 && *hi > 0.0 && rng_chance(r, 0.5))
            *lo = *hi * 0.5;
        break;
    default:
        break;
    }
}

static void gen_case(rng *r, int op, tcase *tc)
{
    static const int order_default[3] = {0, 1, 2}, order_mod[3] = {1, 0, 2};
    const int *order = op == OP_MOD ? order_mod : order_default;
    memset(tc, 0, sizeof *tc);
    tc->op = op;
    for (int i = 0; i < OPS[op].arity; i++) {
        int arg = order[i];
        double lo, hi;
        range_of_kind(r, tc, arg, pick_kind(r), &lo, &hi);
        domain_bias(r, tc, arg, &lo, &hi);
        if (!isfinite(lo) || !isfinite(hi) || !(lo <= hi)) {
            lo = -1.0;
            hi = 1.0;
        }
        tc->lo[arg] = lo;
        tc->hi[arg] = hi;
    }
    tc->n = rand_exponent(r);
    tc->s = rand_scalar(r);
    tc->la = rand_scalar(r);
    tc->lb = rand_scalar(r);
    tc->lc = rand_scalar(r);
    if (op == OP_POW && rng_chance(r, 0.15)) {
        tc->y_int = true;
        tc->n = rng_below(r, 16) - 6;
        tc->lo[1] = tc->hi[1] = (double)tc->n;
    }
}

/* ======================================================================
 * The oracle
 * ====================================================================== */

static long double ld_sign(long double x)
{
    return x > 0 ? 1.0L : x < 0 ? -1.0L : 0.0L;
}

static long double ld_mod(long double x, long double y)
{
    long double r = fmodl(x, y);                  /* exact */
    if (r != 0 && ((r < 0) != (y < 0)))
        r += y;
    return r;
}

static long double ld_smoothstep(long double e0, long double e1, long double x)
{
    if (x < e0)
        return 0.0L;
    if (x >= e1)
        return 1.0L;
    long double t = (x - e0) / (e1 - e0);
    return t * t * (3.0L - 2.0L * t);
}

/*
 * f at (a, b, c) in long double: returns how many values it wrote to v (0: the
 * point is outside the domain or f is undefined there; 2 for hull/merge,
 * whose result must hold both operands). tol[] receives the oracle's error
 * bound for each value.
 */
static int oracle(const tcase *tc, long double a, long double b, long double c,
                  long double *v, long double *tol)
{
    long double f, mag;
    a += 0.0L;                   /* no negative zeros: atan2, 1/x */
    b += 0.0L;
    c += 0.0L;
    switch (tc->op) {
    case OP_MAKE: case OP_INPUT: case OP_FROM_INTERVAL:
        v[0] = a;
        tol[0] = 0;
        return 1;
    case OP_HULL: case OP_MERGE:
        v[0] = a;
        v[1] = b;
        tol[0] = tol[1] = 0;
        return 2;
    case OP_NEG:
        v[0] = -a;
        tol[0] = 0;
        return 1;
    case OP_ADD:     f = a + b; mag = fabsl(a) + fabsl(b); break;
    case OP_SUB:     f = a - b; mag = fabsl(a) + fabsl(b); break;
    case OP_ADD_S:   f = a + tc->s; mag = fabsl(a) + fabs(tc->s); break;
    case OP_MUL_S:   f = a * tc->s; mag = fabsl(f); break;
    case OP_LINCOMB:
        f = tc->la * a + tc->lb * b + tc->lc;
        mag = fabsl(tc->la * a) + fabsl(tc->lb * b) + fabs(tc->lc);
        break;
    case OP_LINCOMB3:       /* a row of a transformation: la, lb, s; lc */
        f = tc->la * a + tc->lb * b + tc->s * c + tc->lc;
        mag = fabsl(tc->la * a) + fabsl(tc->lb * b) + fabsl(tc->s * c) + fabs(tc->lc);
        break;
    case OP_MUL:     f = a * b; mag = fabsl(f); break;
    case OP_DIV:
        if (b == 0)
            return 0;
        f = a / b; mag = fabsl(f);
        break;
    case OP_RECIP:
        if (a == 0)
            return 0;
        f = 1.0L / a; mag = fabsl(f);
        break;
    case OP_SQR:     f = a * a; mag = f; break;
    case OP_SQRT:
        if (a < 0)
            return 0;
        f = sqrtl(a); mag = f;
        break;
    case OP_INVSQRT:
        if (a <= 0)
            return 0;
        f = 1.0L / sqrtl(a); mag = f;
        break;
    case OP_EXP:     f = expl(a); mag = f; break;
    case OP_LOG:
        if (a <= 0)
            return 0;
        f = logl(a); mag = fabsl(f);
        break;
    case OP_POW_INT:
        if (a == 0 && tc->n < 0)
            return 0;
        f = powl(a, (long double)tc->n); mag = fabsl(f);
        break;
    case OP_POW:
        if (a < 0 && !tc->y_int)
            return 0;
        if (a == 0 && b < 0)
            return 0;
        f = powl(a, b); mag = fabsl(f);
        break;
    case OP_SIN:     f = sinl(a); mag = fabsl(f); break;
    case OP_COS:     f = cosl(a); mag = fabsl(f); break;
    case OP_TAN:     f = tanl(a); mag = fabsl(f); break;
    case OP_ASIN:
        if (a < -1 || a > 1)
            return 0;
        f = asinl(a); mag = fabsl(f);
        break;
    case OP_ACOS:
        if (a < -1 || a > 1)
            return 0;
        f = acosl(a); mag = fabsl(f);
        break;
    case OP_ATAN:    f = atanl(a); mag = fabsl(f); break;
    case OP_ATAN2:                                 /* atan2(y = a, x = b) */
        if (a == 0 && b == 0)
            return 0;
        f = atan2l(a, b); mag = fabsl(f);
        break;
    case OP_ABS:     f = fabsl(a); mag = 0; break;
    case OP_SIGN:    f = ld_sign(a); mag = 0; break;
    case OP_MIN:     f = fminl(a, b); mag = 0; break;
    case OP_MAX:     f = fmaxl(a, b); mag = 0; break;
    case OP_FLOOR:   f = floorl(a); mag = 0; break;
    case OP_CEIL:    f = ceill(a); mag = 0; break;
    case OP_ROUND:   f = roundl(a); mag = 0; break;
    case OP_MOD:
        if (b == 0)
            return 0;
        f = ld_mod(a, b); mag = fabsl(b);
        break;
    case OP_STEP:    f = b < a ? 0.0L : 1.0L; mag = 0; break;  /* step(edge = a, x = b) */
    case OP_SMOOTHSTEP: f = ld_smoothstep(a, b, c); mag = 4 * fabsl(f); break;
    case OP_CLAMP:   f = fminl(fmaxl(a, b), c); mag = 0; break;
    case OP_MIX:
        f = a * (1.0L - c) + b * c;
        mag = fabsl(a) * (1.0L + fabsl(c)) + fabsl(b * c);
        break;
    default:
        return 0;
    }
    if (isnan(f))
        return 0;
    v[0] = f;
    tol[0] = isinf(f) || isinf(mag) ? 0.0L : 8 * LD_ULP * mag + 8 * LDBL_TRUE_MIN;
    return 1;
}

/* Piecewise-constant classifier of the jumps of discontinuous operations:
 * a jump lies between two points whose keys differ. NAN: not applicable. */
static long double jump_key(int op, long double a, long double b)
{
    switch (op) {
    case OP_FLOOR: return floorl(a);
    case OP_CEIL:  return ceill(a);
    case OP_ROUND: return roundl(a);
    case OP_SIGN:  return ld_sign(a);
    case OP_TAN:   return floorl((a - PI_2_L) / PI_L);
    case OP_STEP:  return b < a ? 0.0L : 1.0L;
    case OP_MOD:   return b == 0 ? NAN : floorl(a / b);
    case OP_ATAN2: return b < 0 ? (a >= 0 ? 1.0L : -1.0L) : 0.0L;  /* side of the cut */
    default:       return NAN;
    }
}

static bool has_jump_key(int op)
{
    return !isnan(jump_key(op, 0.5L, 0.25L));
}

/* ======================================================================
 * Statistics and reporting
 * ====================================================================== */

typedef struct stats {
    long long cases, points, skipped_points, skipped_cases;
    long long violations, near_misses;
    long long flag_missing, flag_spurious, unbounded_missing;
    int details;
} stats;

static stats g_total;
static long g_cases = DEFAULT_CASES;
static uint64_t g_seed = DEFAULT_SEED;
static int g_max_details = DEFAULT_DETAILS;

static void print_case(const tcase *tc)
{
    for (int k = 0; k < OPS[tc->op].arity; k++)
        printf("    arg%d range [%a, %a]  (%.17g .. %.17g)\n", k, tc->lo[k], tc->hi[k],
               tc->lo[k], tc->hi[k]);
    switch (tc->op) {
    case OP_POW_INT: printf("    n = %d\n", tc->n); break;
    case OP_POW: if (tc->y_int) printf("    y is the integer point %d\n", tc->n); break;
    case OP_ADD_S: case OP_MUL_S: printf("    s = %a (%.17g)\n", tc->s, tc->s); break;
    case OP_LINCOMB: printf("    a = %a, b = %a, c = %a\n", tc->la, tc->lb, tc->lc); break;
    case OP_LINCOMB3:
        printf("    m = %a %a %a, c = %a\n", tc->la, tc->lb, tc->s, tc->lc);
        break;
    default: break;
    }
}

static void print_form(const char *name, const aa_form *f)
{
    printf("    %s: x0 = %a, err = %a, n = %u, flags = %u, c = {", name, f->x0, f->err,
           (unsigned)f->n, (unsigned)f->flags);
    for (int i = 0; i < f->n && i < AA_MAX_SYMBOLS; i++)
        printf("%s[%d] %a", i ? ", " : "", i, f->c[i]);
    printf("}\n");
}

static void print_detail_header(stats *st, const char *mode, const tcase *tc, const char *what)
{
    printf("  VIOLATION (%s) %s/%s\n", what, mode, OPS[tc->op].name);
    print_case(tc);
    st->details++;
}

/* ======================================================================
 * Flag requirements, shared by both modes
 * ====================================================================== */

/* An enclosure [lo, hi] of each operand as long doubles (exact in interval
 * mode, the true range of the form in affine mode). */
typedef struct ranges {
    long double lo[3], hi[3];
} ranges;

static long double margin_of(long double lo, long double hi)
{
    long double w = hi - lo;
    return 0.25L * w + 1e-9L * fmaxl(fabsl(lo), fabsl(hi)) + 1e-300L;
}

static bool key_constant(int op, long double lo, long double hi)
{
    return jump_key(op, lo, 0) == jump_key(op, hi, 0);
}

/* True where the operation certainly meets no jump or pole over the operand
 * ranges, widened by a margin: AA_DISCONTINUOUS must then stay clear
 * (operands without flags). */
static bool surely_continuous(const tcase *tc, const ranges *rg)
{
    long double lo[3], hi[3];
    for (int k = 0; k < OPS[tc->op].arity; k++) {
        long double m = margin_of(rg->lo[k], rg->hi[k]);
        lo[k] = rg->lo[k] - m;
        hi[k] = rg->hi[k] + m;
    }
    switch (tc->op) {
    case OP_MAKE: case OP_HULL: case OP_INPUT: case OP_FROM_INTERVAL:
    case OP_ADD: case OP_SUB: case OP_NEG: case OP_ADD_S: case OP_MUL_S:
    case OP_LINCOMB: case OP_MUL: case OP_SQR: case OP_EXP: case OP_SIN:
    case OP_COS: case OP_ATAN: case OP_ABS: case OP_MIN: case OP_MAX:
    case OP_CLAMP: case OP_MIX: case OP_LINCOMB3:
        return true;
    case OP_SQRT: case OP_LOG: case OP_INVSQRT:
        return lo[0] > 0;
    case OP_ASIN: case OP_ACOS:
        return lo[0] > -1 && hi[0] < 1;
    case OP_RECIP:
        return lo[0] > 0 || hi[0] < 0;
    case OP_DIV:
        return lo[1] > 0 || hi[1] < 0;
    case OP_POW_INT:
        return tc->n >= 0 || lo[0] > 0 || hi[0] < 0;
    case OP_POW:
        return lo[0] > 0;
    case OP_TAN: case OP_FLOOR: case OP_CEIL: case OP_ROUND: case OP_SIGN:
        return key_constant(tc->op, lo[0], hi[0]);
    case OP_STEP:
        return hi[0] < lo[1] || hi[1] < lo[0];
    case OP_MOD: {
        if (!(lo[1] > 0 || hi[1] < 0))
            return false;
        long double q[4] = {lo[0] / lo[1], lo[0] / hi[1], hi[0] / lo[1], hi[0] / hi[1]};
        long double qlo = q[0], qhi = q[0];
        for (int i = 1; i < 4; i++) {
            qlo = fminl(qlo, q[i]);
            qhi = fmaxl(qhi, q[i]);
        }
        /* the quotient must stay clear of integers by more than a double
         * computation of it can err, underflow included */
        long double qm = 1e-9L * fmaxl(1.0L, fmaxl(fabsl(qlo), fabsl(qhi))) + 1e-300L;
        return floorl(qlo - qm) == floorl(qhi + qm);
    }
    case OP_ATAN2:
        return lo[1] > 0 || lo[0] > 0 || hi[0] < 0;
    case OP_SMOOTHSTEP:
        return hi[0] < lo[1];
    default:
        return false;   /* merge: always flagged */
    }
}

/* Operations whose divisor (or base) range containing 0 requires AA_UNBOUNDED;
 * returns the argument index, or -1. */
static int pole_argument(const tcase *tc)
{
    switch (tc->op) {
    case OP_DIV: case OP_MOD: return 1;
    case OP_RECIP: return 0;
    case OP_POW_INT: return tc->n < 0 ? 0 : -1;
    default: return -1;
    }
}

/* Tracks keys seen at inner points. */
typedef struct jumps {
    bool any;
    long double kmin, kmax;
} jumps;

static void jumps_add(jumps *j, long double key)
{
    if (isnan(key))
        return;
    if (!j->any) {
        j->any = true;
        j->kmin = j->kmax = key;
    } else {
        j->kmin = fminl(j->kmin, key);
        j->kmax = fmaxl(j->kmax, key);
    }
}

static bool jumps_found(int op, const jumps *j)
{
    if (!j->any)
        return false;
    if (op == OP_ATAN2)
        return j->kmin < 0 && j->kmax > 0;
    return j->kmin != j->kmax;
}

/* Common flag checks; flags_in: OR of the operands' flags. */
static void check_flags(stats *st, const char *mode, const tcase *tc, const ranges *rg,
                        unsigned flags_in, unsigned flags_out, const jumps *jp,
                        bool pole_inside, bool pole_possible)
{
    /* a divisor range holding 0 gives the whole line, flagged AA_UNBOUNDED
     * (required below where 0 is clearly inside); AA_DISCONTINUOUS is not
     * required on top of it, nor where only the operand's outward-rounded
     * range reaches 0 (pole_possible) */
    if (tc->op == OP_MERGE || (!pole_possible && jumps_found(tc->op, jp))) {
        if (!(flags_out & AA_DISCONTINUOUS)) {
            st->flag_missing++;
            if (st->details < g_max_details) {
                print_detail_header(st, mode, tc, "AA_DISCONTINUOUS missing");
                printf("    jump keys at inner points: %Lg .. %Lg, result flags %u\n",
                       jp->kmin, jp->kmax, flags_out);
            }
        }
    } else if (flags_in == 0 && surely_continuous(tc, rg) && (flags_out & AA_DISCONTINUOUS)) {
        st->flag_spurious++;
        if (st->details < g_max_details) {
            print_detail_header(st, mode, tc, "AA_DISCONTINUOUS set without a jump");
            printf("    result flags %u\n", flags_out);
        }
    }
    if (pole_inside && !(flags_out & AA_UNBOUNDED)) {
        st->unbounded_missing++;
        if (st->details < g_max_details) {
            print_detail_header(st, mode, tc, "AA_UNBOUNDED missing (divisor range holds 0)");
            printf("    result flags %u\n", flags_out);
        }
    }
}

/* ======================================================================
 * Checking one sample point
 * ====================================================================== */

static bool hits(long double flo, long double fhi, long double alo, long double ahi)
{
    return fhi >= alo && flo <= ahi;       /* false on NaN */
}

static long double clamp_domain(const tcase *tc, int arg, long double v)
{
    switch (tc->op) {
    case OP_SQRT: case OP_LOG: case OP_INVSQRT:
        return v < 0 ? 0 : v;
    case OP_POW:
        return (arg == 0 && !tc->y_int && v < 0) ? 0 : v;
    case OP_ASIN: case OP_ACOS:
        return v < -1 ? -1 : v > 1 ? 1 : v;
    default:
        return v;
    }
}

/*
 * The hull of output `slot` of f over the box v[k] +- e[k] (see the comment
 * at the top). Returns false when f is nowhere defined there.
 */
static bool oracle_hull(const tcase *tc, const long double *v, const long double *e, int slot,
                        long double *hlo, long double *hhi)
{
    int ar = OPS[tc->op].arity;
    int combos = ar == 1 ? 3 : ar == 2 ? 9 : 27;
    long double lo = INFINITY, hi = -INFINITY, fv[2], ft[2];
    bool any = false;
    for (int m = 0; m < combos; m++) {
        long double p[3] = {0, 0, 0};
        int t = m;
        for (int k = 0; k < ar; k++) {
            p[k] = clamp_domain(tc, k, v[k] + (long double)(t % 3 - 1) * e[k]);
            t /= 3;
        }
        int nv = oracle(tc, p[0], p[1], p[2], fv, ft);
        if (nv > slot) {
            lo = fminl(lo, fv[slot] - ft[slot]);
            hi = fmaxl(hi, fv[slot] + ft[slot]);
            any = true;
        }
    }
    /* unary non-monotone functions: their extremum at 0 */
    if (ar == 1 && v[0] - e[0] <= 0 && v[0] + e[0] >= 0) {
        int nv = oracle(tc, 0.0L, 0.0L, 0.0L, fv, ft);
        if (nv > slot) {
            lo = fminl(lo, fv[slot] - ft[slot]);
            hi = fmaxl(hi, fv[slot] + ft[slot]);
            any = true;
        }
    }
    if (!any)
        return false;
    if (isfinite(lo) && isfinite(hi)) {
        long double w = hi - lo;
        lo -= w;
        hi += w;
    }
    switch (tc->op) {
    case OP_SIN: case OP_COS: case OP_ATAN: case OP_ABS: case OP_NEG:
    case OP_MAKE: case OP_INPUT: case OP_FROM_INTERVAL: case OP_HULL: case OP_MERGE: {
        /* Lipschitz 1 */
        long double f0[2], t0[2];
        if (oracle(tc, v[0], v[1], v[2], f0, t0) > slot) {
            lo = fminl(lo, f0[slot] - t0[slot] - e[slot]);
            hi = fmaxl(hi, f0[slot] + t0[slot] + e[slot]);
        }
        if ((tc->op == OP_SIN || tc->op == OP_COS) && e[0] > 0.01L) {
            lo = -1;
            hi = 1;
        }
        break;
    }
    case OP_TAN:
        if (jump_key(OP_TAN, v[0] - e[0], 0) != jump_key(OP_TAN, v[0] + e[0], 0) || e[0] > 0.1L) {
            lo = -INFINITY;
            hi = INFINITY;
        }
        break;
    case OP_RECIP:
        if (v[0] - e[0] <= 0 && v[0] + e[0] >= 0) {
            lo = -INFINITY;
            hi = INFINITY;
        }
        break;
    case OP_POW_INT:
        if (tc->n < 0 && v[0] - e[0] <= 0 && v[0] + e[0] >= 0) {
            lo = -INFINITY;
            hi = INFINITY;
        }
        break;
    case OP_DIV:
        if (v[1] - e[1] <= 0 && v[1] + e[1] >= 0) {
            lo = -INFINITY;
            hi = INFINITY;
        }
        break;
    case OP_LOG:
        if (v[0] - e[0] <= 0)
            lo = -INFINITY;
        break;
    case OP_INVSQRT:
        if (v[0] - e[0] <= 0)
            hi = INFINITY;
        break;
    case OP_POW:
        if (v[0] - e[0] <= 0 && v[1] - e[1] < 0)
            hi = INFINITY;
        break;
    case OP_MOD: {
        long double k1 = jump_key(OP_MOD, v[0] - e[0], v[1]);
        long double k2 = jump_key(OP_MOD, v[0] + e[0], v[1]);
        long double k3 = jump_key(OP_MOD, v[0], v[1] - e[1]);
        long double k4 = jump_key(OP_MOD, v[0], v[1] + e[1]);
        if (k1 != k2 || k3 != k4 || e[0] >= 0.01L * fabsl(v[1])) {
            long double ymax = fabsl(v[1]) + e[1];
            lo = fminl(lo, v[1] < 0 ? -ymax : 0);
            hi = fmaxl(hi, v[1] < 0 ? 0 : ymax);
        }
        break;
    }
    case OP_ATAN2:
        if (v[1] - e[1] <= 0 && v[0] - e[0] <= 0 && v[0] + e[0] >= 0) {
            lo = -PI_L * (1 + 0x1p-60L);
            hi = PI_L * (1 + 0x1p-60L);
        }
        break;
    default:
        break;
    }
    *hlo = lo;
    *hhi = hi;
    return true;
}

/*
 * Checks f at the operand values v (oracle error bounds e, zero in interval
 * mode) against the allowed range [alo, ahi] and the result's range [rlo, rhi].
 * Returns -1 when the point is outside f's domain, 0 when it passes, and 1 on
 * a violation (fval receives the offending value).
 */
static int check_point(stats *st, const tcase *tc, const long double *v, const long double *e,
                       long double alo, long double ahi, long double rlo, long double rhi,
                       long double *fval, int *fslot)
{
    long double fv[2], ft[2];
    int nv = oracle(tc, v[0], v[1], v[2], fv, ft);
    if (nv == 0)
        return -1;
    for (int s = 0; s < nv; s++) {
        long double flo = fv[s] - ft[s], fhi = fv[s] + ft[s];
        if (hits(flo, fhi, alo, ahi) && hits(flo, fhi, rlo, rhi))
            continue;
        if (e[0] > 0 || e[1] > 0 || e[2] > 0) {
            long double hlo, hhi;
            if (!oracle_hull(tc, v, e, s, &hlo, &hhi))
                continue;
            if (hits(hlo, hhi, alo, ahi) && hits(hlo, hhi, rlo, rhi)) {
                st->near_misses++;
                continue;
            }
        }
        *fval = fv[s];
        *fslot = s;
        return 1;
    }
    return 0;
}

/* ======================================================================
 * Interval mode
 * ====================================================================== */

static ia_interval ia_apply(const tcase *tc, const ia_interval *a)
{
    switch (tc->op) {
    case OP_MAKE:       return ia_make(tc->lo[0], tc->hi[0]);
    case OP_HULL:       return ia_hull(a[0], a[1]);
    case OP_ADD:        return ia_add(a[0], a[1]);
    case OP_SUB:        return ia_sub(a[0], a[1]);
    case OP_NEG:        return ia_neg(a[0]);
    case OP_ADD_S:      return ia_add_s(a[0], tc->s);
    case OP_MUL_S:      return ia_mul_s(a[0], tc->s);
    case OP_MUL:        return ia_mul(a[0], a[1]);
    case OP_DIV:        return ia_div(a[0], a[1]);
    case OP_RECIP:      return ia_recip(a[0]);
    case OP_SQR:        return ia_sqr(a[0]);
    case OP_SQRT:       return ia_sqrt(a[0]);
    case OP_INVSQRT:    return ia_invsqrt(a[0]);
    case OP_EXP:        return ia_exp(a[0]);
    case OP_LOG:        return ia_log(a[0]);
    case OP_POW_INT:    return ia_pow_int(a[0], tc->n);
    case OP_POW:        return ia_pow(a[0], a[1]);
    case OP_SIN:        return ia_sin(a[0]);
    case OP_COS:        return ia_cos(a[0]);
    case OP_TAN:        return ia_tan(a[0]);
    case OP_ASIN:       return ia_asin(a[0]);
    case OP_ACOS:       return ia_acos(a[0]);
    case OP_ATAN:       return ia_atan(a[0]);
    case OP_ATAN2:      return ia_atan2(a[0], a[1]);
    case OP_ABS:        return ia_abs(a[0]);
    case OP_SIGN:       return ia_sign(a[0]);
    case OP_MIN:        return ia_min(a[0], a[1]);
    case OP_MAX:        return ia_max(a[0], a[1]);
    case OP_FLOOR:      return ia_floor(a[0]);
    case OP_CEIL:       return ia_ceil(a[0]);
    case OP_ROUND:      return ia_round(a[0]);
    case OP_MOD:        return ia_mod(a[0], a[1]);
    case OP_STEP:       return ia_step(a[0], a[1]);
    case OP_SMOOTHSTEP: return ia_smoothstep(a[0], a[1], a[2]);
    case OP_CLAMP:      return ia_clamp(a[0], a[1], a[2]);
    case OP_MIX:        return ia_mix(a[0], a[1], a[2]);
    case OP_MERGE:      return ia_merge(a[0], a[1]);
    default:            return ia_entire();
    }
}

/* Delicate points of the operation inside [lo, hi] (the double nearest to
 * each, and its neighbours), at most `max` of them. */
static int delicate_points(const tcase *tc, int arg, double lo, double hi, double *out, int max)
{
    double c[3];
    int nc = 0, n = 0;
    switch (tc->op) {
    case OP_SIN: case OP_COS: case OP_TAN: {
        double k = ceil(lo / PI_2_D);
        if (fabs(k) < 1e9)
            c[nc++] = k * PI_2_D;
        break;
    }
    case OP_FLOOR: case OP_CEIL: case OP_ROUND:
        if (fabs(lo) < 0x1p52) {
            c[nc++] = ceil(lo);
            c[nc++] = floor(lo) + 0.5;
        }
        break;
    case OP_ASIN: case OP_ACOS:
        c[nc++] = -1.0;
        c[nc++] = 1.0;
        break;
    case OP_SIGN: case OP_ABS: case OP_SQR: case OP_RECIP: case OP_POW_INT:
    case OP_LOG: case OP_SQRT: case OP_INVSQRT: case OP_ATAN2: case OP_MUL:
        c[nc++] = 0.0;
        break;
    case OP_DIV:
        if (arg == 1)
            c[nc++] = 0.0;
        break;
    case OP_POW:                    /* x = 0 or 1; y = 0 or 1 */
        c[nc++] = 0.0;
        c[nc++] = 1.0;
        break;
    case OP_MOD:
        if (arg == 0 && tc->lo[1] == tc->hi[1] && tc->lo[1] != 0) {
            double k = ceil(lo / tc->lo[1]);
            if (fabs(k) < 1e15)
                c[nc++] = k * tc->lo[1];
        }
        break;
    default:
        break;
    }
    for (int i = 0; i < nc && n < max; i++) {
        double p[3] = {c[i], nextafter(c[i], -INFINITY), nextafter(c[i], INFINITY)};
        for (int j = 0; j < 3 && n < max; j++)
            if (p[j] >= lo && p[j] <= hi)
                out[n++] = p[j];
    }
    return n;
}

#define MAX_ARG_SAMPLES 16

/* Sample values of one operand range; inner[i] marks points at least 1/8 of
 * the width away from both ends. Returns the count. */
static int ia_arg_samples(rng *r, const tcase *tc, int arg, double lo, double hi,
                          double *s, bool *inner)
{
    int n = 0;
    s[n] = lo; inner[n++] = false;
    s[n] = hi; inner[n++] = false;
    if (lo == hi)
        return n;
    double q1 = lerp(lo, hi, 0.125), q2 = lerp(lo, hi, 0.875);
    bool has_inner = q1 > lo && q2 < hi && q1 <= q2;
    s[n] = q1; inner[n++] = has_inner;
    s[n] = q2; inner[n++] = has_inner;
    for (int i = 0; i < 3; i++) {
        double x = rng_uniform(r, lo, hi);
        s[n] = x;
        inner[n++] = has_inner && x >= q1 && x <= q2;
    }
    /* a few ulps in from the ends */
    double a = lo, b = hi;
    int steps = 1 + rng_below(r, 3);
    for (int i = 0; i < steps; i++) {
        a = nextafter(a, INFINITY);
        b = nextafter(b, -INFINITY);
    }
    if (a <= hi) { s[n] = a; inner[n++] = false; }
    if (b >= lo) { s[n] = b; inner[n++] = false; }
    double d[3];
    int nd = delicate_points(tc, arg, lo, hi, d, 3);
    for (int i = 0; i < nd; i++) {
        s[n] = d[i];
        inner[n++] = has_inner && d[i] >= q1 && d[i] <= q2;
    }
    return n;
}

static void run_case_ia(rng *r, const tcase *tc, stats *st)
{
    int ar = OPS[tc->op].arity;
    ia_interval in[3];
    double s[3][MAX_ARG_SAMPLES];
    bool inner[3][MAX_ARG_SAMPLES];
    int ns[3] = {1, 1, 1};
    ranges rg;

    for (int k = 0; k < ar; k++) {
        in[k] = ia_make(tc->lo[k], tc->hi[k]);
        rg.lo[k] = tc->lo[k];
        rg.hi[k] = tc->hi[k];
        ns[k] = ia_arg_samples(r, tc, k, tc->lo[k], tc->hi[k], s[k], inner[k]);
    }
    for (int k = ar; k < 3; k++) {
        s[k][0] = 0;
        inner[k][0] = true;
    }
    ia_interval z = ia_apply(tc, in);
    unsigned flags_in = 0;
    for (int k = 0; k < ar; k++)
        flags_in |= in[k].flags;
    st->cases++;

    bool skip_values = false, pole_inside = false;
    int pa = pole_argument(tc);
    if (pa >= 0 && tc->lo[pa] <= 0 && tc->hi[pa] >= 0) {
        pole_inside = true;
        if (tc->op == OP_MOD)
            skip_values = true;
    }

    /* the points: unary: every sample; otherwise the corners, the inner
     * corners, and random combinations */
    int idx[40][3];
    int np = 0;
    if (ar == 1) {
        for (int i = 0; i < ns[0]; i++) {
            idx[np][0] = i;
            idx[np][1] = idx[np][2] = 0;
            np++;
        }
    } else {
        int corners = 1 << ar;
        for (int m = 0; m < corners; m++) {
            for (int k = 0; k < 3; k++)
                idx[np][k] = (k < ar && ns[k] > 1) ? ((m >> k) & 1) : 0;
            np++;
        }
        if (ar == 2) {
            for (int m = 0; m < 4; m++) {
                for (int k = 0; k < 3; k++)
                    idx[np][k] = (k < ar && ns[k] > 3) ? 2 + ((m >> k) & 1) : 0;
                np++;
            }
        }
        for (int i = 0; i < 4; i++) {
            for (int k = 0; k < 3; k++)
                idx[np][k] = rng_below(r, ns[k]);
            np++;
        }
    }

    jumps jp = {false, 0, 0};
    bool has_key = has_jump_key(tc->op);
    long double zero_e[3] = {0, 0, 0};
    bool empty = ia_is_empty(z);
    for (int p = 0; p < np; p++) {
        long double v[3];
        bool all_inner = true;
        for (int k = 0; k < 3; k++) {
            v[k] = s[k][idx[p][k]];
            if (k < ar && !inner[k][idx[p][k]])
                all_inner = false;
        }
        if (has_key && all_inner)
            jumps_add(&jp, jump_key(tc->op, v[0], v[1]));
        if (skip_values)
            continue;
        long double fval = 0;
        int slot = 0;
        long double alo = empty ? INFINITY : z.lo, ahi = empty ? -INFINITY : z.hi;
        int res = check_point(st, tc, v, zero_e, alo, ahi, alo, ahi, &fval, &slot);
        if (res < 0) {
            st->skipped_points++;
            continue;
        }
        st->points++;
        if (res > 0) {
            st->violations++;
            if (st->details < g_max_details) {
                print_detail_header(st, "interval", tc, "containment");
                printf("    at (%La, %La, %La): f = %La (%.20Lg)\n", v[0], v[1], v[2], fval, fval);
                printf("    result [%a, %a] flags %u%s\n", z.lo, z.hi, z.flags,
                       empty ? " (empty)" : "");
            }
        }
    }
    check_flags(st, "interval", tc, &rg, flags_in, z.flags, &jp, pole_inside, pole_inside);
}

/* ======================================================================
 * Affine mode
 * ====================================================================== */

static void aa_apply(aa_context *ctx, const tcase *tc, aa_form *z, const aa_form *x,
                     const aa_form *y, const aa_form *w)
{
    switch (tc->op) {
    case OP_INPUT:         aa_input(ctx, z, tc->lo[0], tc->hi[0]); break;
    case OP_FROM_INTERVAL: aa_from_interval(ctx, z, ia_make(tc->lo[0], tc->hi[0])); break;
    case OP_ADD:           aa_add(ctx, z, x, y); break;
    case OP_SUB:           aa_sub(ctx, z, x, y); break;
    case OP_NEG:           aa_neg(ctx, z, x); break;
    case OP_ADD_S:         aa_add_s(ctx, z, x, tc->s); break;
    case OP_MUL_S:         aa_mul_s(ctx, z, x, tc->s); break;
    case OP_LINCOMB:       aa_lincomb(ctx, z, tc->la, x, tc->lb, y, tc->lc); break;
    case OP_LINCOMB3: {
        const double m[3] = {tc->la, tc->lb, tc->s};
        const aa_form in3[3] = {*x, *y, *w};
        aa_lincomb3(ctx, z, m, in3, tc->lc);
        break;
    }
    case OP_MUL:           aa_mul(ctx, z, x, y); break;
    case OP_DIV:           aa_div(ctx, z, x, y); break;
    case OP_RECIP:         aa_recip(ctx, z, x); break;
    case OP_SQR:           aa_sqr(ctx, z, x); break;
    case OP_SQRT:          aa_sqrt(ctx, z, x); break;
    case OP_INVSQRT:       aa_invsqrt(ctx, z, x); break;
    case OP_EXP:           aa_exp(ctx, z, x); break;
    case OP_LOG:           aa_log(ctx, z, x); break;
    case OP_POW_INT:       aa_pow_int(ctx, z, x, tc->n); break;
    case OP_POW:           aa_pow(ctx, z, x, y); break;
    case OP_SIN:           aa_sin(ctx, z, x); break;
    case OP_COS:           aa_cos(ctx, z, x); break;
    case OP_TAN:           aa_tan(ctx, z, x); break;
    case OP_ASIN:          aa_asin(ctx, z, x); break;
    case OP_ACOS:          aa_acos(ctx, z, x); break;
    case OP_ATAN:          aa_atan(ctx, z, x); break;
    case OP_ATAN2:         aa_atan2(ctx, z, x, y); break;
    case OP_ABS:           aa_abs(ctx, z, x); break;
    case OP_SIGN:          aa_sign(ctx, z, x); break;
    case OP_MIN:           aa_min(ctx, z, x, y); break;
    case OP_MAX:           aa_max(ctx, z, x, y); break;
    case OP_FLOOR:         aa_floor(ctx, z, x); break;
    case OP_CEIL:          aa_ceil(ctx, z, x); break;
    case OP_ROUND:         aa_round(ctx, z, x); break;
    case OP_MOD:           aa_mod(ctx, z, x, y); break;
    case OP_STEP:          aa_step(ctx, z, x, y); break;
    case OP_SMOOTHSTEP:    aa_smoothstep(ctx, z, x, y, w); break;
    case OP_CLAMP:         aa_clamp(ctx, z, x, y, w); break;
    case OP_MIX:           aa_mix(ctx, z, x, y, w); break;
    case OP_MERGE:         aa_merge(ctx, z, x, y); break;
    default:               aa_unbounded(z, AA_UNBOUNDED); break;
    }
}

static bool form_finite(const aa_form *f)
{
    if (!isfinite(f->x0) || !isfinite(f->err) || f->n > AA_MAX_SYMBOLS)
        return false;
    for (int i = 0; i < f->n; i++)
        if (!isfinite(f->c[i]))
            return false;
    return true;
}

/*
 * Builds an operand spanning about [lo, hi] from the inputs: mid + sum w_j *
 * in_j over a random subset of the inputs that always holds input 0, plus
 * sometimes a quarter of the radius on a non-affine function of inputs.
 */
static void build_operand(rng *r, aa_context *ctx, const aa_form *in, int nin, double lo,
                          double hi, aa_form *x)
{
    double mid = mid_of(lo, hi), rad = hi * 0.5 - lo * 0.5;
    if (lo == hi || !(rad > 0)) {
        aa_const(x, lo);
        return;
    }
    int use[8], nuse = 0;
    double t[8], tsum = 0;
    use[nuse++] = 0;
    for (int j = 1; j < nin; j++)
        if (rng_chance(r, 0.5))
            use[nuse++] = j;
    for (int j = 0; j < nuse; j++) {
        t[j] = 0.05 + rng_unit(r);
        tsum += t[j];
    }
    bool preop = rng_chance(r, 0.3);
    double share = preop ? 0.75 : 1.0;
    for (int j = 0; j < nuse; j++) {
        double w = rad * share * (t[j] / tsum) * rng_sign(r);
        if (j == 0) {
            switch (rng_below(r, 3)) {
            case 0:
                aa_lincomb(ctx, x, w, &in[use[0]], 0.0, &in[use[0]], mid);
                break;
            case 1:
                aa_mul_s(ctx, x, &in[use[0]], w);
                aa_add_s(ctx, x, x, mid);
                break;
            default:
                aa_lincomb(ctx, x, w, &in[use[0]], 0.0, &in[0], 0.0);
                aa_add_s(ctx, x, x, mid);
                break;
            }
        } else if (rng_chance(r, 0.5)) {
            aa_lincomb(ctx, x, 1.0, x, w, &in[use[j]], 0.0);
        } else {
            aa_form tmp;
            aa_mul_s(ctx, &tmp, &in[use[j]], w);
            aa_add(ctx, x, x, &tmp);
        }
    }
    if (preop) {
        aa_form tf;
        int a = rng_below(r, nin), b = rng_below(r, nin);
        switch (rng_below(r, 3)) {
        case 0: aa_sqr(ctx, &tf, &in[a]); break;
        case 1: aa_mul(ctx, &tf, &in[a], &in[b]); break;
        default: aa_sin(ctx, &tf, &in[a]); break;
        }
        aa_lincomb(ctx, x, 1.0, x, rad * 0.25 * rng_sign(r), &tf, 0.0);
    }
}

/* Value of a form at an assignment, and the bound on its long double error. */
static long double form_value(const aa_form *f, const long double *eps, long double eerr,
                              long double *ebound)
{
    long double s = f->x0, mag = fabsl(s), t;
    int n = f->n;
    for (int i = 0; i < n; i++) {
        t = f->c[i] * eps[i];
        s += t;
        mag += fabsl(t);
    }
    t = f->err * eerr;
    s += t;
    mag += fabsl(t);
    *ebound = (long double)(n + 3) * LD_ULP * mag;
    return s;
}

/* True range of a form: [x0 - R, x0 + R], R = sum |c_i| + err, in long double,
 * shrunk by the long double error so that it is inside the true range. */
static void form_true_range(const aa_form *f, long double *lo, long double *hi)
{
    long double R = f->err;
    for (int i = 0; i < f->n; i++)
        R += fabsl((long double)f->c[i]);
    long double m = (long double)(f->n + 3) * LD_ULP * (fabsl((long double)f->x0) + R);
    *lo = f->x0 - R + m;
    *hi = f->x0 + R - m;
    if (*lo > *hi)
        *lo = *hi = f->x0;
}

/* The range that the result z allows at an assignment: old symbols (< nold)
 * take their values, new ones and the private term count as radius. */
static void allowed_at(const aa_form *z, int nold, const long double *eps, long double *alo,
                       long double *ahi)
{
    long double c = z->x0, mag = fabsl(c), R = z->err, t;
    int n = z->n > AA_MAX_SYMBOLS ? AA_MAX_SYMBOLS : z->n;
    for (int i = 0; i < n; i++) {
        if (i < nold) {
            t = z->c[i] * eps[i];
            c += t;
            mag += fabsl(t);
        } else {
            R += fabsl((long double)z->c[i]);
        }
    }
    if (isinf(R) && !isnan(c)) {
        *alo = -INFINITY;
        *ahi = INFINITY;
        return;
    }
    long double m = (long double)(n + 3) * LD_ULP * (mag + R);
    *alo = c - R - m;
    *ahi = c + R + m;
}

typedef struct assign {
    long double eps[AA_MAX_SYMBOLS];
    long double eerr[3];
    bool inner;
} assign;

static long double grid_value(rng *r)
{
    return (long double)(rng_below(r, 9) - 4) * 0.25L;
}

static void fill_random(rng *r, assign *as, int nold, bool corner)
{
    for (int i = 0; i < nold; i++)
        as->eps[i] = corner ? (long double)rng_sign(r) : grid_value(r);
    for (int k = 0; k < 3; k++)
        as->eerr[k] = corner ? (long double)rng_sign(r) : grid_value(r);
    as->inner = false;
    if (!corner) {
        as->inner = true;
        for (int i = 0; i < nold; i++)
            if (fabsl(as->eps[i]) > 0.75L)
                as->inner = false;
        for (int k = 0; k < 3; k++)
            if (fabsl(as->eerr[k]) > 0.75L)
                as->inner = false;
    }
}

/* The corner where operand f is at its top (sgn = +1) or bottom (-1),
 * scaled by `scale`; symbols f does not use get random signs. */
static void fill_extreme(rng *r, assign *as, int nold, const aa_form *f, int errdim, double sgn,
                         double scale)
{
    for (int i = 0; i < nold; i++) {
        double c = i < f->n ? f->c[i] : 0.0;
        double d = c > 0 ? sgn : c < 0 ? -sgn : rng_sign(r);
        as->eps[i] = (long double)(d * scale);
    }
    for (int k = 0; k < 3; k++)
        as->eerr[k] = (long double)(rng_sign(r) * scale);
    as->eerr[errdim] = (long double)(sgn * scale);
    as->inner = scale <= 0.75;
}

/* An assignment that puts operand f (close to) on the value p: random grid
 * values, then the symbol with the largest coefficient solved for. */
static bool fill_solved(rng *r, assign *as, int nold, const aa_form *f, int errdim, double p)
{
    fill_random(r, as, nold, false);
    int best = -1;
    double bc = 0;
    for (int i = 0; i < nold && i < f->n; i++)
        if (fabs(f->c[i]) > bc) {
            bc = fabs(f->c[i]);
            best = i;
        }
    if (best < 0)
        return false;
    long double eb;
    as->eps[best] = 0;
    long double rest = form_value(f, as->eps, as->eerr[errdim], &eb);
    long double e = ((long double)p - rest) / f->c[best];
    if (!(fabsl(e) <= 1))
        return false;
    as->eps[best] = e;
    as->inner = false;
    return true;
}

static void run_case_aa(rng *r, const tcase *tc, stats *st)
{
    static const int caps[4] = {2, 4, 16, AA_MAX_SYMBOLS};
    int ar = OPS[tc->op].arity;
    bool interval_operand = tc->op == OP_INPUT || tc->op == OP_FROM_INTERVAL;
    aa_context ctx;
    aa_form in[8], arg[3], z;
    int cap = caps[rng_below(r, 4)];
    aa_context_init(&ctx, cap);

    int maxin = cap < 3 ? cap : 3;
    if (cap >= 16 && rng_chance(r, 0.2))
        maxin = 8;
    int nin = 1 + rng_below(r, maxin);
    for (int j = 0; j < nin; j++)
        aa_input(&ctx, &in[j], -1.0, 1.0);

    bool alias_xy = ar == 2 && tc->op != OP_LINCOMB && rng_chance(r, 0.1);
    int errdim[3] = {0, 1, 2};
    memset(arg, 0, sizeof arg);
    if (!interval_operand) {
        for (int k = 0; k < ar; k++)
            build_operand(r, &ctx, in, nin, tc->lo[k], tc->hi[k], &arg[k]);
        if (alias_xy) {
            arg[1] = arg[0];
            errdim[1] = 0;
        }
        for (int k = 0; k < ar; k++) {
            if (!form_finite(&arg[k]) || (arg[k].flags & AA_UNBOUNDED)) {
                st->skipped_cases++;
                return;
            }
        }
    }
    int nold = ctx.used;
    unsigned flags_in = 0;
    for (int k = 0; k < ar; k++)
        flags_in |= arg[k].flags;

    /* the operation, sometimes with the result aliasing the first operand */
    bool alias_z = !interval_operand && rng_chance(r, 0.15);
    const aa_form *px = &arg[0], *py = alias_xy ? &arg[0] : &arg[1], *pw = &arg[2];
    if (alias_z) {
        z = arg[0];
        aa_apply(&ctx, tc, &z, &z, alias_xy ? &z : py, pw);
    } else {
        aa_apply(&ctx, tc, &z, px, py, pw);
    }
    st->cases++;

    ia_interval zr = aa_range(&z);
    bool z_bad = isnan(z.x0) || isnan(z.err) || z.n > AA_MAX_SYMBOLS;
    for (int i = 0; !z_bad && i < z.n; i++)
        if (isnan(z.c[i]))
            z_bad = true;

    ranges rg;
    for (int k = 0; k < ar; k++) {
        if (interval_operand) {
            rg.lo[k] = tc->lo[k];
            rg.hi[k] = tc->hi[k];
        } else {
            /* the true values of an operand lie in its affine range met
             * with its interval hull, i.e. aa_range */
            form_true_range(&arg[k], &rg.lo[k], &rg.hi[k]);
            ia_interval ar_k = aa_range(&arg[k]);
            if ((long double)ar_k.lo > rg.lo[k])
                rg.lo[k] = ar_k.lo;
            if ((long double)ar_k.hi < rg.hi[k])
                rg.hi[k] = ar_k.hi;
        }
    }

    bool skip_values = false, pole_inside = false, pole_possible = false;
    int pa = pole_argument(tc);
    if (pa >= 0) {
        ia_interval pr = aa_range(&arg[pa]);
        if (rg.lo[pa] <= 0 && rg.hi[pa] >= 0)
            pole_inside = true;
        pole_possible = pole_inside || (pr.lo <= 0 && pr.hi >= 0);
        if (tc->op == OP_MOD && pole_possible)
            skip_values = true;
    }

    /* No NaN may appear in a result. (aa_range(z) is the affine range met
     * with the form's interval hull, so it may be narrower than the affine
     * form's full extent: what it must contain is every true value, which
     * check_point verifies at every sample below.) */
    if (z_bad) {
        st->violations++;
        if (st->details < g_max_details) {
            print_detail_header(st, "affine", tc, "NaN in result");
            print_form("z", &z);
        }
        return;
    }
    /* interval operand (input, from_interval): interval-style samples */
    double isamp[MAX_ARG_SAMPLES];
    bool iinner[MAX_ARG_SAMPLES];
    int nis = 0;
    if (interval_operand)
        nis = ia_arg_samples(r, tc, 0, tc->lo[0], tc->hi[0], isamp, iinner);

    /* the assignments */
    int npts = interval_operand ? nis : 1 + 4 * ar + 2 + 3 + (ar == 1 ? 1 : 0);
    jumps jp = {false, 0, 0};
    bool has_key = has_jump_key(tc->op);
    for (int p = 0; p < npts; p++) {
        assign as;
        long double v[3] = {0, 0, 0}, e[3] = {0, 0, 0};
        if (interval_operand) {
            fill_random(r, &as, nold, rng_chance(r, 0.5));
            v[0] = isamp[p];
        } else {
            if (p == 0) {
                fill_random(r, &as, nold, false);
                for (int i = 0; i < nold; i++)
                    as.eps[i] = 0;
                for (int k = 0; k < 3; k++)
                    as.eerr[k] = 0;
                as.inner = true;
            } else if (p <= 4 * ar) {
                int q = p - 1, k = q / 4, kind = q % 4;
                fill_extreme(r, &as, nold, &arg[k], errdim[k], (kind & 1) ? -1.0 : 1.0,
                             (kind & 2) ? 0.75 : 1.0);
            } else if (p <= 4 * ar + 2) {
                fill_random(r, &as, nold, true);
            } else if (p <= 4 * ar + 5) {
                fill_random(r, &as, nold, false);
            } else {
                double d[3];
                int nd = delicate_points(tc, 0, (double)rg.lo[0], (double)rg.hi[0], d, 3);
                if (nd == 0 || !fill_solved(r, &as, nold, &arg[0], errdim[0], d[rng_below(r, nd)]))
                    fill_random(r, &as, nold, false);
            }
            bool possible = true;
            for (int k = 0; k < ar; k++) {
                v[k] = form_value(&arg[k], as.eps, as.eerr[errdim[k]], &e[k]);
                /* an assignment that puts an operand outside its interval
                 * hull describes no true value: nothing to check there */
                ia_interval ar_k = aa_range(&arg[k]);
                if (v[k] + e[k] < (long double)ar_k.lo || v[k] - e[k] > (long double)ar_k.hi)
                    possible = false;
            }
            if (!possible) {
                st->skipped_points++;
                continue;
            }
        }
        if (has_key && as.inner) {
            /* a key only counts where the oracle's error cannot flip it */
            long double k1 = jump_key(tc->op, v[0] - e[0], v[1] - e[1]);
            long double k2 = jump_key(tc->op, v[0] + e[0], v[1] + e[1]);
            long double k3 = jump_key(tc->op, v[0] - e[0], v[1] + e[1]);
            long double k4 = jump_key(tc->op, v[0] + e[0], v[1] - e[1]);
            if (k1 == k2 && k1 == k3 && k1 == k4)
                jumps_add(&jp, k1);
        }
        if (skip_values)
            continue;
        long double alo, ahi, fval = 0;
        int slot = 0;
        allowed_at(&z, nold, as.eps, &alo, &ahi);
        int res = check_point(st, tc, v, e, alo, ahi, zr.lo, zr.hi, &fval, &slot);
        if (res < 0) {
            st->skipped_points++;
            continue;
        }
        st->points++;
        if (res > 0) {
            st->violations++;
            if (st->details < g_max_details) {
                print_detail_header(st, "affine", tc, "containment");
                printf("    context capacity %d, %d inputs, %d symbols before the op%s%s\n", cap,
                       nin, nold, alias_xy ? ", y is x" : "", alias_z ? ", z aliases x" : "");
                for (int k = 0; k < ar && !interval_operand; k++) {
                    char name[16];
                    snprintf(name, sizeof name, "arg%d", k);
                    print_form(name, &arg[k]);
                }
                print_form("z", &z);
                printf("    eps = {");
                for (int i = 0; i < nold; i++)
                    printf("%s%Lg", i ? ", " : "", as.eps[i]);
                printf("}, eps_err = {%Lg, %Lg, %Lg}\n", as.eerr[0], as.eerr[1], as.eerr[2]);
                printf("    operand values %La, %La, %La (+- %Lg, %Lg, %Lg)\n", v[0], v[1], v[2],
                       e[0], e[1], e[2]);
                printf("    f%s = %La (%.20Lg)\n", slot ? " (2nd value)" : "", fval, fval);
                printf("    allowed [%La, %La], aa_range(z) = [%a, %a]\n", alo, ahi, zr.lo, zr.hi);
            }
        }
    }
    check_flags(st, "affine", tc, &rg, flags_in, z.flags, &jp, pole_inside, pole_possible);
}

/* ======================================================================
 * Driver
 * ====================================================================== */

typedef struct job {
    int op;
    int mode;
    char name[40];
} job;

static stats run_op(int op, int mode)
{
    stats st;
    memset(&st, 0, sizeof st);
    rng r;
    rng_seed(&r, g_seed ^ ((uint64_t)(op + 1) * 0x9e3779b97f4a7c15u) ^ ((uint64_t)mode << 56));
    for (long i = 0; i < g_cases; i++) {
        tcase tc;
        gen_case(&r, op, &tc);
        if (mode == MODE_IA)
            run_case_ia(&r, &tc, &st);
        else
            run_case_aa(&r, &tc, &st);
    }
    return st;
}

static void test_op(void **state)
{
    const job *j = *state;
    stats st = run_op(j->op, j->mode);
    printf("%-8s %-14s cases %7lld  points %8lld  skipped %7lld  violations %lld  "
           "flags: missing %lld spurious %lld unbounded-missing %lld  (near misses %lld%s)\n",
           j->mode == MODE_IA ? "interval" : "affine", OPS[j->op].name, st.cases, st.points,
           st.skipped_points, st.violations, st.flag_missing, st.flag_spurious,
           st.unbounded_missing, st.near_misses,
           st.skipped_cases ? ", some cases skipped: operands not finite" : "");
    fflush(stdout);
    g_total.cases += st.cases;
    g_total.points += st.points;
    g_total.violations += st.violations;
    g_total.flag_missing += st.flag_missing;
    g_total.flag_spurious += st.flag_spurious;
    g_total.unbounded_missing += st.unbounded_missing;
    assert_true(st.cases >= g_cases * 99 / 100);
    assert_int_equal(st.violations, 0);
    assert_int_equal(st.flag_missing, 0);
    assert_int_equal(st.flag_spurious, 0);
    assert_int_equal(st.unbounded_missing, 0);
}

static int print_summary(void **state)
{
    (void)state;
    printf("aa containment: %lld cases, %lld points, %lld violations "
           "(flags: %lld missing, %lld spurious, %lld unbounded missing)\n",
           g_total.cases, g_total.points, g_total.violations, g_total.flag_missing,
           g_total.flag_spurious, g_total.unbounded_missing);
    return 0;
}

int main(int argc, char **argv)
{
    const char *mode_filter = NULL, *op_filter = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "interval") == 0 || strcmp(argv[i], "affine") == 0)
            mode_filter = argv[i];
        else
            op_filter = argv[i];
    }
    const char *env = getenv("AAFARM_PROPERTY_CASES");
    if (env && *env) {
        long n = strtol(env, NULL, 10);
        if (n > 0)
            g_cases = n;
    }
    env = getenv("AAFARM_PROPERTY_DETAILS");
    if (env && *env)
        g_max_details = atoi(env);
    env = getenv("AAFARM_PROPERTY_SEED");
    if (env && *env)
        g_seed = strtoull(env, NULL, 0);
    printf("aa containment: seed 0x%" PRIx64 ", %ld cases per operation and mode "
           "(AAFARM_PROPERTY_SEED, AAFARM_PROPERTY_CASES)\n", g_seed, g_cases);

    static job jobs[2 * OP_COUNT];
    static struct CMUnitTest tests[2 * OP_COUNT];
    int nt = 0;
    for (int mode = MODE_IA; mode <= MODE_AA; mode++) {
        if (mode_filter && strcmp(mode_filter, mode == MODE_IA ? "interval" : "affine") != 0)
            continue;
        for (int op = 0; op < OP_COUNT; op++) {
            if (!(OPS[op].modes & (unsigned)mode))
                continue;
            if (op_filter && strcmp(op_filter, OPS[op].name) != 0)
                continue;
            job *j = &jobs[nt];
            j->op = op;
            j->mode = mode;
            snprintf(j->name, sizeof j->name, "%s/%s", mode == MODE_IA ? "interval" : "affine",
                     OPS[op].name);
            tests[nt].name = j->name;
            tests[nt].test_func = test_op;
            tests[nt].setup_func = NULL;
            tests[nt].teardown_func = NULL;
            tests[nt].initial_state = j;
            nt++;
        }
    }
    if (nt == 0) {
        fprintf(stderr, "no operation matches the filter\n");
        return 2;
    }
    return _cmocka_run_group_tests("aa_containment", tests, (size_t)nt, NULL, print_summary);
}

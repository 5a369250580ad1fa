/*
 * tests/aa/test_aa_fastpath.c: the fast paths of affine.c and affine.h
 * (issue 24) give bit for bit what the general code gives, on many random
 * operands: constants, forms of 1..16 symbols with zero, tiny, subnormal,
 * huge and negative-zero coefficients, private errors, narrowed hulls,
 * flags, unbounded forms; factors +-1, powers of two, 0, -0, ordinary,
 * tiny, huge and non-finite. Forms are compared field by field as bits
 * (x0, err, lo, hi, n, flags and the coefficients below n), so a -0.0 for
 * a 0.0 is a difference.
 *
 *   aa_add, aa_sub             = aa_lincomb(1, x, +-1, y, 0)
 *   aa_neg, aa_add_s, aa_mul_s = aa_lincomb(-1 | 1 | s, x, 0, NULL, 0 | s | 0)
 *   aa_mul(constant, form)     = aa_lincomb(k, form, 0, NULL, 0), flags joined
 *   aa_apply_linear(x, a, c, 0, hull) = aa_lincomb(a, x, 0, NULL, c) with
 *                              that hull (when bounded)
 *   the same with z aliasing an operand (x, or y of add and sub)
 *   aa_exact_difference        when it answers, aa_range(aa_sub(x, y)) is
 *                              [d, d]; it answers for most pairs of constants
 *   aa_is_exact_const          aa_range(x) is [x0, x0]
 *   aa_smoothstep(e0, e1, x)   of three points = their interval smoothstep
 *                              (ia_smoothstep on a private error)
 *   aa_clamp(x, lo, hi)        = aa_min(aa_max(x, lo), hi) (bounded) with the same
 *                              symbols taken, also with z aliasing x: x
 *                              between lo and hi (its copy), below, above,
 *                              across either end, constants and forms
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "aa/affine.h"
#include "aa/affine_internal.h"
#include "test_rng.h"

enum { CASES = 200000 };

/* ---- a fixed-seed generator (test_rng.h) ---- */

static uint64_t g_rng = 0x24fa57u;

static int rng_int(int n) { return test_rng_int(&g_rng, n); }

static double rng_unit(void) { return test_rng_unit(&g_rng); }

/* a number of every kind the arithmetic cares about */
static double rng_value(void)
{
    double s = rng_int(2) ? -1.0 : 1.0;
    switch (rng_int(12)) {
    case 0: return s * 0.0;
    case 1: return s;
    case 2: return s * ldexp(1.0, rng_int(40) - 20);             /* powers of two */
    case 3: return s * (double)rng_int(20);                       /* counters */
    case 4: return s * ldexp(rng_unit(), -1030 - rng_int(20));    /* subnormal */
    case 5: return s * ldexp(1.0 + rng_unit(), 1000 + rng_int(23)); /* huge */
    case 6: return s * ldexp(1.0 + rng_unit(), -1022 + rng_int(4)); /* near underflow */
    default: return s * ldexp(rng_unit(), rng_int(20) - 10);
    }
}

/* a factor: the classes lincomb tells apart, and a few non-finite ones */
static double rng_factor(void)
{
    switch (rng_int(16)) {
    case 0: return INFINITY;
    case 1: return NAN;
    default: return rng_value();
    }
}

/* a random form: a constant (as aa_const makes it), or x0 + symbols + err
 * with a hull around its affine range (sometimes narrowed), or unbounded */
static void rng_form(aa_form *z)
{
    int kind = rng_int(10);
    if (kind == 0) {
        aa_unbounded(z, rng_int(2) ? AA_DISCONTINUOUS : 0);
        return;
    }
    aa_const(z, rng_value());
    if (kind <= 3)
        return;
    int n = kind == 4 ? 0 : 1 + rng_int(AA_MAX_SYMBOLS);
    for (int i = 0; i < n; i++)
        z->c[i] = rng_int(4) == 0 ? 0.0 : rng_value();
    z->n = (unsigned short)n;
    z->err = rng_int(3) == 0 ? 0.0 : fabs(rng_value());
    double r = aa_radius(z);
    if (isfinite(r)) {
        z->lo = z->x0 - r * (1.0 + 0x1p-40);
        z->hi = z->x0 + r * (1.0 + 0x1p-40);
        if (rng_int(4) == 0)
            z->lo = z->lo + 0.25 * (z->hi - z->lo);     /* a narrower hull */
    } else {
        aa_unbounded(z, 0);
    }
    if (rng_int(5) == 0)
        z->flags |= AA_DISCONTINUOUS;
}

static bool bits_equal(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

static bool same_form(const aa_form *a, const aa_form *b)
{
    if (!bits_equal(a->x0, b->x0) || !bits_equal(a->err, b->err) || !bits_equal(a->lo, b->lo) ||
        !bits_equal(a->hi, b->hi) || a->n != b->n || a->flags != b->flags)
        return false;
    for (int i = 0; i < a->n; i++)
        if (!bits_equal(a->c[i], b->c[i]))
            return false;
    return true;
}

static long report(const char *what, long bad, const aa_form *fast, const aa_form *ref)
{
    if (bad == 1)
        printf("%s: first difference: fast x0 %a err %a [%a, %a] n %d flags %d / general x0 %a "
               "err %a [%a, %a] n %d flags %d\n", what, fast->x0, fast->err, fast->lo, fast->hi,
               fast->n, fast->flags, ref->x0, ref->err, ref->lo, ref->hi, ref->n, ref->flags);
    return bad;
}

/* ---- the specialised linear combinations ---- */

enum { OP_ADD, OP_SUB, OP_NEG, OP_ADD_S, OP_MUL_S, OP_MUL_K, OP_APPLY, OP__COUNT };
static const char *const op_name[OP__COUNT] = {
    "aa_add", "aa_sub", "aa_neg", "aa_add_s", "aa_mul_s", "aa_mul(constant, form)",
    "aa_apply_linear"
};

/* the fast path into *z (aliasing x when alias is 1, y when 2) and the
 * general one into *r */
static void run_op(aa_context *ctx, int op, const aa_form *x, const aa_form *y, double s,
                   int alias, aa_form *z, aa_form *r)
{
    aa_form xs = *x, ys = *y;
    aa_form *dst = alias == 1 ? &xs : alias == 2 ? &ys : z;
    switch (op) {
    case OP_ADD:
        aa_add(ctx, dst, &xs, &ys);
        aa_lincomb(ctx, r, 1.0, x, 1.0, y, 0.0);
        break;
    case OP_SUB:
        aa_sub(ctx, dst, &xs, &ys);
        aa_lincomb(ctx, r, 1.0, x, -1.0, y, 0.0);
        break;
    case OP_APPLY: {                 /* a = s, c = y's centre, the hull [-1, 2] */
        ia_interval hull = ia_make(-1.0, 2.0);
        aa_apply_linear(ctx, dst, &xs, s, y->x0, 0.0, hull, 0);
        aa_lincomb(ctx, r, s, x, 0.0, NULL, y->x0);
        if (!(r->flags & AA_UNBOUNDED)) {
            r->lo = hull.lo;
            r->hi = hull.hi;
        }
        break;
    }
    case OP_NEG:
        aa_neg(ctx, dst, &xs);
        aa_lincomb(ctx, r, -1.0, x, 0.0, NULL, 0.0);
        break;
    case OP_ADD_S:
        aa_add_s(ctx, dst, &xs, s);
        aa_lincomb(ctx, r, 1.0, x, 0.0, NULL, s);
        break;
    case OP_MUL_S:                   /* s = 0 is aa_mul_s's own case */
        aa_mul_s(ctx, dst, &xs, s);
        aa_lincomb(ctx, r, s, x, 0.0, NULL, 0.0);
        break;
    default: {                       /* a constant k = s times the form x */
        aa_form k;
        aa_const(&k, s);
        aa_mul(ctx, dst, &k, &xs);
        aa_lincomb(ctx, r, s, x, 0.0, NULL, 0.0);
        r->flags |= (unsigned short)(k.flags | x->flags);
        break;
    }
    }
    if (alias)
        *z = *dst;
}

static void test_lincomb_shapes_bitwise(void **state)
{
    (void)state;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    long bad[OP__COUNT] = { 0 }, runs[OP__COUNT] = { 0 };
    for (int t = 0; t < CASES; t++) {
        aa_form x, y, z, r;
        rng_form(&x);
        rng_form(&y);
        int op = rng_int(OP__COUNT);
        double s = rng_factor();
        if (op == OP_MUL_S && s == 0.0)
            s = 0.5;
        if (op == OP_MUL_K && (s == 0.0 || !isfinite(s)))
            s = 3.0;                     /* aa_const(0 or inf) is not this path */
        int alias = rng_int(3) == 0 ? 1 + ((op == OP_ADD || op == OP_SUB) && rng_int(2)) : 0;
        run_op(&ctx, op, &x, &y, s, alias, &z, &r);
        runs[op]++;
        if (!same_form(&z, &r))
            report(op_name[op], ++bad[op], &z, &r);
    }
    long total = 0;
    for (int op = 0; op < OP__COUNT; op++) {
        printf("%-24s %6ld cases, %ld differ from aa_lincomb\n", op_name[op], runs[op], bad[op]);
        assert_true(runs[op] > CASES / (2 * OP__COUNT));
        total += bad[op];
    }
    assert_int_equal(total, 0);
}

/* ---- comparisons of constants ---- */

static void test_exact_difference(void **state)
{
    (void)state;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    long answered = 0, bad = 0, consts = 0;
    for (int t = 0; t < CASES; t++) {
        aa_form x, y, d;
        if (rng_int(2)) {                /* mostly constants, some near misses */
            aa_const(&x, rng_value());
            aa_const(&y, rng_int(4) == 0 ? x.x0 : rng_value());
            if (rng_int(8) == 0)
                x.hi = nextafter(x.hi, INFINITY);
            if (rng_int(8) == 0)
                y.n = 1, y.c[0] = 0.0;
        } else {
            rng_form(&x);
            rng_form(&y);
        }
        double e;
        if (aa_exact_difference(&x, &y, &e)) {
            answered++;
            aa_sub(&ctx, &d, &x, &y);
            ia_interval r = aa_range(&d);
            if ((d.flags & AA_UNBOUNDED) || !(r.lo == e && r.hi == e)) {
                if (bad++ == 0)
                    printf("x0 %a - y0 %a: fast %a, general [%a, %a]\n", x.x0, y.x0, e,
                           r.lo, r.hi);
            }
        }
        if (aa_is_exact_const(&x)) {
            consts++;
            ia_interval r = aa_range(&x);
            if (!(r.lo == x.x0 && r.hi == x.x0)) {
                if (bad++ == 0)
                    printf("constant %a: range [%a, %a]\n", x.x0, r.lo, r.hi);
            }
        }
    }
    printf("aa_exact_difference answered %ld of %d pairs, %ld exact constants, %ld differ\n",
           answered, CASES, consts, bad);
    assert_true(answered > CASES / 8);
    assert_true(consts > CASES / 4);
    assert_int_equal(bad, 0);
}

/* ---- clamp: max then min, each range once ---- */

/* x: a random form, or one of 1..8 symbols of a small radius around a
 * point of [-1.5, 1.5], so that it often lies between -1 and 1, across
 * one of them, or outside (a normalize's clamp) */
static void clamp_operand(aa_form *x)
{
    if (rng_int(3) == 0) {
        rng_form(x);
        return;
    }
    aa_const(x, 3.0 * rng_unit() - 1.5);
    int n = rng_int(4) == 0 ? 0 : 1 + rng_int(8);
    double r = ldexp(rng_unit(), -rng_int(12));
    for (int i = 0; i < n; i++)
        x->c[i] = rng_int(4) == 0 ? 0.0 : r * (rng_unit() - 0.5) / (n + 1);
    x->n = (unsigned short)n;
    x->err = rng_int(2) ? 0.0 : r * rng_unit() / (n + 1);
    double rad = aa_radius(x);
    x->lo = x->x0 - rad * (1.0 + 0x1p-40);
    x->hi = x->x0 + rad * (1.0 + 0x1p-40);
    if (rng_int(5) == 0)
        x->flags |= AA_DISCONTINUOUS;
}

static void test_clamp_is_max_then_min(void **state)
{
    (void)state;
    long bad = 0, between = 0, across = 0, outside = 0;
    for (int t = 0; t < CASES; t++) {
        aa_form x, lo, hi, z, m, r;
        clamp_operand(&x);
        if (rng_int(4) == 0) {
            clamp_operand(&lo);
            clamp_operand(&hi);
        } else {
            aa_const(&lo, -1.0);
            aa_const(&hi, 1.0);
            if (rng_int(6) == 0)
                lo.flags |= AA_DISCONTINUOUS;
        }
        if ((x.flags | lo.flags | hi.flags) & AA_UNBOUNDED)
            continue;                    /* clamped as intervals, not max then min */
        int used = rng_int(AA_DEFAULT_CAPACITY + 1);
        aa_context a, b;
        aa_context_init(&a, AA_DEFAULT_CAPACITY);
        aa_context_init(&b, AA_DEFAULT_CAPACITY);
        a.used = b.used = used;
        bool alias = rng_int(3) == 0;
        z = x;
        aa_clamp(&a, alias ? &z : &m, &z, &lo, &hi);
        if (!alias)
            z = m;
        aa_max(&b, &m, &x, &lo);
        aa_min(&b, &r, &m, &hi);
        ia_interval rx = aa_range(&x), rl = aa_range(&lo), rh = aa_range(&hi);
        if (rl.hi <= rx.lo && rx.hi <= rh.lo)
            between++;
        else if (rx.hi <= rl.lo || rh.hi <= rx.lo)
            outside++;
        else
            across++;
        if (!same_form(&z, &r) || a.used != b.used || a.folded != b.folded)
            report("aa_clamp", ++bad, &z, &r);
    }
    printf("aa_clamp: %ld cases between, %ld across an end, %ld outside; %ld differ from "
           "aa_min(aa_max(x, lo), hi)\n", between, across, outside, bad);
    assert_true(between > CASES / 10 && across > CASES / 20 && outside > CASES / 20);
    assert_int_equal(bad, 0);
}

/* smoothstep of three points: what the interval path gives (aa_smoothstep
 * of constants is their interval smoothstep on a private error), on flat
 * sides (0 or 1: the fast path), across the ramp, at its ends, with
 * e1 <= e0 and with flags; points that carry symbols with zero
 * coefficients are exactly 0 or 1 on a flat side */
static void test_smoothstep_of_points(void **state)
{
    (void)state;
    long bad = 0, flat = 0, ramp = 0;
    for (int t = 0; t < CASES; t++) {
        double a = rng_value(), b = rng_int(8) == 0 ? rng_value() : a + fabs(rng_value()),
               x = rng_int(4) == 0 ? (rng_int(2) ? a : b) : rng_value();
        if (rng_int(3) == 0) x = a + (b - a) * (2.0 * rng_unit() - 0.5);
        aa_form e0, e1, xf, z, ref;
        aa_const(&e0, a);
        aa_const(&e1, b);
        aa_const(&xf, x);
        if (rng_int(5) == 0) xf.flags |= AA_DISCONTINUOUS;
        if (rng_int(7) == 0) e1.flags |= AA_DISCONTINUOUS;
        aa_context ctx, none;
        aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
        aa_context_init(&none, 0);
        aa_smoothstep(&ctx, &z, &e0, &e1, &xf);
        ia_interval r = ia_smoothstep(aa_range(&e0), aa_range(&e1), aa_range(&xf));
        aa_set_interval(&none, &ref, r, r.flags);
        if (r.lo == r.hi && (r.lo == 0.0 || r.lo == 1.0)) flat++;
        else ramp++;
        if (!same_form(&z, &ref) || ctx.used != 0)
            report("aa_smoothstep of points", ++bad, &z, &ref);
        /* the same points with zero-coefficient symbols */
        if (a < b && (x < a || x >= b) && isfinite(x)) {
            xf.n = 2;
            xf.c[0] = xf.c[1] = 0.0;
            aa_smoothstep(&ctx, &z, &e0, &e1, &xf);
            if (!(z.x0 == (x < a ? 0.0 : 1.0) && z.err == 0.0 && aa_is_point(&z)))
                report("aa_smoothstep of points with symbols", ++bad, &z, &ref);
        }
    }
    printf("aa_smoothstep of points: %ld flat, %ld on the ramp (or degenerate); %ld differ\n",
           flat, ramp, bad);
    assert_true(flat > CASES / 4 && ramp > CASES / 10);
    assert_int_equal(bad, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lincomb_shapes_bitwise),
        cmocka_unit_test(test_exact_difference),
        cmocka_unit_test(test_clamp_is_max_then_min),
        cmocka_unit_test(test_smoothstep_of_points),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

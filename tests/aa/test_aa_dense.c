/*
 * tests/aa/test_aa_dense.c: the dense fixed-width forms (common/aa/dense.h)
 * contain the exact result. Random operands (coefficients and errors of
 * every kind: zero, ordinary, powers of two, tiny, subnormal, near
 * underflow, huge), random symbol assignments (the corners and random
 * points of [-1, 1], the operands' private error symbols included); at
 * each, a long double oracle evaluates the operands and the exact result,
 * which must lie within the result form at the same point: |f - (z0 +
 * sum zi ei)| <= err (+ |zk| for a fresh symbol k of aa_dense_mul), and
 * within aa_dense_range(z). The oracle's own rounding (2^-64 relative) is
 * allowed for, 2^-60 of the magnitudes, far below the bounds under test
 * (2^-53): dropping a rounding term of dense.c makes this test fail.
 * Also: x - x of a form without error is exactly 0, constants stay exact,
 * conversions to and from aa_form keep the values.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "aa/dense.h"
#include "test_rng.h"

enum { CASES = 60000, POINTS = 12 };

static uint64_t g_rng = 0x5eedd15eu;

static int rng_int(int n) { return test_rng_int(&g_rng, n); }
static double rng_unit(void) { return test_rng_unit(&g_rng); }

/* a number of every kind the bounds care about; `scale` keeps most of one
 * case's numbers near one magnitude, so that sums cancel and round */
static double rng_value(int scale)
{
    double s = rng_int(2) ? -1.0 : 1.0;
    switch (rng_int(14)) {
    case 0: return 0.0;
    case 1: return s * ldexp(1.0, scale + rng_int(8) - 4);
    case 2: return s * ldexp(rng_unit(), -1030 - rng_int(20));      /* subnormal */
    case 3: return s * ldexp(1.0 + rng_unit(), -1022 + rng_int(4)); /* near underflow */
    case 4: return s * ldexp(1.0 + rng_unit(), 990 + rng_int(20));  /* huge */
    default: return s * ldexp(1.0 + rng_unit(), scale + rng_int(6) - 3);
    }
}

/* a form over the symbols 0..used-1 */
static void rng_dense(aa_dense *z, int used, int scale)
{
    if (rng_int(8) == 0) {
        aa_dense_const(z, rng_value(scale));
        return;
    }
    z->x0 = rng_value(scale);
    for (int i = 0; i < AA_DENSE_W; i++)
        z->c[i] = i < used && rng_int(5) ? rng_value(scale - rng_int(10)) : 0.0;
    z->err = rng_int(3) == 0 ? 0.0 : fabs(rng_value(scale - 20 - rng_int(20)));
}

/* a symbol value: a corner, 0, or a random point with few bits (so that
 * the oracle's products are exact) */
static long double rng_eps(void)
{
    switch (rng_int(4)) {
    case 0: return 1.0L;
    case 1: return -1.0L;
    default: return (long double)(rng_int(2049) - 1024) / 1024.0L;
    }
}

typedef struct oracle {
    long double v;       /* the value at the point */
    long double mag;     /* the magnitudes summed: the oracle's own error scale */
} oracle;

static oracle eval(const aa_dense *x, const long double *eps, long double eerr)
{
    oracle o = { x->x0, fabsl((long double)x->x0) };
    for (int i = 0; i < AA_DENSE_W; i++) {
        o.v += (long double)x->c[i] * eps[i];
        o.mag += fabsl((long double)x->c[i]);
    }
    o.v += (long double)x->err * eerr;
    o.mag += (long double)x->err;
    return o;
}

enum { OP_ADD, OP_SUB, OP_LINCOMB, OP_MUL, OP__N };
static const char *const op_name[OP__N] = { "add", "sub", "lincomb", "mul" };

static bool finite_form(const aa_dense *z)
{
    return isfinite(aa_dense_radius(z)) && isfinite(z->x0);
}

/* one case: the op on random operands, checked at POINTS points */
static long check_case(int op, long *checked)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_DENSE_W);
    int used = 1 + rng_int(AA_DENSE_W);
    if (op == OP_MUL && rng_int(2))
        used = AA_DENSE_W;                      /* no fresh symbol: folded */
    ctx.used = used;
    int scale = rng_int(60) - 30;
    aa_dense x, y, z;
    rng_dense(&x, used, scale);
    rng_dense(&y, used, scale + rng_int(5) - 2);
    if (rng_int(10) == 0)
        y = x;                                  /* cancellation: x - x */
    double a = rng_value(0), b = rng_value(0), c = rng_value(scale);
    switch (op) {
    case OP_ADD: aa_dense_add(&z, &x, &y); break;
    case OP_SUB: aa_dense_sub(&z, &x, &y); break;
    case OP_LINCOMB: aa_dense_lincomb(&z, a, &x, b, &y, c); break;
    default: aa_dense_mul(&ctx, &z, &x, &y); break;
    }
    if (!finite_form(&x) || !finite_form(&y) || !finite_form(&z)) {
        /* an unbounded result must say so */
        if (!finite_form(&z))
            assert_true(aa_dense_range(&z).flags & AA_UNBOUNDED);
        return 0;
    }
    long bad = 0;
    ia_interval range = aa_dense_range(&z);
    for (int k = 0; k < POINTS; k++) {
        long double eps[AA_DENSE_W];
        for (int i = 0; i < AA_DENSE_W; i++)
            eps[i] = i < used ? rng_eps() : 0.0L;    /* new symbols: free below */
        oracle ox = eval(&x, eps, rng_eps()), oy = eval(&y, eps, rng_eps());
        if (memcmp(&x, &y, sizeof x) == 0) {     /* y = x: the same private error */
            long double e = rng_eps();
            ox = eval(&x, eps, e);
            oy = eval(&y, eps, e);
        }
        long double f, mag;
        switch (op) {
        case OP_ADD: f = ox.v + oy.v; mag = ox.mag + oy.mag; break;
        case OP_SUB: f = ox.v - oy.v; mag = ox.mag + oy.mag; break;
        case OP_LINCOMB:
            f = (long double)a * ox.v + (long double)b * oy.v + (long double)c;
            mag = fabsl((long double)a) * ox.mag + fabsl((long double)b) * oy.mag +
                  fabsl((long double)c);
            break;
        default: f = ox.v * oy.v; mag = ox.mag * oy.mag; break;
        }
        long double zl = z.x0, allow = z.err;
        for (int i = 0; i < AA_DENSE_W; i++) {
            if (i < used)
                zl += (long double)z.c[i] * eps[i];
            else
                allow += fabsl((long double)z.c[i]);   /* a fresh symbol: any value */
        }
        long double slack = mag * 0x1p-60L;     /* no absolute part: underflow shows */
        if (fabsl(f - zl) > allow + slack || f < (long double)range.lo - slack ||
            f > (long double)range.hi + slack) {
            if (bad < 3)
                fprintf(stderr, "  VIOLATION %s: x0 %a err %a, y0 %a err %a -> z0 %a err %a; "
                        "f - z(e) = %La, allowed %La\n", op_name[op], x.x0, x.err, y.x0,
                        y.err, z.x0, z.err, f - zl, allow);
            bad++;
        }
        (*checked)++;
    }
    return bad;
}

static void test_containment(void **state)
{
    (void)state;
    long total = 0;
    for (int op = 0; op < OP__N; op++) {
        long bad = 0, checked = 0;
        for (int k = 0; k < CASES; k++)
            bad += check_case(op, &checked);
        printf("dense %-8s %d cases, %ld points, %ld violations\n", op_name[op], CASES,
               checked, bad);
        total += bad;
    }
    assert_int_equal(total, 0);
}

/* exactness where the arithmetic rounds nothing */
static void test_exact(void **state)
{
    (void)state;
    aa_dense x, y, z;
    aa_dense_const(&x, 3.0);
    aa_dense_const(&y, 0.25);
    aa_dense_add(&z, &x, &y);
    assert_true(z.x0 == 3.25 && z.err == 0.0);
    aa_dense_lincomb(&z, 2.0, &x, -4.0, &y, 1.0);    /* products bounded a priori */
    assert_true(z.x0 == 6.0 && z.err <= 0x1p-48 * 8.0);
    x.c[0] = 0.5;
    x.c[1] = -0.125;
    aa_dense_sub(&z, &x, &x);                     /* x - x, no private error */
    assert_true(z.x0 == 0.0 && z.err == 0.0);
    for (int i = 0; i < AA_DENSE_W; i++)
        assert_true(z.c[i] == 0.0);
    ia_interval r = aa_dense_range(&y);
    assert_true(r.lo == 0.25 && r.hi == 0.25);
    aa_dense_const(&x, INFINITY);
    assert_true(aa_dense_range(&x).flags & AA_UNBOUNDED);
}

/* aa_form -> dense -> aa_form keeps every value of the form */
static void test_convert(void **state)
{
    (void)state;
    aa_context ctx;
    aa_context_init(&ctx, 8);
    aa_form u, v, s, back;
    aa_input(&ctx, &u, 0.25, 0.5);
    aa_input(&ctx, &v, -1.0, 3.0);
    aa_mul(&ctx, &s, &u, &v);
    aa_input(&ctx, &back, 0.0, 1.0);             /* symbols 3..5: folded */
    aa_input(&ctx, &back, 0.0, 1.0);
    aa_add(&ctx, &s, &s, &back);
    aa_dense d;
    aa_dense_from_form(&d, &s);
    aa_dense_to_form(&back, &d);
    ia_interval r0 = aa_range(&s), r1 = aa_range(&back);
    assert_true(r1.lo <= r0.lo && r1.hi >= r0.hi);     /* the hull is not kept */
    assert_true(r1.hi - r1.lo <= 2.0 * aa_radius(&s) * (1.0 + 0x1p-40));
    assert_true(s.n > AA_DENSE_W && back.n <= AA_DENSE_W);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_containment),
        cmocka_unit_test(test_exact),
        cmocka_unit_test(test_convert),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

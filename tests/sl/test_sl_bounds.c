/*
 * tests/sl/test_sl_bounds.c: the interval and affine modes of the VM
 * (Heidrich & Seidel 1998 §4, §4.1, §5).
 *
 *   merging      an undecided if / ?: / loop runs both ways and encloses
 *                every float outcome, flagged AA_DISCONTINUOUS; decided
 *                ones are exact and unflagged; an early return does not
 *                leak the uninitialised result into the bound; affine
 *                comparisons decide correlated operands that intervals
 *                cannot
 *   containment  for every library shader, random (u,v) ranges on the
 *                plane P = (2u-1, 2v-1, 0) and on the unit sphere: 8x8
 *                float samples inside each range lie inside the interval
 *                and the affine enclosure of P (displacement) or Ci
 *                (surface, lit by fixed lights); 0 violations, counts
 *                printed
 *   tightness    the average affine box width over the interval box
 *                width, printed, and below 1 for the smooth shaders
 *   programs     60 random shaders mixing if/else, ?:, loops, break,
 *                continue and early returns: containment as above
 *
 * A float sample is compared with a tolerance of 1e-9 (1 + |value|): the
 * float run rounds too, the enclosures hold the exact real values.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/strbuf.h"
#include "sl_harness.h"

/* ---------------------------------------------------------------------- */
/* helpers                                                                 */
/* ---------------------------------------------------------------------- */

typedef struct enclosures {
    ia_interval ia[3];
    ia_interval aa[3];      /* aa_range of the affine results */
    unsigned ia_flags[3], aa_flags[3];
} enclosures;

/* Runs `prog` over [u0,u1] x [v0,v1] of surface s in both modes; reads
 * global g. */
static void run_bounds(sl_vm *vm, const sl_instance *inst, h_surface s, double u0, double u1,
                       double v0, double v1, sl_global g, enclosures *e)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    h_globals_interval(vm, s, u0, u1, v0, v1);
    sl_status st = sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL);
    if (st != SL_OK)
        fprintf(stderr, "%s\n", sl_vm_error(vm));
    assert_int_equal(st, SL_OK);
    sl_vm_get_interval(vm, g, e->ia);
    h_globals_affine(vm, &ctx, s, u0, u1, v0, v1);
    st = sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx);
    if (st != SL_OK)
        fprintf(stderr, "%s\n", sl_vm_error(vm));
    assert_int_equal(st, SL_OK);
    aa_form a[3];
    sl_vm_get_affine(vm, g, a);
    for (int i = 0; i < 3; i++) {
        e->aa[i] = aa_range(&a[i]);
        e->aa_flags[i] = a[i].flags;
        e->ia_flags[i] = e->ia[i].flags;
    }
}

static void run_float(sl_vm *vm, const sl_instance *inst, h_surface s, double u, double v,
                      sl_global g, double out[3])
{
    h_globals_float(vm, s, u, v);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, g, out);
}

static bool inside(ia_interval r, double x)
{
    double tol = 1e-9 * (1 + fabs(x));
    return x >= r.lo - tol && x <= r.hi + tol;
}

/* The displacement program body wrapped into a shader, run over one range. */
static void body_bounds(const char *body, double u0, double u1, enclosures *e)
{
    char src[2048];
    snprintf(src, sizeof src, "displacement t() { %s }", body);
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    run_bounds(vm, inst, H_PLANE, u0, u1, 0.25, 0.5, SL_G_P, e);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static double body_float(const char *body, double u)
{
    char src[2048];
    snprintf(src, sizeof src, "displacement t() { %s }", body);
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    double P[3];
    run_float(vm, inst, H_PLANE, u, 0.3, SL_G_P, P);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
    return P[0];
}

static void assert_range(ia_interval r, double lo, double hi)
{
    assert_true(r.lo <= lo && r.hi >= hi);
    assert_true(r.lo >= lo - 1e-9 && r.hi <= hi + 1e-9);
}

/* ---------------------------------------------------------------------- */
/* case splits (issue 24)                                                  */
/* ---------------------------------------------------------------------- */

/* Runs `body` over u in [0.2, 0.3] (v in [0.25, 0.5]) of the plane with
 * case splits of at most max_ops operations: each case's P in out[]
 * (aa_range per component), the number of runs returned */
static int split_runs(const char *body, int max_ops, ia_interval out[][3], int nout)
{
    char src[2048];
    snprintf(src, sizeof src, "displacement t() { %s }", body);
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    int runs = 0;
    sl_vm_split_begin(vm, max_ops);
    do {
        aa_context_reset(&ctx);
        h_globals_affine(vm, &ctx, H_PLANE, 0.2, 0.3, 0.25, 0.5);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx), SL_OK);
        aa_form a[3];
        sl_vm_get_affine(vm, SL_G_P, a);
        assert_true(runs < nout);
        for (int i = 0; i < 3; i++) out[runs][i] = aa_range(&a[i]);
        runs++;
    } while (sl_vm_split_next(vm));
    sl_vm_split_end(vm);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
    return runs;
}

static void test_case_splits(void **state)
{
    (void)state;
    ia_interval r[8][3];
    /* k = floor(4u) over [0.8, 1.2]: 0 or 1, so k*k - k is 0 in both
     * cases; one run bounds it by [-1/4, 0] or wider */
    const char *body = "float k = floor(4 * u); P = point(k * k - k, 0, 0);";
    assert_int_equal(split_runs(body, 0, r, 8), 1);
    assert_true(r[0][0].lo <= -0.2 && r[0][0].hi >= 0);
    assert_int_equal(split_runs(body, 3, r, 8), 2);
    for (int c = 0; c < 2; c++) assert_true(r[c][0].lo == 0 && r[c][0].hi == 0);
    /* two operations: four cases, every pair of values once (depth first) */
    body = "P = point(floor(4 * u), step(0.25, u), mod(4 * u, 1));";
    assert_int_equal(split_runs(body, 3, r, 8), 8);
    for (int c = 0; c < 8; c++) {
        assert_true(r[c][0].lo == r[c][0].hi && r[c][0].lo == (c >> 2));
        assert_true(r[c][1].lo == r[c][1].hi && r[c][1].lo == ((c >> 1) & 1));
        /* mod: 4u - k for k = 0 ([0.8, 1.2]) or 1 ([-0.2, 0.2]) */
        double k = c & 1;
        assert_true(r[c][2].lo <= 0.8 - k && r[c][2].hi >= 1.2 - k);
        assert_true(r[c][2].lo >= 0.8 - k - 1e-9 && r[c][2].hi <= 1.2 - k + 1e-9);
    }
    /* at most max_ops splits: the rest bound both values as one run does */
    assert_int_equal(split_runs(body, 1, r, 8), 2);
    for (int c = 0; c < 2; c++) {
        assert_true(r[c][0].lo == c && r[c][0].hi == c);
        assert_true(r[c][1].lo <= 0 && r[c][1].hi >= 1);
    }
    /* decided operations are not split: one run */
    assert_int_equal(split_runs("P = point(floor(u), step(0.1, u), ceil(2 * u));", 3, r, 8), 1);
}

/* The hull of the cases' P.x, and whether P.x at u (float) lies in it for
 * every u of a fine grid over the split range [0.2, 0.3] */
static ia_interval cases_hull(ia_interval r[][3], int runs)
{
    ia_interval h = r[0][0];
    for (int c = 1; c < runs; c++) h = ia_make(fmin(h.lo, r[c][0].lo), fmax(h.hi, r[c][0].hi));
    return h;
}
static void assert_cases_enclose(const char *body, ia_interval h)
{
    for (int k = 0; k <= 200; k++) {
        double u = 0.2 + 0.1 * k / 200.0;
        assert_true(inside(h, body_float(body, u)));
    }
}

static void test_case_splits_same_value(void **state)
{
    (void)state;
    ia_interval r[8][3];
    /* the filtered pulse train's integral (tests/shaders/corpus/include/
     * filterwidth.h): floor(x) twice of one x, continuous over x = 1 (the
     * seam in u = 0.25). Both floors take one case (split_plan.c): 2 runs,
     * k = 0: min(0.3, [0.8, 1.2]) = 0.3; k = 1: 0.3 + [-0.2, 0.2]. Split
     * apart: four runs, two of them cases no point has (0.6 and
     * [-0.2, 0.2]), and a hull of [-0.2, 0.6] */
    const char *body = "float x = 4 * u; P = point(0.3 * floor(x) + min(0.3, x - floor(x)), 0, 0);";
    int runs = split_runs(body, 3, r, 8);
    assert_int_equal(runs, 2);
    ia_interval h = cases_hull(r, runs);
    assert_true(h.lo >= 0.1 - 1e-9 && h.hi <= 0.5 + 1e-9);
    assert_cases_enclose(body, h);
    /* the pulse train itself: two integrals, four floors, two values: 2 of
     * the budget of 3, where apart they overflowed it */
    body = "float x0 = 4 * u - 0.05, x1 = x0 + 0.1;"
           "float i1 = 0.3 * floor(x1) + min(0.3, x1 - floor(x1));"
           "float i0 = 0.3 * floor(x0) + min(0.3, x0 - floor(x0));"
           "P = point((i1 - i0) / 0.1, 0, 0);";
    runs = split_runs(body, 3, r, 8);
    assert_int_equal(runs, 4);
    assert_cases_enclose(body, cases_hull(r, runs));
    /* the same slot written between the floors: two values, split apart
     * (x = 0.95: floor 0, then floor(1.05) = 1, a case of its own) */
    body = "float x = 4 * u; float a = floor(x); x = x + 0.1; P = point(a + 2 * floor(x), 0, 0);";
    runs = split_runs(body, 3, r, 8);
    assert_int_equal(runs, 4);
    assert_cases_enclose(body, cases_hull(r, runs));
    /* a branch between them (it writes x): apart, and the undecided
     * branch is a split of its own (one side a case): 2 x 2 x 2 runs */
    body = "float x = 4 * u; float a = floor(x); if (u > 0.24) x = x + 0.1;"
           "P = point(a + 2 * floor(x), 0, 0);";
    runs = split_runs(body, 3, r, 8);
    assert_int_equal(runs, 8);
    assert_cases_enclose(body, cases_hull(r, runs));
    /* mod and step of the same operands agree too; of other operands not */
    body = "float x = 4 * u; P = point(mod(x, 1) + mod(x, 1), step(1, x) - step(1, x), step(1, x));";
    assert_int_equal(split_runs(body, 3, r, 8), 4);
    for (int c = 0; c < 4; c++) assert_true(r[c][1].lo == 0 && r[c][1].hi == 0);
}

/* Undecided branches split into cases (issue 24: the nearest cell of a
 * Voronoi loop is chosen by comparisons that a range leaves undecided, so
 * its boxes were estimated from samples): one side a case, a branch in a
 * loop once per time it is met, each case exact for the points that take
 * its sides, the hull enclosing every point */
static void test_case_splits_branches(void **state)
{
    (void)state;
    ia_interval r[8][3];
    /* u in [0.2, 0.3] against 0.25: 0 in one case, 1 in the other (one
     * run merges them: [0, 1]) */
    const char *body = "float h; if (u > 0.25) h = 1; else h = 0; P = point(h, 0, 0);";
    assert_int_equal(split_runs(body, 0, r, 8), 1);
    assert_true(r[0][0].lo <= 0 && r[0][0].hi >= 1);
    assert_int_equal(split_runs(body, 3, r, 8), 2);
    for (int c = 0; c < 2; c++) assert_true(r[c][0].lo == r[c][0].hi);
    assert_true(r[0][0].lo != r[1][0].lo);
    assert_cases_enclose(body, cases_hull(r, 2));
    /* in a loop: met twice, four cases (h = 0, 1, 1, 2 by the sides) */
    body = "float h = 0, i; for (i = 0; i < 2; i += 1) if (u > 0.24 + 0.02 * i) h += 1;"
           "P = point(h, 0, 0);";
    assert_int_equal(split_runs(body, 3, r, 8), 4);
    double seen = 0;
    for (int c = 0; c < 4; c++) {
        assert_true(r[c][0].lo == r[c][0].hi);
        seen += r[c][0].lo;
    }
    assert_true(seen == 4.0);
    assert_cases_enclose(body, cases_hull(r, 4));
    /* a decided condition takes no split; a conditional expression splits */
    assert_int_equal(split_runs("float h = u > 0.1 ? 1 : 0; P = point(h, 0, 0);", 3, r, 8), 1);
    body = "float h = u > 0.25 ? u : 1 - u; P = point(h, 0, 0);";
    assert_int_equal(split_runs(body, 3, r, 8), 2);
    assert_cases_enclose(body, cases_hull(r, 2));
}

/* ---------------------------------------------------------------------- */
/* merging                                                                 */
/* ---------------------------------------------------------------------- */

static void test_undecided_if_merges(void **state)
{
    (void)state;
    enclosures e;
    const char *body = "if (u > 0.35) P = point(1, 0, 0); else P = point(2, 0, 0);";
    body_bounds(body, 0.3, 0.4, &e);
    assert_range(e.ia[0], 1, 2);
    assert_range(e.aa[0], 1, 2);
    assert_true(e.ia_flags[0] & AA_DISCONTINUOUS);
    assert_true(e.aa_flags[0] & AA_DISCONTINUOUS);
    /* y = 2v - 1 is written by neither branch: not merged, not flagged */
    assert_false(e.aa_flags[1] & AA_DISCONTINUOUS);
    /* a decided condition takes one branch, exactly, without the flag */
    body_bounds(body, 0.4, 0.5, &e);
    assert_true(e.ia[0].lo == 1 && e.ia[0].hi == 1);
    assert_true(e.aa[0].lo == 1 && e.aa[0].hi == 1);
    assert_false(e.aa_flags[0] & AA_DISCONTINUOUS);
    assert_true(body_float(body, 0.36) == 1 && body_float(body, 0.34) == 2);
}

static void test_undecided_conditional_expression(void **state)
{
    (void)state;
    enclosures e;
    body_bounds("P = point(u < 0.5 ? u : 1 - u, 0, 0);", 0.4, 0.6, &e);
    /* both values over the whole range: [0.4, 0.6] */
    assert_range(e.ia[0], 0.4, 0.6);
    assert_true(e.aa[0].lo <= 0.4 && e.aa[0].hi >= 0.6);
    assert_true(e.aa_flags[0] & AA_DISCONTINUOUS);
    /* && and ! on undecided operands stay undecided; decided ones decide */
    body_bounds("P = point((u > 0.5 && v < 2) ? 1 : 0, !(u > 0.9) ? 3 : 4, 0);", 0.4, 0.6, &e);
    assert_range(e.aa[0], 0, 1);
    assert_true(e.aa[1].lo == 3 && e.aa[1].hi == 3);
}

static void test_undecided_loop(void **state)
{
    (void)state;
    enclosures e;
    /* the number of iterations depends on u: 3 or 4 (or 5: u*10 rounds) */
    const char *body = "float a = 0; while (a < u * 10) a += 1; P = point(a, 0, 0);";
    body_bounds(body, 0.3, 0.4, &e);
    for (double u = 0.3; u <= 0.4; u += 0.01) {
        double f = body_float(body, u);
        assert_true(inside(e.ia[0], f) && inside(e.aa[0], f));
    }
    assert_true(e.aa[0].lo >= 3 && e.aa[0].hi <= 5);
    assert_true(e.aa_flags[0] & AA_DISCONTINUOUS);
    /* break out of an undecided loop */
    body = "float a = 0; while (1) { a += 1; if (a > u * 10) break; } P = point(a, 0, 0);";
    body_bounds(body, 0.3, 0.4, &e);
    for (double u = 0.3; u <= 0.4; u += 0.01)
        assert_true(inside(e.aa[0], body_float(body, u)));
    assert_true(e.aa[0].lo >= 3 && e.aa[0].hi <= 5);
    /* a break under an undecided condition is a dead path: its state is
     * saved and the loop goes on with the other paths only, so the counter
     * stays a point and the loop ends (u + 0.1 i > 0.6 at i = 3 or never,
     * for u in [0.25, 0.35]) */
    body = "float i, a = 0; for (i = 0; i < 4; i += 1) { if (u + i * 0.1 > 0.6) break; a += 1; }"
           " P = point(a, i, 0);";
    body_bounds(body, 0.25, 0.35, &e);
    for (double u = 0.25; u <= 0.35; u += 0.01) {
        double f = body_float(body, u);
        assert_true(inside(e.aa[0], f) && inside(e.ia[0], f));
    }
    assert_range(e.aa[0], 3, 4);
    assert_range(e.aa[1], 3, 4);
    assert_range(e.ia[0], 3, 4);
    /* integer counters stay exact: a decided loop gives a point */
    body_bounds("float a = 0, i; for (i = 0; i < 5; i += 1) { if (i == 3) continue; a += i * i; }"
                " P = point(a, 0, 0);", 0.3, 0.4, &e);
    assert_true(e.aa[0].lo == 21 && e.aa[0].hi == 21);
    assert_true(e.ia[0].lo == 21 && e.ia[0].hi == 21);
}

static void test_early_return_bound(void **state)
{
    (void)state;
    enclosures e;
    char src[] = "float f(float x) { if (x > 0.35) return 1; return 2; }\n"
                 "displacement t() { P = point(f(u), 0, 0); }";
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    run_bounds(vm, inst, H_PLANE, 0.3, 0.4, 0, 1, SL_G_P, &e);
    /* the return slot is dead until returned: [1, 2], not [0, 2] */
    assert_range(e.ia[0], 1, 2);
    assert_range(e.aa[0], 1, 2);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

/* An early return inside a loop: the returned paths are saved, the loop
 * counter stays exact, the result covers 4 and 5 only. */
static void test_return_in_loop(void **state)
{
    (void)state;
    const char *src = "float first(float x) { float k;\n"
                      "  for (k = 0; k < 8; k += 1) { if (x < k * 0.1) return k; }\n"
                      "  return -1; }\n"
                      "displacement t() { P = point(first(u), 0, 0); }\n";
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    enclosures e;
    run_bounds(vm, inst, H_PLANE, 0.33, 0.43, 0, 1, SL_G_P, &e);
    for (double u = 0.331; u < 0.43; u += 0.01) {
        double f[3];
        run_float(vm, inst, H_PLANE, u, 0.5, SL_G_P, f);
        assert_true(f[0] == 4 || f[0] == 5);
        assert_true(inside(e.aa[0], f[0]) && inside(e.ia[0], f[0]));
    }
    assert_range(e.aa[0], 4, 5);
    assert_range(e.ia[0], 4, 5);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_affine_decides_correlated_comparison(void **state)
{
    (void)state;
    enclosures e;
    /* u < u + 0.1 everywhere, but the intervals [0.3,0.4] and [0.4,0.5] touch */
    body_bounds("P = point(u < u + 0.1 ? 1 : 2, 0, 0);", 0.3, 0.4, &e);
    assert_true(e.aa[0].lo == 1 && e.aa[0].hi == 1);
    assert_false(e.aa_flags[0] & AA_DISCONTINUOUS);
    assert_true(e.ia[0].lo == 1 && e.ia[0].hi == 2);
    assert_true(e.ia_flags[0] & AA_DISCONTINUOUS);
}

static void test_flags_reach_P(void **state)
{
    (void)state;
    enclosures e;
    body_bounds("P += step(0.35, u) * N;", 0.3, 0.4, &e);
    assert_true(e.aa_flags[2] & AA_DISCONTINUOUS);
    assert_true(e.ia_flags[2] & AA_DISCONTINUOUS);
    assert_range(e.aa[2], 0, 1);
    body_bounds("P += floor(u * 2) * N;", 0.3, 0.4, &e);   /* floor constant: no jump */
    assert_false(e.aa_flags[2] & AA_DISCONTINUOUS);
    body_bounds("P += mod(u * 10, 1) * N;", 0.3, 0.4, &e);  /* jumps at u = 0.4 */
    assert_true(e.aa_flags[2] & AA_DISCONTINUOUS);
    /* derivatives carry bounds in these modes (vm_deriv.inc): on the plane
     * P = (2u-1, 2v-1, 0), so calculatenormal(P) = (0, 0, 4) */
    body_bounds("N = calculatenormal(P); P = N;", 0.3, 0.4, &e);
    assert_false(e.aa_flags[0] & AA_UNBOUNDED);
    assert_false(e.ia_flags[0] & AA_UNBOUNDED);
    assert_range(e.aa[2], 4, 4);
    assert_range(e.ia[2], 4, 4);
    assert_range(e.aa[0], 0, 0);
}

static void test_uniform_parameter_in_condition(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement t(float k = 1) { if (k > 0.5) P += N; else P -= N; }");
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    enclosures e;
    run_bounds(vm, inst, H_PLANE, 0.3, 0.4, 0.3, 0.4, SL_G_P, &e);
    assert_true(e.aa[2].lo == 1 && e.aa[2].hi == 1);
    double k = 0;
    assert_true(sl_instance_set(inst, "k", SL_TYPE_FLOAT, &k, 1, NULL, 0));
    run_bounds(vm, inst, H_PLANE, 0.3, 0.4, 0.3, 0.4, SL_G_P, &e);
    assert_true(e.aa[2].lo == -1 && e.aa[2].hi == -1);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

/* ---------------------------------------------------------------------- */
/* random structured programs                                              */
/* ---------------------------------------------------------------------- */

/* A generator of small shaders mixing everything that merges: if/else,
 * ?:, for and while loops with undecided conditions, break, continue, a
 * function with early returns inside a loop, an early return of the
 * shader. */
typedef struct gen {
    sl_strbuf b;
    unsigned long long rng;
    int depth, counters;
} gen;

static int pick(gen *g, int n) { return (int)(h_rand(&g->rng) * n); }
static void put(gen *g, const char *s) { sl_strbuf_puts(&g->b, s); }

static void gen_expr(gen *g, int d);

static void gen_cond(gen *g, int d)
{
    put(g, "(");
    gen_expr(g, d);
    put(g, pick(g, 2) ? " < " : " > ");
    gen_expr(g, d);
    put(g, ")");
}

static void gen_expr(gen *g, int d)
{
    static const char *const atoms[] = { "u", "v", "a", "b", "c", "0.5", "1", "2", "0.25", "-1" };
    switch (d <= 0 ? 0 : pick(g, 7)) {
    case 0: case 1: put(g, atoms[pick(g, 10)]); break;
    case 2: put(g, "("); gen_expr(g, d - 1); put(g, " + "); gen_expr(g, d - 1); put(g, ")"); break;
    case 3: put(g, "("); gen_expr(g, d - 1); put(g, " * "); gen_expr(g, d - 1); put(g, ")"); break;
    case 4: put(g, "sin("); gen_expr(g, d - 1); put(g, ")"); break;
    case 5:
        put(g, "(");
        gen_cond(g, d - 1);
        put(g, " ? ");
        gen_expr(g, d - 1);
        put(g, " : ");
        gen_expr(g, d - 1);
        put(g, ")");
        break;
    default: put(g, "f("); gen_expr(g, d - 1); put(g, ")"); break;
    }
}

static void gen_stmts(gen *g, int n, bool in_loop);

static void gen_loop_stmt(gen *g, bool is_for)
{
    char line[128];
    int c = g->counters++ % 20;
    if (is_for) {
        snprintf(line, sizeof line, "for (i%d = 0; i%d < %d; i%d += 1) {\n", c, c,
                 1 + pick(g, 4), c);
        put(g, line);
    } else {
        snprintf(line, sizeof line, "i%d = 0; while (", c);
        put(g, line);
        gen_cond(g, 1);
        snprintf(line, sizeof line, " && i%d < 4) {\ni%d += 1;\n", c, c);
        put(g, line);
    }
    g->depth++;
    gen_stmts(g, 1 + pick(g, 3), true);
    g->depth--;
    put(g, "}\n");
}

static void gen_stmt(gen *g, bool in_loop)
{
    static const char *const vars[] = { "a", "b", "c" };
    static const char *const ops[] = { " = ", " += ", " *= " };
    switch (g->depth > 2 ? pick(g, 2) : pick(g, in_loop ? 7 : 5)) {
    case 0: case 1:
        put(g, vars[pick(g, 3)]);
        put(g, ops[pick(g, 3)]);
        gen_expr(g, 2);
        put(g, ";\n");
        break;
    case 2:
        put(g, "if ");
        gen_cond(g, 1);
        put(g, " {\n");
        g->depth++;
        gen_stmts(g, 1 + pick(g, 3), in_loop);
        if (pick(g, 2)) {
            put(g, "} else {\n");
            gen_stmts(g, 1 + pick(g, 2), in_loop);
        }
        g->depth--;
        put(g, "}\n");
        break;
    case 3: gen_loop_stmt(g, true); break;
    case 4: gen_loop_stmt(g, false); break;
    case 5: put(g, pick(g, 3) ? "if (u > 0.5) break;\n" : "break;\n"); break;
    default:
        put(g, "if ");
        gen_cond(g, 1);
        put(g, pick(g, 2) ? " continue;\n" : " break;\n");
        break;
    }
}

static void gen_stmts(gen *g, int n, bool in_loop)
{
    for (int i = 0; i < n; i++)
        gen_stmt(g, in_loop);
}

static char *gen_shader(unsigned long long seed)
{
    gen g = { .rng = seed * 7919 + 1 };
    char k[64];
    snprintf(k, sizeof k, "%.3f", h_rand(&g.rng) * 2 - 1);
    put(&g, "float f(float x) { if (x > ");
    put(&g, k);
    put(&g, ") return x * 0.5; float y = x, j;\n"
            "  for (j = 0; j < 3; j += 1) { if (y > u) return y; y += 0.3; }\n"
            "  return -x; }\n"
            "displacement t() {\nfloat a = u, b = v, c = 0.5;\n"
            "float i0, i1, i2, i3, i4, i5, i6, i7, i8, i9, i10, i11, i12, i13, i14, i15, i16,"
            " i17, i18, i19;\n");
    gen_stmts(&g, 3 + pick(&g, 4), false);
    if (pick(&g, 3) == 0)
        put(&g, "if (v > 0.5) { P = point(a, b, c); return; }\n");
    put(&g, "P = point(a, b, c) * 0.5 + P;\n}\n");
    return g.b.data;
}

/* Every generated program: 10 (u,v) ranges, 4x4 float samples each, all
 * inside both enclosures of P. A loop cap is allowed (an error, not a
 * wrong bound); none is expected with these small loops. */
static void test_random_programs(void **state)
{
    (void)state;
    long samples = 0, violations = 0, caps = 0;
    for (unsigned long long seed = 1; seed <= 60; seed++) {
        char *src = gen_shader(seed);
        sl_program *p = h_compile(src);
        assert_non_null(p);
        sl_instance *inst = sl_instance_new(p);
        sl_vm *vm = sl_vm_new(NULL);
        unsigned long long rng = seed;
        for (int r = 0; r < 10; r++) {
            double w = ldexp(1.0, -1 - r % 5), u0 = h_rand(&rng) * (1 - w);
            double v0 = h_rand(&rng) * (1 - w);
            aa_context ctx;
            aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
            h_globals_interval(vm, H_PLANE, u0, u0 + w, v0, v0 + w);
            sl_status si = sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL);
            ia_interval I[3];
            sl_vm_get_interval(vm, SL_G_P, I);
            h_globals_affine(vm, &ctx, H_PLANE, u0, u0 + w, v0, v0 + w);
            sl_status sa = sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx);
            aa_form A[3];
            sl_vm_get_affine(vm, SL_G_P, A);
            if (si == SL_ERR_LOOP_CAP || sa == SL_ERR_LOOP_CAP) {
                caps++;
                continue;
            }
            assert_int_equal(si, SL_OK);
            assert_int_equal(sa, SL_OK);
            for (int k = 0; k < 16; k++) {
                double u = u0 + w * (k % 4 + 0.5) / 4, v = v0 + w * (k / 4 + 0.5) / 4, F[3];
                run_float(vm, inst, H_PLANE, u, v, SL_G_P, F);
                for (int i = 0; i < 3; i++) {
                    bool ok = !isfinite(F[i]) ||
                              (inside(I[i], F[i]) && inside(aa_range(&A[i]), F[i]));
                    if (!ok && violations++ < 2)
                        fprintf(stderr, "violation at u=%g v=%g in:\n%s", u, v, src);
                }
                samples++;
            }
        }
        sl_vm_destroy(&vm);
        sl_instance_destroy(&inst);
        sl_program_destroy(&p);
        free(src);
    }
    printf("  random programs: 60 programs, %ld samples, %ld violations, %ld loop caps\n",
           samples, violations, caps);
    assert_int_equal(violations, 0);
    assert_int_equal(caps, 0);
}

/* ---------------------------------------------------------------------- */
/* containment and tightness of the library shaders                        */
/* ---------------------------------------------------------------------- */

enum { RANGES = 200, GRID = 8 };

typedef struct bound_stats {
    long samples, ia_violations, aa_violations;
    double ratio_sum;              /* of affine / interval box width, per range */
    int ratios, unbounded;
} bound_stats;

static void check_range(sl_vm *vm, const sl_instance *inst, h_surface s, sl_global g,
                        double u0, double u1, double v0, double v1, bound_stats *st)
{
    enclosures e;
    run_bounds(vm, inst, s, u0, u1, v0, v1, g, &e);
    double iw = 0, aw = 0;
    bool finite = true;
    for (int i = 0; i < 3; i++) {
        iw += e.ia[i].hi - e.ia[i].lo;
        aw += e.aa[i].hi - e.aa[i].lo;
    }
    finite = isfinite(iw) && isfinite(aw);
    if (finite && iw > 1e-12) {        /* else numerically constant: no ratio */
        st->ratio_sum += aw / iw;
        st->ratios++;
    } else if (!finite) {
        st->unbounded++;
    }
    for (int a = 0; a < GRID; a++) {
        for (int b = 0; b < GRID; b++) {
            double u = u0 + (u1 - u0) * (a + 0.5) / GRID;
            double v = v0 + (v1 - v0) * (b + 0.5) / GRID;
            double f[3];
            run_float(vm, inst, s, u, v, g, f);
            st->samples++;
            bool ia_ok = true, aa_ok = true;
            for (int i = 0; i < 3; i++) {
                ia_ok &= inside(e.ia[i], f[i]);
                aa_ok &= inside(e.aa[i], f[i]);
            }
            if (!aa_ok && st->aa_violations < 3)
                fprintf(stderr, "  affine violation at u=%.17g v=%.17g: (%g %g %g) not in "
                        "[%g %g] [%g %g] [%g %g]\n", u, v, f[0], f[1], f[2], e.aa[0].lo,
                        e.aa[0].hi, e.aa[1].lo, e.aa[1].hi, e.aa[2].lo, e.aa[2].hi);
            if (!ia_ok && st->ia_violations < 3)
                fprintf(stderr, "  interval violation at u=%.17g v=%.17g\n", u, v);
            st->ia_violations += !ia_ok;
            st->aa_violations += !aa_ok;
        }
    }
}

/* Random boxes of widths 2^-1 .. 2^-7 inside the unit square. */
static void random_box(unsigned long long *rng, double *lo, double *hi)
{
    int k = 1 + (int)(h_rand(rng) * 7);
    double w = ldexp(1.0, -k);
    *lo = h_rand(rng) * (1 - w);
    *hi = *lo + w;
}

/* Containment of global g of program p (named `name` in the report) over
 * random ranges of the plane and the sphere, with the named spaces
 * `spaces` (NULL: identity); the mean width ratio affine/interval. */
static double check_program(sl_program *p, const char *name, sl_global g,
                            const sl_spaces *spaces)
{
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    sl_vm_set_spaces(vm, spaces);
    /* fixed lights (all modes): an ambient and a distant light */
    sl_light_sample lights[2] = {
        { { 0, 0, 0 }, { 0.2, 0.2, 0.2 }, true, false },
        { { 1, 2, -2 }, { 0.8, 0.7, 0.6 }, false, true },
    };
    sl_vm_set_fixed_lights(vm, lights, 2);
    double ratio_sum = 0;
    for (int s = H_PLANE; s <= H_SPHERE; s++) {
        bound_stats st = { 0 };
        unsigned long long rng = 0x9E3779B97F4A7C15ULL + (unsigned long long)s;
        for (int r = 0; r < RANGES; r++) {
            double u0, u1, v0, v1;
            random_box(&rng, &u0, &u1);
            random_box(&rng, &v0, &v1);
            check_range(vm, inst, (h_surface)s, g, u0, u1, v0, v1, &st);
        }
        double ratio = st.ratios ? st.ratio_sum / st.ratios : 1.0;
        printf("  %-8s %-6s: %ld samples in %d ranges, violations interval %ld affine %ld, "
               "width affine/interval %.3f over %d ranges (%d unbounded)\n", name,
               s == H_PLANE ? "plane" : "sphere", st.samples, RANGES, st.ia_violations,
               st.aa_violations, ratio, st.ratios, st.unbounded);
        assert_int_equal(st.ia_violations, 0);
        assert_int_equal(st.aa_violations, 0);
        ratio_sum += ratio;
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
    return ratio_sum / 2;
}

static double check_shader(const char *name, sl_global g)
{
    return check_program(h_compile_library(name), name, g, NULL);
}

/*
 * Transforms by the named spaces (issue 24: the affine mode takes each
 * row of a matrix of constants as one linear combination): points,
 * vectors and normals of the surface through a rotated, scaled and
 * translated "shader" space and a projective one, each component
 * enclosing the float samples; with the identity (the library shaders'
 * tests above) a row or column taken for another would go unseen.
 */
static void test_transforms_by_spaces(void **state)
{
    (void)state;
    static sl_spaces sp;
    for (int k = 0; k < SL_SPACE__COUNT; k++)
        sp.to_current[k] = sp.from_current[k] = mat4_identity();
    mat4 rot = mat4_mul(mat4_rotate(37.0, 0.3, -1.0, 0.6), mat4_scale(1.5, 0.25, 3.0));
    sp.to_current[SL_SPACE_SHADER] = mat4_mul(mat4_translate(0.7, -2.0, 0.4), rot);
    mat4_invert(&sp.to_current[SL_SPACE_SHADER], &sp.from_current[SL_SPACE_SHADER]);
    sp.to_current[SL_SPACE_OBJECT] = sp.to_current[SL_SPACE_SHADER];
    sp.to_current[SL_SPACE_OBJECT].m[3][0] = 0.05;     /* projective: w = 1 + 0.05 x */
    sp.to_current[SL_SPACE_OBJECT].m[3][2] = -0.02;
    mat4_invert(&sp.to_current[SL_SPACE_OBJECT], &sp.from_current[SL_SPACE_OBJECT]);
    static const char *bodies[] = {
        "P = transform(\"shader\", P) + 0.1 * vector(u, v, u * v);",
        "P = vtransform(\"shader\", vector(P) * (1 + u));",
        "P = vector(ntransform(\"shader\", N * (2 - v)));",
        "P = transform(\"shader\", \"current\", P * u);",
        "P = transform(\"object\", P);",
    };
    for (size_t i = 0; i < sizeof bodies / sizeof bodies[0]; i++) {
        char src[512];
        snprintf(src, sizeof src, "displacement t() { %s }", bodies[i]);
        char name[16];
        snprintf(name, sizeof name, "xform%zu", i);
        check_program(h_compile(src), name, SL_G_P, &sp);
    }
}

static void test_wave(void **state) { (void)state; assert_true(check_shader("wave", SL_G_P) < 1); }
static void test_nail(void **state) { (void)state; check_shader("nail", SL_G_P); }
static void test_ufo(void **state) { (void)state; assert_true(check_shader("ufo", SL_G_P) < 1); }
static void test_threads(void **state) { (void)state; assert_true(check_shader("threads", SL_G_P) < 1); }
static void test_dented(void **state) { (void)state; assert_true(check_shader("dented", SL_G_P) < 1); }
static void test_lumpy(void **state) { (void)state; assert_true(check_shader("lumpy", SL_G_P) < 1); }
static void test_matte(void **state) { (void)state; check_shader("matte", SL_G_Ci); }
static void test_plastic(void **state) { (void)state; check_shader("plastic", SL_G_Ci); }
static void test_metal(void **state) { (void)state; check_shader("metal", SL_G_Ci); }
static void test_wood(void **state) { (void)state; check_shader("wood", SL_G_Ci); }
static void test_granite(void **state) { (void)state; check_shader("granite", SL_G_Ci); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_case_splits),
        cmocka_unit_test(test_case_splits_same_value),
        cmocka_unit_test(test_case_splits_branches),
        cmocka_unit_test(test_undecided_if_merges),
        cmocka_unit_test(test_undecided_conditional_expression),
        cmocka_unit_test(test_undecided_loop),
        cmocka_unit_test(test_early_return_bound),
        cmocka_unit_test(test_return_in_loop),
        cmocka_unit_test(test_affine_decides_correlated_comparison),
        cmocka_unit_test(test_flags_reach_P),
        cmocka_unit_test(test_uniform_parameter_in_condition),
        cmocka_unit_test(test_random_programs),
        cmocka_unit_test(test_transforms_by_spaces),
        cmocka_unit_test(test_wave),
        cmocka_unit_test(test_nail),
        cmocka_unit_test(test_ufo),
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_dented),
        cmocka_unit_test(test_lumpy),
        cmocka_unit_test(test_matte),
        cmocka_unit_test(test_plastic),
        cmocka_unit_test(test_metal),
        cmocka_unit_test(test_wood),
        cmocka_unit_test(test_granite),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

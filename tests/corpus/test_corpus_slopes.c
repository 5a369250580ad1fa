/*
 * test_corpus_slopes.c: the slope bounds the hit proofs rest on
 * (trace_surface_slopes, sl_vm_run_slopes; trace/prove.h) for every
 * shader of tests/shaders/corpus, on the surfaces whose normal has known
 * slopes (plane, sphere, bilinear patch). Over random cells (sides 1/2
 * to 1/512 of the domain, the cell widened as the proofs widen it), where
 * the run gives bounds, the displaced P and its true derivatives d/du and
 * d/dv from the renderer's point path (trace_surface_point_eval, dual
 * mode) at a 3 x 3 grid and random points of the cell must lie inside
 * them, and every difference quotient of P along u and along v between
 * two points of the cell too (the mean value theorem: that is what the
 * Krawczyk test uses, and what a jump the bounds missed breaks). The
 * slack is the point path's rounding: a relative 1e-9 of the values.
 *
 * The corpus's height maps and filter widths (texture() through s and t,
 * Dv(t) * dv of a linear t) must get bounds on most cells: they are what
 * the proofs of a terrain need (issue 24). Prints per shader and surface
 * the cells with bounds and the samples checked.
 *
 *   AAFARM_CORPUS_ONLY   comma-separated shader names to run (default all)
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "corpus.h"
#include "geom/surface.h"
#include "trace/displace.h"
#include "trace/mesh.h"

enum { CELLS = 400, GRID = 3, RANDOM_POINTS = 8 };

static corpus C;

static int setup(void **state) { return corpus_group_load(&C, state); }
static int teardown(void **state) { return corpus_group_free(&C, state); }

typedef struct tally {
    long cells, bounded, points, quotients, violations;
    char first[256];
} tally;

static bool inside(double x, ia_interval r)
{
    double slack = 1e-9 * (fabs(x) + fmax(fabs(r.lo), fabs(r.hi))) + 1e-300;
    return x >= r.lo - slack && x <= r.hi + slack;
}

static void violation(tally *t, const char *what, double u, double v, int i, double x,
                      ia_interval r)
{
    if (!t->violations++)
        snprintf(t->first, sizeof t->first, "%s[%d] = %.17g at (%.9f, %.9f) outside [%.17g, %.17g]",
                 what, i, x, u, v, r.lo, r.hi);
}

static void check_cell(trace_thread *th, const trace_object *obj, const double X[4], tally *t,
                       corpus_rng *rng)
{
    ia_interval P[3], Pu[3], Pv[3];
    t->cells++;
    if (!trace_surface_slopes(th, obj, X[0], X[1], X[2], X[3], P, Pu, Pv)) {
        th->failed = false;
        return;
    }
    t->bounded++;
    enum { N = GRID * GRID + RANDOM_POINTS };
    double us[N], vs[N];
    vec3 ps[N];
    int n = 0;
    for (int k = 0; k < N; k++) {
        double fu = k < GRID * GRID ? (k % GRID) / (GRID - 1.0) : corpus_rng_uniform(rng);
        double fv = k < GRID * GRID ? (k / GRID) / (GRID - 1.0) : corpus_rng_uniform(rng);
        double u = X[0] + fu * (X[1] - X[0]), v = X[2] + fv * (X[3] - X[2]);
        if (!geom_uv_inside(&obj->surf, u, v)) continue;
        trace_surface_point sp;
        trace_surface_point_eval(th, obj, u, v, &sp);
        if (th->failed) {
            th->failed = false;
            continue;
        }
        double p[3] = {sp.P.x, sp.P.y, sp.P.z}, pu[3] = {sp.Pu.x, sp.Pu.y, sp.Pu.z};
        double pv[3] = {sp.Pv.x, sp.Pv.y, sp.Pv.z};
        for (int i = 0; i < 3; i++) {
            t->points++;
            if (!inside(p[i], P[i])) violation(t, "P", u, v, i, p[i], P[i]);
            if (!inside(pu[i], Pu[i])) violation(t, "dP/du", u, v, i, pu[i], Pu[i]);
            if (!inside(pv[i], Pv[i])) violation(t, "dP/dv", u, v, i, pv[i], Pv[i]);
        }
        us[n] = u;
        vs[n] = v;
        ps[n++] = sp.P;
    }
    /* quotients between pairs on a line of constant v (or u): the grid's
     * rows and columns */
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++) {
            int axis = vs[a] == vs[b] ? 0 : us[a] == us[b] ? 1 : -1;
            if (axis < 0) continue;
            double h = axis ? vs[b] - vs[a] : us[b] - us[a];
            if (!(fabs(h) > 0)) continue;
            double pa[3] = {ps[a].x, ps[a].y, ps[a].z}, pb[3] = {ps[b].x, ps[b].y, ps[b].z};
            for (int i = 0; i < 3; i++) {
                double q = (pb[i] - pa[i]) / h;
                /* the two points' rounding, over h */
                double err = 1e-12 * (fabs(pa[i]) + fabs(pb[i]) + 1.0) / fabs(h);
                ia_interval r = axis ? Pv[i] : Pu[i];
                t->quotients++;
                if (!(q >= r.lo - err && q <= r.hi + err))
                    violation(t, axis ? "quotient along v" : "quotient along u", us[a], vs[a], i,
                              q, r);
            }
        }
}

static void run(corpus_surface s, tally *total, long *rows_with_bounds)
{
    for (int i = 0; i < C.nshaders; i++) {
        fixture f;
        if (!corpus_open(&f, &C, &C.shaders[i], s, TRACE_ARITH_AFFINE, 32, 24, false)) {
            fixture_close(&f);
            fail_msg("%s on %s did not open", C.shaders[i].name, corpus_surface_name(s));
        }
        trace_thread *th = trace_thread_new(&f.js->world);
        trace_view *view = malloc(sizeof *view);
        const trace_object *obj = trace_object_piece(th, &f.js->world.objects[0], 0, view);
        assert_non_null(obj);
        tally t;
        memset(&t, 0, sizeof t);
        corpus_rng rng = {0x510be5u + (uint64_t)i * 7 + (uint64_t)s};
        for (int k = 0; k < CELLS; k++) {
            double size = ldexp(1.0, -(1 + (int)(corpus_rng_uniform(&rng) * 9)));
            double u0 = corpus_rng_uniform(&rng) * (1 - size);
            double v0 = corpus_rng_uniform(&rng) * (1 - size);
            double X[4] = {u0, u0 + size, v0, v0 + size};
            check_cell(th, obj, X, &t, &rng);
        }
        printf("%-20s %-9s %5ld cells %5ld with slope bounds %7ld samples %7ld quotients %ld "
               "violations%s\n",
               C.shaders[i].name, corpus_surface_name(s), t.cells, t.bounded, t.points,
               t.quotients, t.violations, t.violations ? "  FAIL" : "");
        if (t.violations) printf("    first: %s\n", t.first);
        total->cells += t.cells;
        total->bounded += t.bounded;
        total->points += t.points;
        total->quotients += t.quotients;
        total->violations += t.violations;
        *rows_with_bounds += t.bounded > t.cells / 2;
        free(view);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
}

/* a shader's bounds on the plane, by name: how many of its cells */
static long bounded_cells(const char *name)
{
    for (int i = 0; i < C.nshaders; i++) {
        if (strcmp(C.shaders[i].name, name)) continue;
        fixture f;
        assert_true(corpus_open(&f, &C, &C.shaders[i], CORPUS_PLANE, TRACE_ARITH_AFFINE, 32, 24,
                                false));
        trace_thread *th = trace_thread_new(&f.js->world);
        trace_view *view = malloc(sizeof *view);
        const trace_object *obj = trace_object_piece(th, &f.js->world.objects[0], 0, view);
        long n = 0;
        for (int k = 0; k < 32; k++) {
            double size = 1.0 / 64, u0 = 0.1 + 0.025 * k, v0 = 0.3;
            ia_interval P[3], Pu[3], Pv[3];
            n += trace_surface_slopes(th, obj, u0, u0 + size, v0, v0 + size, P, Pu, Pv);
            th->failed = false;
        }
        free(view);
        trace_thread_destroy(&th);
        fixture_close(&f);
        return n;
    }
    return -1;                            /* not in the corpus (AAFARM_CORPUS_ONLY) */
}

static void test_slopes_enclose(void **state)
{
    (void)state;
    static const corpus_surface surfaces[] = {CORPUS_PLANE, CORPUS_SPHERE, CORPUS_PATCH};
    tally total;
    memset(&total, 0, sizeof total);
    long rows_with_bounds = 0;
    for (size_t k = 0; k < sizeof surfaces / sizeof surfaces[0]; k++)
        run(surfaces[k], &total, &rows_with_bounds);
    printf("total: %ld cells, %ld with slope bounds (%ld shader x surface rows with most), %ld "
           "samples, %ld quotients, %ld violations\n",
           total.cells, total.bounded, rows_with_bounds, total.points, total.quotients,
           total.violations);
    assert_int_equal(total.violations, 0);
    assert_true(total.points > 0 && total.quotients > 0);
}

/* the height map and the filter widths have bounds: a lookup at one
 * footprint through linear s and t (tex_heightmap), and Dv(t) * dv
 * feeding clamps (fw_grooves' filterstep) */
static void test_maps_and_widths_have_slopes(void **state)
{
    (void)state;
    const char *names[] = {"tex_heightmap", "fw_grooves"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        long n = bounded_cells(names[k]);
        printf("%s: %ld of 32 cells with slope bounds\n", names[k], n);
        if (n >= 0) assert_true(n >= 24);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slopes_enclose),
        cmocka_unit_test(test_maps_and_widths_have_slopes),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

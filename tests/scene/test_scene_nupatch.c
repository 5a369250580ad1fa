/*
 * tests/scene/test_scene_nupatch.c: NuPatch (common/scene/rib_nupatch.c).
 * Each knot interval becomes one bicubic Bezier patch; its points are
 * compared with the spline surface evaluated independently here by the
 * Cox-de Boor recursion (the textbook definition of the basis functions)
 * at random (u,v) of every piece: clamped and uniform knots, several
 * pieces, order 2 and 3 raised to cubic, a partial [umin, umax] range,
 * "Pw" with equal weights; orders 5 and 6 (GEOM_NURBS pieces). A rational
 * quarter circle lies on the exact circle. Weights <= 0, orders above 16,
 * bad knots, ranges and degenerate pieces are errors with file:line:col;
 * TrimCurve warns once. (tests/geom/test_geom_nurbs checks the rational
 * pieces against de Boor.)
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"

/* N_{i,p}(t), right-open intervals (t inside the domain, not at a knot) */
static double cox_de_boor(const double *U, int i, int p, double t)
{
    if (p == 0)
        return U[i] <= t && t < U[i + 1] ? 1 : 0;
    double a = 0, b = 0;
    if (U[i + p] > U[i])
        a = (t - U[i]) / (U[i + p] - U[i]) * cox_de_boor(U, i, p - 1, t);
    if (U[i + p + 1] > U[i + 1])
        b = (U[i + p + 1] - t) / (U[i + p + 1] - U[i + 1]) * cox_de_boor(U, i + 1, p - 1, t);
    return a + b;
}

typedef struct spline {
    int nu, ou, nv, ov;
    double ku[32], kv[32], umin, umax, vmin, vmax;
    vec3 P[64];
} spline;

static vec3 spline_at(const spline *s, double u, double v)
{
    vec3 r = v3(0, 0, 0);
    for (int j = 0; j < s->nv; j++)
        for (int i = 0; i < s->nu; i++) {
            double w = cox_de_boor(s->ku, i, s->ou - 1, u) * cox_de_boor(s->kv, j, s->ov - 1, v);
            r = v3_add(r, v3_scale(s->P[j * s->nu + i], w));
        }
    return r;
}

static size_t nums(char *out, size_t n, const double *v, int count)
{
    size_t used = (size_t)snprintf(out, n, "[");
    for (int i = 0; i < count; i++)
        used += (size_t)snprintf(out + used, n - used, "%.17g ", v[i]);
    return used + (size_t)snprintf(out + used, n - used, "]");
}

/* Parses the NuPatch of s and checks every piece against spline_at. */
static void check(const spline *s, int want_pieces)
{
    char text[16384], a[1024], b[1024];
    nums(a, sizeof a, s->ku, s->nu + s->ou);
    nums(b, sizeof b, s->kv, s->nv + s->ov);
    size_t used = (size_t)snprintf(text, sizeof text, CAMERA "WorldBegin\nNuPatch %d %d %s "
                                   "%.17g %.17g %d %d %s %.17g %.17g \"P\" [", s->nu, s->ou, a,
                                   s->umin, s->umax, s->nv, s->ov, b, s->vmin, s->vmax);
    for (int k = 0; k < s->nu * s->nv; k++)
        used += (size_t)snprintf(text + used, sizeof text - used, "%.17g %.17g %.17g ",
                                 s->P[k].x, s->P[k].y, s->P[k].z);
    snprintf(text + used, sizeof text - used, "]\nWorldEnd\n");
    sl_diag *d;
    scene *sc = parse_rib(text, &d);
    if (!sc)
        sl_diag_print(d, stderr);
    assert_non_null(sc);
    assert_int_equal(sc->nobjects, want_pieces);
    /* the pieces in order: u intervals fastest; find each one's range */
    double bu[32], bv[32];
    int nbu = 0, nbv = 0;
    bu[nbu++] = s->umin;
    for (int k = 0; k < s->nu + s->ou; k++)
        if (s->ku[k] > bu[nbu - 1] && s->ku[k] < s->umax)
            bu[nbu++] = s->ku[k];
    bu[nbu++] = s->umax;
    bv[nbv++] = s->vmin;
    for (int k = 0; k < s->nv + s->ov; k++)
        if (s->kv[k] > bv[nbv - 1] && s->kv[k] < s->vmax)
            bv[nbv++] = s->kv[k];
    bv[nbv++] = s->vmax;
    assert_int_equal((nbu - 1) * (nbv - 1), want_pieces);
    uint64_t seed = 7;
    for (int pv = 0; pv < nbv - 1; pv++)
        for (int pu = 0; pu < nbu - 1; pu++) {
            const geom_surface *g = sc->objects[pv * (nbu - 1) + pu].surface;
            assert_int_equal(g->kind, s->ou > 4 || s->ov > 4 ? GEOM_NURBS : GEOM_BICUBIC);
            for (int k = 0; k < 20; k++) {
                seed = seed * 6364136223846793005ull + 1442695040888963407ull;
                double lu = 0.02 + 0.96 * ((seed >> 11) & 0xffff) / 65536.0;
                double lv = 0.02 + 0.96 * ((seed >> 30) & 0xffff) / 65536.0;
                double u = bu[pu] + lu * (bu[pu + 1] - bu[pu]);
                double v = bv[pv] + lv * (bv[pv + 1] - bv[pv]);
                geom_sample got;
                geom_eval(g, lu, lv, &got);
                vec3 want = spline_at(s, u, v);
                if (!(vec_dist(got.P, want) < 1e-9))
                    fail_msg("piece (%d,%d) at (%g,%g): got (%g %g %g) want (%g %g %g)", pu, pv,
                             u, v, got.P.x, got.P.y, got.P.z, want.x, want.y, want.z);
            }
        }
    scene_destroy(&sc);
    sl_diag_destroy(&d);
}

static void grid_points(spline *s)
{
    for (int j = 0; j < s->nv; j++)
        for (int i = 0; i < s->nu; i++)
            s->P[j * s->nu + i] = v3(i, j, ((i * 5 + j * 3) % 7) / 5.0);
}

static void test_pieces(void **state)
{
    (void)state;
    /* clamped cubic: one Bezier piece */
    spline s = { 4, 4, 4, 4, { 0, 0, 0, 0, 1, 1, 1, 1 }, { 0, 0, 0, 0, 1, 1, 1, 1 }, 0, 1, 0, 1,
                 { { 0, 0, 0 } } };
    grid_points(&s);
    check(&s, 1);
    /* uniform cubic, 6 x 5 points: 3 x 2 pieces */
    spline t = { 6, 4, 5, 4, { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9 }, { 0, 1, 2, 3, 4, 5, 6, 7, 8 },
                 3, 6, 3, 5, { { 0, 0, 0 } } };
    grid_points(&t);
    check(&t, 6);
    /* a partial range: u in [3.5, 5.25] spans 3 pieces (two cut), v [3, 4] one */
    t.umin = 3.5, t.umax = 5.25, t.vmin = 3, t.vmax = 4;
    check(&t, 3);
    /* order 2 in u (bilinear pieces) and 3 in v, non-uniform knots with a
     * double knot */
    spline q = { 4, 2, 5, 3, { 0, 0, 1, 2.5, 4, 4 }, { 0, 0, 0, 1, 1, 3, 3, 3 }, 0, 4, 0, 3,
                 { { 0, 0, 0 } } };
    grid_points(&q);
    check(&q, 3 * 2);
}

static void test_pw_and_trim(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        "TrimCurve [1] [2] [0 0 1 1] [0] [1] [2] [0 1] [0 1] [1 1]\n"
        "NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [0 0 0 2  2 0 0 2  0 2 0 2  2 2 2 2]\n"
        "TrimCurve [1] [2] [0 0 1 1] [0] [1] [2] [0 1] [0 1] [1 1]\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 1);
    assert_int_equal(sl_diag_warning_count(d), 1);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_WARNING, 0)),
                           "t.rib:4:1: TrimCurve: trim curves are not supported"));
    geom_sample g;
    geom_eval(s->objects[0].surface, 1, 1, &g);
    assert_true(vec_dist(g.P, v3(1, 1, 1)) < 1e-12);     /* (2 2 2) / 2 */
    geom_eval(s->objects[0].surface, 0.5, 0.5, &g);
    assert_true(vec_dist(g.P, v3(0.5, 0.5, 0.25)) < 1e-12);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

/* orders above 4 (GEOM_NURBS pieces) against the same de Boor */
static void test_high_order(void **state)
{
    (void)state;
    spline s = { 7, 5, 6, 6, { 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3 },
                 { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11 }, 0, 3, 5, 6, { { 0, 0, 0 } } };
    grid_points(&s);
    check(&s, 3);
}

/* A rational quadratic quarter circle (middle weight sqrt(2)/2), extruded:
 * one GEOM_NURBS piece on the exact unit circle. */
static void test_rational_circle(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = parse_rib(WORLD(
        "NuPatch 3 3 [0 0 0 1 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [1 0 0 1  "
        "0.70710678118654752 0.70710678118654752 0 0.70710678118654752  0 1 0 1  "
        "1 0 2 1  0.70710678118654752 0.70710678118654752 1.4142135623730950 "
        "0.70710678118654752  0 1 2 1]\n"), &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 1);
    assert_int_equal(s->nnurbs, 1);
    const geom_surface *g = s->objects[0].surface;
    assert_int_equal(g->kind, GEOM_NURBS);
    for (int i = 0; i <= 20; i++)
        for (int j = 0; j <= 4; j++) {
            geom_sample e;
            geom_eval(g, i / 20.0, j / 4.0, &e);
            assert_true(fabs(hypot(e.P.x, e.P.y) - 1) < 1e-15);
            assert_true(fabs(e.P.z - 2 * j / 4.0) < 1e-15);
        }
    geom_sample e;
    geom_eval(g, 0.5, 0, &e);          /* the middle of the arc: 45 degrees */
    assert_true(fabs(e.P.x - e.P.y) < 1e-15);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static const error_case cases[] = {
    { WORLD("NuPatch 17 17 [0 0 0 0 0 1 1 1 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 0]\n"),
      "t.rib:4:9: NuPatch: uorder must be 2 to 16 (orders above 16 are not supported) and "
      "nu at least the order, got nu 17, uorder 17" },
    { WORLD("NuPatch 2 2 [0 1 0 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 0]\n"),
      "t.rib:4:13: NuPatch: uknot must be finite and nondecreasing (entry 2 is 0)" },
    { WORLD("NuPatch 2 2 [0 0 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 0]\n"),
      "t.rib:4:13: NuPatch: uknot needs nu + uorder = 4 numbers, got 3" },
    { WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] -1 1 \"P\" [0 0 0]\n"),
      "t.rib:4:41: NuPatch: vmin vmax must satisfy 0 <= vmin < vmax <= 1 (the knots' domain), "
      "got -1 1" },
    { WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 0  1 0 0  0 1 0]\n"),
      "t.rib:4:45: NuPatch: \"P\" needs nu x nv = 4 points, got 3" },
    { WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [0 0 0 1  1 0 0 1  0 1 0 -2  "
            "1 1 0 1]\n"),
      "t.rib:4:45: NuPatch: \"Pw\" point 2 has weight -2: every weight must be a finite number "
      "> 0 (\"Pw\" is x*w y*w z*w w)" },
    { WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [0 0 0 0  1 0 0 1  0 1 0 1  "
            "1 1 0 1]\n"),
      "t.rib:4:45: NuPatch: \"Pw\" point 0 has weight 0: every weight must be a finite number "
      "> 0 (\"Pw\" is x*w y*w z*w w)" },
    { WORLD("NuPatch 3 3 [0 0 0 1 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [0 0 0 1  1 0 0 0.5  2 0 0 1  "
            "3 0 0 1  1 0 0 0.25  5 0 0 1]\n"),
      "t.rib:4:1: NuPatch: piece (0, 0) over u [0, 1], v [0, 1] is degenerate: its points lie "
      "on one line" },
};

static void test_errors(void **state)
{
    (void)state;
    expect_first_errors(cases, sizeof cases / sizeof cases[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pieces),
        cmocka_unit_test(test_pw_and_trim),
        cmocka_unit_test(test_high_order),
        cmocka_unit_test(test_rational_circle),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

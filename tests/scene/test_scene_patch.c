/*
 * tests/scene/test_scene_patch.c: bicubic patches (common/scene/
 * rib_patch.c). For each basis (bezier, b-spline, catmull-rom, hermite,
 * power, an explicit matrix) the GEOM_BICUBIC that Patch "bicubic" makes
 * evaluates to the basis' own formula, written here from the RI spec's
 * blending functions; PatchMesh counts its patches (steps, periodic and
 * nonperiodic wrapping) and its b-spline patches meet continuously;
 * bilinear PatchMesh; Basis is an attribute; errors with file:line:col.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "scene_testing.h"

#define WORLD(body) CAMERA "WorldBegin\n" body "WorldEnd\n"

/* 16 points of a bumpy grid, u fastest: x = i, y = j, z = (i*7 + j*3) % 5 / 4 */
static void grid(vec3 g[16], char *text, size_t n)
{
    size_t used = (size_t)snprintf(text, n, "\"P\" [");
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            g[4 * j + i] = v3(i, j, ((i * 7 + j * 3) % 5) / 4.0);
            used += (size_t)snprintf(text + used, n - used, "%d %d %.17g ", i, j,
                                     g[4 * j + i].z);
        }
    snprintf(text + used, n - used, "]");
}

typedef void (*blend_fn)(double t, double w[4]);

static void blend_bspline(double t, double w[4])
{
    double s = 1 - t;
    w[0] = s * s * s / 6;
    w[1] = (3 * t * t * t - 6 * t * t + 4) / 6;
    w[2] = (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6;
    w[3] = t * t * t / 6;
}

static void blend_catmull_rom(double t, double w[4])
{
    w[0] = 0.5 * (-t * t * t + 2 * t * t - t);
    w[1] = 0.5 * (3 * t * t * t - 5 * t * t + 2);
    w[2] = 0.5 * (-3 * t * t * t + 4 * t * t + t);
    w[3] = 0.5 * (t * t * t - t * t);
}

/* geometry P0, T0, P1, T1 */
static void blend_hermite(double t, double w[4])
{
    w[0] = 2 * t * t * t - 3 * t * t + 1;
    w[1] = t * t * t - 2 * t * t + t;
    w[2] = -2 * t * t * t + 3 * t * t;
    w[3] = t * t * t - t * t;
}

/* geometry: the coefficients of t^3, t^2, t, 1 */
static void blend_power(double t, double w[4])
{
    w[0] = t * t * t, w[1] = t * t, w[2] = t, w[3] = 1;
}

static void blend_bezier(double t, double w[4])
{
    double s = 1 - t;
    w[0] = s * s * s, w[1] = 3 * s * s * t, w[2] = 3 * s * t * t, w[3] = t * t * t;
}

static void check_basis(const char *basis, blend_fn blend)
{
    vec3 g[16];
    char pts[1024], text[2048];
    grid(g, pts, sizeof pts);
    snprintf(text, sizeof text, WORLD("Basis %s %s\nPatch \"bicubic\" %s\n"), basis, basis, pts);
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 1);
    assert_int_equal(s->objects[0].surface->kind, GEOM_BICUBIC);
    for (int k = 0; k < 25; k++) {
        double u = (k % 5) / 4.0, v = (k / 5) / 4.0, wu[4], wv[4];
        blend(u, wu);
        blend(v, wv);
        vec3 want = v3(0, 0, 0);
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++)
                want = v3_add(want, v3_scale(g[4 * j + i], wu[i] * wv[j]));
        geom_sample got;
        geom_eval(s->objects[0].surface, u, v, &got);
        if (!(vec_dist(got.P, want) < 1e-12))
            fail_msg("%s at (%g, %g): got (%g %g %g), want (%g %g %g)", basis, u, v,
                     got.P.x, got.P.y, got.P.z, want.x, want.y, want.z);
    }
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_bases(void **state)
{
    (void)state;
    check_basis("\"bezier\" 3", blend_bezier);
    check_basis("\"b-spline\" 1", blend_bspline);
    check_basis("\"catmull-rom\" 1", blend_catmull_rom);
    check_basis("\"hermite\" 2", blend_hermite);
    check_basis("\"power\" 4", blend_power);
    /* an explicit matrix: the b-spline's, times 6 over 6 */
    check_basis("[-0.16666666666666666 0.5 -0.5 0.16666666666666666  0.5 -1 0.5 0 "
                "-0.5 0 0.5 0  0.16666666666666666 0.66666666666666663 0.16666666666666666 0] 1",
                blend_bspline);
}

/* A b-spline PatchMesh: 6 x 5 points nonperiodic in u (3 patches), periodic
 * in v (5 patches); neighbouring patches meet. */
static void test_patch_mesh(void **state)
{
    (void)state;
    char text[8192];
    size_t used = (size_t)snprintf(text, sizeof text, CAMERA "WorldBegin\nAttributeBegin\n"
                                   "Basis \"b-spline\" 1 \"b-spline\" 1\n"
                                   "PatchMesh \"bicubic\" 6 \"nonperiodic\" 5 \"periodic\" \"P\" [");
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 6; i++) {
            double a = 2 * M_PI * j / 5;
            used += (size_t)snprintf(text + used, sizeof text - used, "%g %g %g ",
                                     (2 + 0.3 * (i % 2)) * cos(a), (2 + 0.3 * (i % 2)) * sin(a),
                                     (double)i);
        }
    snprintf(text + used, sizeof text - used, "]\nAttributeEnd\n"
             "PatchMesh \"bilinear\" 3 \"periodic\" 2 \"nonperiodic\" \"P\" [0 0 0 1 0 0 0 1 0 "
             "0 0 1 1 0 1 0 1 1]\n"
             "Patch \"bicubic\" \"P\" [0 0 0 1 0 0 2 0 0 3 0 0  0 1 0 1 1 1 2 1 1 3 1 0 "
             "0 2 0 1 2 1 2 2 1 3 2 0  0 3 0 1 3 0 2 3 0 3 3 0]\nWorldEnd\n");
    sl_diag *d;
    scene *s = parse_rib(text, &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 15 + 3 + 1);
    for (int k = 0; k < 15; k++)
        assert_int_equal(s->objects[k].surface->kind, GEOM_BICUBIC);
    /* u neighbours: patch (pu, pv) at u = 1 meets (pu+1, pv) at u = 0 */
    for (int pv = 0; pv < 5; pv++)
        for (int pu = 0; pu < 2; pu++)
            for (int k = 0; k <= 4; k++) {
                geom_sample a, b;
                geom_eval(s->objects[pv * 3 + pu].surface, 1, k / 4.0, &a);
                geom_eval(s->objects[pv * 3 + pu + 1].surface, 0, k / 4.0, &b);
                assert_true(vec_dist(a.P, b.P) < 1e-12);
            }
    /* v wraps: the last row meets the first */
    for (int pu = 0; pu < 3; pu++) {
        geom_sample a, b;
        geom_eval(s->objects[4 * 3 + pu].surface, 0.5, 1, &a);
        geom_eval(s->objects[pu].surface, 0.5, 0, &b);
        assert_true(vec_dist(a.P, b.P) < 1e-12);
    }
    /* bilinear, periodic in u: 3 patches, the last closes back to point 0 */
    for (int k = 15; k < 18; k++)
        assert_int_equal(s->objects[k].surface->kind, GEOM_PATCH);
    assert_true(vec_dist(s->objects[17].surface->verts[1], v3(0, 0, 0)) == 0);
    /* the Basis ended with its AttributeEnd: the last patch is Bezier and
     * interpolates its corners */
    geom_sample c;
    geom_eval(s->objects[18].surface, 1, 1, &c);
    assert_true(vec_dist(c.P, v3(3, 3, 0)) < 1e-12);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static const error_case cases[] = {
    { WORLD("Basis \"bspline\" 1 \"b-spline\" 1\nSphere 1 -1 1 360\n"),
      "t.rib:4:7: Basis: unknown u basis \"bspline\" (expected \"bezier\", \"b-spline\", "
      "\"catmull-rom\", \"hermite\", \"power\" or 16 numbers)" },
    { WORLD("Basis \"bezier\" 3 [1 2 3] 1\nSphere 1 -1 1 360\n"),
      "t.rib:4:18: Basis: the v basis matrix needs 16 numbers, got 3" },
    { WORLD("Basis \"bezier\" 0 \"bezier\" 3\nSphere 1 -1 1 360\n"),
      "t.rib:4:16: Basis: the u step must be a whole number from 1 to 4" },
    { WORLD("PatchMesh \"bicubic\" 5 \"nonperiodic\" 4 \"nonperiodic\" \"P\" [0 0 0]\n"),
      "t.rib:4:21: PatchMesh: a nonperiodic u direction needs 4 + k*3 points (the step), "
      "got 5" },
    { WORLD("PatchMesh \"bicubic\" 4 \"nonperiodic\" 4 \"open\" \"P\" [0 0 0]\n"),
      "t.rib:4:39: PatchMesh: vwrap must be \"periodic\" or \"nonperiodic\", got \"open\"" },
    { WORLD("PatchMesh \"bilinear\" 2 \"nonperiodic\" 2 \"nonperiodic\" \"P\" [0 0 0 1 0 0]\n"),
      "t.rib:4:54: PatchMesh: \"P\" needs 2 x 2 = 4 points, got 2" },
    { WORLD("PatchMesh \"bicubic\" 4 \"nonperiodic\" 4 \"nonperiodic\" \"P\" [0 0 0 0 0 0 0 0 0 "
            "0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0]\n"),
      "t.rib:4:1: PatchMesh: bicubic patch is degenerate: its control points lie on one line" },
};

static void test_errors(void **state)
{
    (void)state;
    expect_first_errors(cases, sizeof cases / sizeof cases[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bases),
        cmocka_unit_test(test_patch_mesh),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * tests/geom/test_geom_prepare.c: parameter validation and polygons' (u,v).
 *
 *   reasons     bad parameters of every kind are rejected with the exact
 *               one-line reason; a NULL or short buffer is safe
 *   accepted    RenderMan's usual parameters (and slightly-over-360-degree
 *               sweeps from degree conversion) are accepted; names
 *   sphere phi  phi0/phi1 are asin(zmin/r), asin(zmax/r), clamped at the poles
 *   polygon     the plane basis: axis_u x axis_v along Newell's normal,
 *               orthogonal axes, vertices at their (u,v) in [0,1]^2, the
 *               rectangle tight (touching every side)
 *   coverage    geom_uv_inside and geom_uv_box_cover agree with dense
 *               sampling (OUTSIDE: no sample inside; INSIDE: all inside), and
 *               are decisive away from the boundary; other kinds: inside
 *   unknown     a kind that is none: NaN, entire, unbounded, no hit
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "geom_fixtures.h"

#define PI 3.14159265358979323846

static void expect_reason(geom_surface s, const char *want)
{
    char why[256];
    memset(why, 'x', sizeof why);
    bool ok = geom_surface_prepare(&s, why, sizeof why);
    if (ok)
        fail_msg("accepted, expected \"%s\"", want);
    if (strcmp(why, want) != 0)
        fail_msg("reason \"%s\", expected \"%s\"", why, want);
}

static void test_reasons(void **state)
{
    (void)state;
    geom_surface s;
    s = fx_default(GEOM_SPHERE); s.radius = -1;
    expect_reason(s, "sphere radius must be > 0, got -1");
    s = fx_default(GEOM_SPHERE); s.radius = NAN;
    expect_reason(s, "sphere radius must be a finite number, got nan");
    s = fx_default(GEOM_SPHERE); s.zmin = 0.5; s.zmax = 0.5;
    expect_reason(s, "sphere zmin and zmax must differ, both are 0.5 (nothing left)");
    s = fx_default(GEOM_SPHERE); s.zmin = 1; s.zmax = 2;
    expect_reason(s, "sphere zmin and zmax must not both be >= radius 1, got 1 and 2 (nothing left)");
    s = fx_default(GEOM_SPHERE); s.zmin = 2; s.zmax = 1;       /* either order */
    expect_reason(s, "sphere zmin and zmax must not both be >= radius 1, got 2 and 1 (nothing left)");
    s = fx_default(GEOM_SPHERE); s.zmin = -3; s.zmax = -1;
    expect_reason(s, "sphere zmin and zmax must not both be <= -radius -1, got -3 and -1 (nothing left)");
    s = fx_default(GEOM_SPHERE); s.zmin = 3; s.zmax = 2.5;     /* both clamped to the pole */
    expect_reason(s, "sphere zmin and zmax must not both be >= radius 1, got 3 and 2.5 (nothing left)");
    s = fx_default(GEOM_SPHERE); s.thetamax = 0;
    expect_reason(s, "sphere thetamax must not be 0");
    s = fx_default(GEOM_SPHERE); s.thetamax = 7;
    expect_reason(s, "sphere thetamax must be at most 2*pi (360 degrees) in magnitude, got 7");
    s = fx_default(GEOM_DISK); s.height = INFINITY;
    expect_reason(s, "disk height must be a finite number, got inf");
    s = fx_default(GEOM_CYLINDER); s.zmax = -1;
    expect_reason(s, "cylinder zmin and zmax must differ, both are -1 (nothing left)");
    s = fx_default(GEOM_CONE); s.height = 0;
    expect_reason(s, "cone height must not be 0");
    s = fx_default(GEOM_CONE); s.radius = 0;
    expect_reason(s, "cone radius must be > 0, got 0");
    s = fx_default(GEOM_PARABOLOID); s.zmin = -1;
    expect_reason(s, "paraboloid zmin must be >= 0, got -1");
    s = fx_default(GEOM_PARABOLOID); s.zmax = 0;
    expect_reason(s, "paraboloid zmax must be > 0, got 0");
    s = fx_default(GEOM_HYPERBOLOID); s.point2 = s.point1;
    expect_reason(s, "hyperboloid point1 and point2 must differ, both are (1 0 -1)");
    s = fx_default(GEOM_HYPERBOLOID); s.point1 = v3(0, 0, 0); s.point2 = v3(0, 0, 1);
    expect_reason(s, "hyperboloid point1 and point2 both lie on the z axis: the surface is a line");
    s = fx_default(GEOM_HYPERBOLOID); s.point1.y = NAN;
    expect_reason(s, "hyperboloid point1 must be finite numbers, got (1 nan -1)");
    s = fx_default(GEOM_TORUS); s.minorrad = -0.5;
    expect_reason(s, "torus minorradius must be > 0, got -0.5");
    s = fx_default(GEOM_TORUS); s.phimin = 1; s.phimax = 1;
    expect_reason(s, "torus phimin and phimax must differ, both are 1 (nothing left)");
    s = fx_default(GEOM_TORUS); s.phimin = -4; s.phimax = 4;
    expect_reason(s, "torus phimax - phimin must be at most 2*pi (360 degrees) in magnitude, got 8");
    s = fx_default(GEOM_TORUS); s.phimin = 4; s.phimax = -4;
    expect_reason(s, "torus phimax - phimin must be at most 2*pi (360 degrees) in magnitude, got -8");
    s = fx_default(GEOM_PARABOLOID); s.zmin = 1; s.zmax = -0.5;
    expect_reason(s, "paraboloid zmax must be > 0, got -0.5");
    s = fx_default(GEOM_POLYGON); s.nverts = 2;
    expect_reason(s, "polygon needs 3 to 64 vertices, got 2");
    s = fx_default(GEOM_POLYGON); s.nverts = 65;
    expect_reason(s, "polygon needs 3 to 64 vertices, got 65");
    s = fx_default(GEOM_POLYGON); s.verts[2].z = NAN;
    expect_reason(s, "polygon vertex 2 must be finite numbers, got (1 1 nan)");
    s = fx_default(GEOM_POLYGON); s.verts[2] = s.verts[1]; s.verts[3] = s.verts[0];
    expect_reason(s, "polygon needs at least 3 distinct vertices, got 2");
    s = fx_default(GEOM_POLYGON); s.verts[2] = v3(2, 0, 0); s.verts[3] = v3(3, 0, 0);
    expect_reason(s, "polygon has no area: its vertices lie on one line");
    s = fx_default(GEOM_POLYGON); s.verts[2].z = 0.5;
    expect_reason(s, "polygon is not planar: vertex 0 lies 0.117851 off its plane");
    s = fx_default(GEOM_POLYGON); s.verts[2] = v3(0.3, 0.3, 0);   /* dart */
    expect_reason(s, "polygon is not convex: it turns the other way at vertex 2");
    s = fx_default(GEOM_POLYGON);                   /* pentagram: all left turns */
    s.nverts = 5;
    for (int i = 0; i < 5; i++)
        s.verts[i] = v3(cos(4 * PI * i / 5), sin(4 * PI * i / 5), 0);
    expect_reason(s, "polygon is not convex: its edges cross (vertex 3 lies outside the edge "
                     "from vertex 0 to vertex 1)");
    s = fx_default(GEOM_POLYGON);                   /* bow tie */
    s.verts[2] = v3(0, 1, 0); s.verts[3] = v3(1, 1, 0);
    expect_reason(s, "polygon has no area: its vertices lie on one line");
    s = fx_default(GEOM_PATCH); s.nverts = 3;
    expect_reason(s, "patch needs 4 corners (P00 P10 P01 P11), got 3");
    s = fx_default(GEOM_PATCH); s.verts[1].x = INFINITY;
    expect_reason(s, "patch corner 1 must be finite numbers, got (inf 0 0)");
    s = fx_default(GEOM_PATCH);
    s.verts[1] = v3(1, 1, 1); s.verts[2] = v3(2, 2, 2); s.verts[3] = v3(3, 3, 3);
    expect_reason(s, "patch is degenerate: its corners lie on one line");
    s = fx_default(GEOM_SPHERE); s.kind = (geom_kind)42;
    expect_reason(s, "unknown surface kind 42");
}

static void test_reason_buffers(void **state)
{
    (void)state;
    geom_surface s = fx_default(GEOM_SPHERE);
    s.radius = -1;
    assert_false(geom_surface_prepare(&s, NULL, 0));
    char tiny[8];
    assert_false(geom_surface_prepare(&s, tiny, sizeof tiny));
    assert_string_equal(tiny, "sphere ");
    s.radius = 1;
    char why[64] = "stale";
    assert_true(geom_surface_prepare(&s, why, sizeof why));
    assert_string_equal(why, "");
}

static void test_accepted(void **state)
{
    (void)state;
    for (int k = 0; k < GEOM__COUNT; k++) {
        if (k == GEOM_SUBDIV) continue;    /* needs a mesh: test_geom_subdiv */
        if (k == GEOM_NURBS) continue;     /* needs a NuPatch: test_geom_nurbs */
        geom_surface s = fx_default((geom_kind)k);
        char why[200];
        if (!geom_surface_prepare(&s, why, sizeof why))
            fail_msg("%s: %s", geom_kind_name((geom_kind)k), why);
        s.thetamax = 360 * (PI / 180) * (1 + 1e-15);   /* degrees, rounded */
        assert_true(geom_surface_prepare(&s, why, sizeof why));
        s.thetamax = -0.5;
        assert_true(geom_surface_prepare(&s, why, sizeof why));
    }
    static const char *const names[] = { "sphere", "disk", "cylinder", "cone",
                                         "paraboloid", "hyperboloid", "torus",
                                         "polygon", "patch", "bicubic patch",
                                         "subdivision face", "NuPatch piece" };
    for (int k = 0; k < GEOM__COUNT; k++)
        assert_string_equal(geom_kind_name((geom_kind)k), names[k]);
    assert_string_equal(geom_kind_name(GEOM__COUNT), "unknown");
    assert_string_equal(geom_kind_name((geom_kind)-1), "unknown");
}

static void test_sphere_phi(void **state)
{
    (void)state;
    geom_surface s = fx_default(GEOM_SPHERE);
    s.radius = 2;
    s.zmin = -5;
    s.zmax = 1;
    assert_true(geom_surface_prepare(&s, NULL, 0));
    assert_true(s.phi0 == -PI / 2);
    assert_true(fabs(s.phi1 - PI / 6) < 1e-15);
    geom_sample g;
    geom_eval(&s, 0.3, 1, &g);                /* v = 1 is the z = zmax rim */
    assert_true(fabs(g.P.z - 1) < 1e-15);
    geom_eval(&s, 0.3, 0, &g);                /* v = 0 the south pole */
    assert_true(fabs(g.P.z + 2) < 1e-15);
}

static void test_polygon_basis(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        if (s->kind != GEOM_POLYGON)
            continue;
        vec3 nn = v3(0, 0, 0);
        for (int i = 0; i < s->nverts; i++)
            nn = v3_add(nn, v3_cross(s->verts[i], s->verts[(i + 1) % s->nverts]));
        vec3 cr = v3_cross(s->axis_u, s->axis_v);
        assert_true(v3_dot(v3_normalize(cr), v3_normalize(nn)) > 1 - 1e-12);
        assert_true(fabs(v3_dot(s->axis_u, s->axis_v)) <
                    1e-12 * v3_length(s->axis_u) * v3_length(s->axis_v));
        double umin = 1, umax = 0, vmin = 1, vmax = 0;
        for (int i = 0; i < s->nverts; i++) {
            /* every vertex is the image of some (u,v) in [0,1]^2 */
            vec3 rel = v3_sub(s->verts[i], s->origin);
            double u = v3_dot(rel, s->axis_u) / v3_dot(s->axis_u, s->axis_u);
            double v = v3_dot(rel, s->axis_v) / v3_dot(s->axis_v, s->axis_v);
            geom_sample g;
            geom_eval(s, u, v, &g);
            assert_true(v3_length(v3_sub(g.P, s->verts[i])) < 1e-12 * fx[k].size);
            assert_true(u > -1e-12 && u < 1 + 1e-12 && v > -1e-12 && v < 1 + 1e-12);
            assert_true(geom_uv_inside(s, u, v));
            umin = fmin(umin, u); umax = fmax(umax, u);
            vmin = fmin(vmin, v); vmax = fmax(vmax, v);
        }
        assert_true(umin < 1e-12 && vmin < 1e-12 && umax > 1 - 1e-12 && vmax > 1 - 1e-12);
    }
}

/* a minimum-area rectangle: a unit square rotated in its plane keeps area 1
 * (the axis-aligned box of its vertices would have area 2) */
static void test_polygon_rectangle(void **state)
{
    (void)state;
    geom_surface s = fx_default(GEOM_POLYGON);
    s.verts[0] = v3(0, -0.5 * sqrt(2), 3);
    s.verts[1] = v3(0.5 * sqrt(2), 0, 3);
    s.verts[2] = v3(0, 0.5 * sqrt(2), 3);
    s.verts[3] = v3(-0.5 * sqrt(2), 0, 3);
    assert_true(geom_surface_prepare(&s, NULL, 0));
    double area = v3_length(v3_cross(s.axis_u, s.axis_v));
    assert_true(fabs(area - 1) < 1e-12);
    assert_true(s.normal.z > 0.999999);
    assert_int_equal(geom_uv_box_cover(&s, 0.01, 0.99, 0.01, 0.99), GEOM_INSIDE);
}

static void test_coverage(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    long boxes[3] = { 0 }, bad = 0;
    fx_seed(31);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        for (int b = 0; b < 400; b++) {
            double w = b % 3 == 0 ? 0.3 : b % 3 == 1 ? 0.05 : 1e-4;
            double u0 = fx_range(-0.2, 1.2), v0 = fx_range(-0.2, 1.2);
            double u1 = u0 + w * fx_unit(), v1 = v0 + w * fx_unit();
            geom_cover c = geom_uv_box_cover(s, u0, u1, v0, v1);
            boxes[c]++;
            if (s->kind != GEOM_POLYGON) {
                assert_int_equal(c, GEOM_INSIDE);
                assert_true(geom_uv_inside(s, u0, v0));
                continue;
            }
            int in = 0, total = 0;
            for (int i = 0; i <= 8; i++)
                for (int j = 0; j <= 8; j++, total++)
                    in += geom_uv_inside(s, u0 + (u1 - u0) * i / 8, v0 + (v1 - v0) * j / 8);
            if ((c == GEOM_OUTSIDE && in > 0) || (c == GEOM_INSIDE && in < total)) {
                if (bad++ < 5)
                    print_message("  %s: box [%g,%g]x[%g,%g] says %d, %d/%d samples inside\n",
                                  fx[k].name, u0, u1, v0, v1, (int)c, in, total);
            }
        }
        if (s->kind == GEOM_POLYGON) {
            /* decisive: a small box around the centroid of the vertices' (u,v)
             * is inside, one far off is outside */
            double cu = 0, cv = 0;
            for (int i = 0; i < s->nuv; i++) {
                cu += s->uv[i][0] / s->nuv;
                cv += s->uv[i][1] / s->nuv;
            }
            assert_int_equal(geom_uv_box_cover(s, cu - 1e-3, cu + 1e-3, cv - 1e-3, cv + 1e-3),
                             GEOM_INSIDE);
            assert_int_equal(geom_uv_box_cover(s, 1.5, 1.6, 1.5, 1.6), GEOM_OUTSIDE);
            assert_false(geom_uv_inside(s, -0.5, -0.5));
        }
    }
    printf("boxes: %ld outside, %ld partial, %ld inside; %ld wrong\n", boxes[GEOM_OUTSIDE],
           boxes[GEOM_PARTIAL], boxes[GEOM_INSIDE], bad);
    assert_int_equal(bad, 0);
    assert_true(boxes[GEOM_OUTSIDE] > 100 && boxes[GEOM_PARTIAL] > 100);
}

/* A surface whose kind is not one: every function answers, none crashes. */
static void test_unknown_kind(void **state)
{
    (void)state;
    geom_surface s = fx_default(GEOM_SPHERE);
    s.kind = (geom_kind)99;
    geom_sample g;
    geom_eval_dual(&s, 0.5, 0.5, &g);
    assert_true(isnan(g.P.x) && isnan(g.Ng.z));
    geom_ia gi;
    geom_eval_ia(&s, ia_make(0, 1), ia_make(0, 1), &gi);
    assert_true(gi.P[0].lo == -INFINITY && gi.Ng[2].hi == INFINITY);
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form u, v;
    aa_input(&ctx, &u, 0, 1);
    aa_input(&ctx, &v, 0, 1);
    geom_aa ga;
    geom_eval_aa(&ctx, &s, &u, &v, &ga);
    assert_true(ga.P[1].flags & AA_UNBOUNDED);
    geom_hit h;
    assert_false(geom_intersect(&s, v3(0, 0, 5), v3(0, 0, -1), 0, INFINITY, &h));
    assert_true(geom_uv_inside(&s, 0.5, 0.5));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reasons),
        cmocka_unit_test(test_reason_buffers),
        cmocka_unit_test(test_accepted),
        cmocka_unit_test(test_sphere_phi),
        cmocka_unit_test(test_polygon_basis),
        cmocka_unit_test(test_polygon_rectangle),
        cmocka_unit_test(test_coverage),
        cmocka_unit_test(test_unknown_kind),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_geom_vertex_normal.c: triangle polygons with corner normals
 * (surface_vertex_normal.c, geom_unit_normal_aa/_ia in surface_normal.c).
 * The interpolated normal equals the corner normals at the corners; two
 * non-coplanar triangles sharing an edge and its corner normals give the
 * same normal along that edge (the crack-free property); over random
 * (u,v) boxes the affine and interval enclosures of N/|N| contain dense
 * samples (long double oracle from the defining coefficients); prepare
 * rejects corner normals on a non-triangle with a reason.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "geom_fixtures.h"

static vec3 random_unit_near(vec3 axis, double spread)
{
    vec3 r = v3(fx_range(-1, 1), fx_range(-1, 1), fx_range(-1, 1));
    return v3_normalize(v3_add(v3_normalize(axis), v3_scale(r, spread)));
}

static void make_triangle(geom_surface *s, vec3 a, vec3 b, vec3 c, vec3 na, vec3 nb, vec3 nc)
{
    memset(s, 0, sizeof *s);
    s->kind = GEOM_POLYGON;
    s->nverts = 3;
    s->verts[0] = a, s->verts[1] = b, s->verts[2] = c;
    s->nvn = 3;
    s->vn[0] = na, s->vn[1] = nb, s->vn[2] = nc;
    char why[256];
    bool ok = geom_surface_prepare(s, why, sizeof why);
    if (!ok)
        printf("prepare: %s\n", why);
    assert_true(ok);
}

/* (u,v) of a point in the triangle's plane (axis_u and axis_v are orthogonal) */
static void uv_of(const geom_surface *s, vec3 p, double *u, double *v)
{
    vec3 r = v3_sub(p, s->origin);
    *u = v3_dot(r, s->axis_u) / v3_dot(s->axis_u, s->axis_u);
    *v = v3_dot(r, s->axis_v) / v3_dot(s->axis_v, s->axis_v);
}

static vec3 unit_normal_at(const geom_surface *s, double u, double v)
{
    vec3 N, du, dv;
    assert_true(geom_vertex_normal(s, u, v, &N, &du, &dv));
    return v3_normalize(N);
}

static void test_corners_and_shared_edge(void **state)
{
    (void)state;
    fx_seed(11);
    double worst_corner = 0, worst_edge = 0;
    for (int trial = 0; trial < 200; trial++) {
        /* two triangles (a b c) and (b a d) folded along the edge a-b */
        vec3 a = v3(fx_range(-1, 1), fx_range(-1, 1), fx_range(-1, 1));
        vec3 b = v3_add(a, v3(1 + fx_unit(), fx_range(-0.5, 0.5), fx_range(-0.5, 0.5)));
        vec3 c = v3_add(a, v3(fx_range(0, 1), 1 + fx_unit(), fx_range(-0.5, 0.5)));
        vec3 d = v3_add(a, v3(fx_range(0, 1), -1 - fx_unit(), fx_range(0.5, 1.5)));
        vec3 up = v3(0, 0, 1);
        vec3 na = random_unit_near(up, 0.5), nb = random_unit_near(up, 0.5);
        vec3 nc = random_unit_near(up, 0.5), nd = random_unit_near(up, 0.5);
        geom_surface f1, f2;
        make_triangle(&f1, a, b, c, na, nb, nc);
        make_triangle(&f2, b, a, d, nb, na, nd);
        assert_true(geom_has_vertex_normals(&f1));
        for (int i = 0; i < 3; i++) {
            double u, v;
            uv_of(&f1, f1.verts[i], &u, &v);
            worst_corner = fmax(worst_corner, v3_length(v3_sub(unit_normal_at(&f1, u, v),
                                                                f1.vn[i])));
        }
        for (int k = 0; k <= 16; k++) {
            vec3 p = v3_lerp(a, b, k / 16.0);
            double u1, v1, u2, v2;
            uv_of(&f1, p, &u1, &v1);
            uv_of(&f2, p, &u2, &v2);
            vec3 n1 = unit_normal_at(&f1, u1, v1), n2 = unit_normal_at(&f2, u2, v2);
            worst_edge = fmax(worst_edge, v3_length(v3_sub(n1, n2)));
        }
    }
    printf("vertex normals: worst corner error %g, worst shared-edge difference %g\n",
           worst_corner, worst_edge);
    assert_true(worst_corner < 1e-12);
    assert_true(worst_edge < 1e-12);
}

static void test_enclosures_contain_samples(void **state)
{
    (void)state;
    fx_seed(5);
    long points = 0, violations = 0, boxes = 0, bounded = 0;
    for (int trial = 0; trial < 60; trial++) {
        vec3 axis = v3(fx_range(-1, 1), fx_range(-1, 1), fx_range(-1, 1));
        if (v3_length(axis) < 0.1) axis = v3(1, 0, 0);
        geom_surface s;
        make_triangle(&s, v3(fx_range(-2, 2), fx_range(-2, 2), fx_range(-2, 2)),
                      v3(fx_range(-2, 2), fx_range(-2, 2), fx_range(-2, 2)),
                      v3(fx_range(-2, 2), fx_range(-2, 2), fx_range(-2, 2)),
                      random_unit_near(axis, 0.8), random_unit_near(axis, 0.8),
                      random_unit_near(axis, 0.8));
        vec3 C, A, B;
        geom_vertex_normal(&s, 0, 0, &C, &A, &B);
        for (int b = 0; b < 40; b++) {
            double w = pow(10, -fx_range(0, 6));
            double u0 = fx_range(0, 1 - w), v0 = fx_range(0, 1 - w);
            double u1 = u0 + w, v1 = v0 + w;
            aa_context ctx;
            aa_context_init(&ctx, 16);
            aa_form u, v, Nn[3];
            aa_input(&ctx, &u, u0, u1);
            aa_input(&ctx, &v, v0, v1);
            geom_aa g;
            geom_eval_aa(&ctx, &s, &u, &v, &g);
            geom_unit_normal_aa(&ctx, &s, &u, &v, &g, Nn);
            geom_ia gi;
            ia_interval Ni[3], r[3];
            geom_eval_ia(&s, ia_make(u0, u1), ia_make(v0, v1), &gi);
            geom_unit_normal_ia(&s, ia_make(u0, u1), ia_make(v0, v1), &gi, Ni);
            bool narrow = true;
            for (int i = 0; i < 3; i++) {
                r[i] = aa_range(&Nn[i]);
                narrow = narrow && r[i].hi - r[i].lo <= 2.0 && Ni[i].hi - Ni[i].lo <= 2.0;
            }
            boxes++;
            bounded += narrow;
            for (int k = 0; k < 64; k++) {
                long double us = u0 + w * fx_unit(), vs = v0 + w * fx_unit();
                if (k == 0) us = u0, vs = v0;
                if (k == 1) us = u1, vs = v1;
                long double n[3], len2 = 0;
                for (int i = 0; i < 3; i++) {
                    n[i] = (long double)v3_comp(C, i) + us * v3_comp(A, i) +
                           vs * v3_comp(B, i);
                    len2 += n[i] * n[i];
                }
                if (!(len2 > 1e-12L)) continue;
                for (int i = 0; i < 3; i++) {
                    long double x = n[i] / sqrtl(len2);
                    if (x < r[i].lo || x > r[i].hi || x < Ni[i].lo || x > Ni[i].hi)
                        violations++;
                }
                points++;
            }
        }
    }
    printf("vertex normal enclosures: %ld boxes (%ld of width <= 2), %ld points, "
           "%ld violations\n", boxes, bounded, points, violations);
    assert_int_equal(violations, 0);
    assert_true(bounded > boxes / 2);
    assert_true(points > 100000);
}

static void test_prepare_rejects(void **state)
{
    (void)state;
    geom_surface s;
    memset(&s, 0, sizeof s);
    s.kind = GEOM_POLYGON;
    s.nverts = 4;
    s.verts[0] = v3(0, 0, 0), s.verts[1] = v3(1, 0, 0);
    s.verts[2] = v3(1, 1, 0), s.verts[3] = v3(0, 1, 0);
    s.nvn = 3;
    s.vn[0] = s.vn[1] = s.vn[2] = v3(0, 0, 1);
    char why[256];
    assert_false(geom_surface_prepare(&s, why, sizeof why));
    assert_string_equal(why, "vertex normals need a triangle with 3 distinct corners and 3 "
                        "normals (got 4 corners, 3 normals)");
    s.nverts = 3;
    s.vn[1] = v3(NAN, 0, 1);
    assert_false(geom_surface_prepare(&s, why, sizeof why));
    assert_string_equal(why, "vertex normal 1 must be finite numbers, got (nan 0 1)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_corners_and_shared_edge),
        cmocka_unit_test(test_enclosures_contain_samples),
        cmocka_unit_test(test_prepare_rejects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * tests/geom/test_geom_derivatives.c: the float and dual evaluations.
 *
 *   oracle        geom_eval's P, dPdu, dPdv, Ng agree with the long double
 *                 oracle (RI spec §5.2 formulas, geom_fixtures.c), every
 *                 fixture, 300 random (u,v) each
 *   Ng            Ng == dPdu x dPdv
 *   finite diff   dPdu, dPdv against central differences of P; dNgdu,
 *                 dNgdv (geom_eval_dual) against central differences of Ng
 *   orientation   Ng points outward for the quadrics with their default
 *                 parameters, along Newell's normal for polygons
 *   eval vs dual  the same P..Ng; geom_eval leaves dNg zero
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "geom_fixtures.h"

static double dist_ld(vec3 a, const long double *b)
{
    long double dx = a.x - b[0], dy = a.y - b[1], dz = a.z - b[2];
    return (double)sqrtl(dx * dx + dy * dy + dz * dz);
}

static double len_ld(const long double *b)
{
    return (double)sqrtl(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
}

static double dist(vec3 a, vec3 b)
{
    return v3_length(v3_sub(a, b));
}

static void test_matches_oracle(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx), checked = 0;
    fx_seed(1);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        for (int i = 0; i < 300; i++) {
            double u = fx_unit(), v = fx_range(0.001, 1);
            geom_sample g;
            fx_exact e;
            geom_eval(s, u, v, &g);
            fx_oracle(s, u, v, &e);
            double sz = fx[k].size;
            const char *what = NULL;
            if (dist_ld(g.P, e.P) > 1e-13 * sz)
                what = "P";
            else if (dist_ld(g.dPdu, e.Pu) > 1e-13 * (sz + len_ld(e.Pu)))
                what = "dPdu";
            else if (dist_ld(g.dPdv, e.Pv) > 1e-13 * (sz + len_ld(e.Pv)))
                what = "dPdv";
            else if (dist_ld(g.Ng, e.Ng) > 1e-12 * (sz * sz + len_ld(e.Ng)))
                what = "Ng";
            if (what)
                fail_msg("%s: %s differs from the oracle at (%g, %g)", fx[k].name, what, u, v);
            vec3 cr = v3_cross(g.dPdu, g.dPdv);
            if (dist(cr, g.Ng) > 1e-12 * (1 + v3_length(cr)))
                fail_msg("%s: Ng != dPdu x dPdv at (%g, %g)", fx[k].name, u, v);
            checked++;
        }
    }
    printf("float evaluation matches the oracle at %d points\n", checked);
}

/* central difference of P or Ng, of geom_eval_dual */
static vec3 central(const geom_surface *s, double u, double v, int along_v, int of_ng,
                    double h)
{
    geom_sample a, b;
    if (along_v) {
        geom_eval_dual(s, u, v - h, &a);
        geom_eval_dual(s, u, v + h, &b);
    } else {
        geom_eval_dual(s, u - h, v, &a);
        geom_eval_dual(s, u + h, v, &b);
    }
    vec3 fa = of_ng ? a.Ng : a.P, fb = of_ng ? b.Ng : b.P;
    return v3_scale(v3_sub(fb, fa), 0.5 / h);
}

static void test_finite_differences(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx), checked = 0;
    const double h = 1e-5;
    fx_seed(2);
    for (int k = 0; k < n; k++) {
        const geom_surface *s = &fx[k].s;
        double sz = fx[k].size, tol = 1e-6 * sz * sz * sz;
        for (int i = 0; i < 200; i++) {
            double u = fx_range(0.01, 0.99), v = fx_range(0.05, 0.95);
            geom_sample g;
            geom_eval_dual(s, u, v, &g);
            vec3 want[4] = { central(s, u, v, 0, 0, h), central(s, u, v, 1, 0, h),
                             central(s, u, v, 0, 1, h), central(s, u, v, 1, 1, h) };
            vec3 got[4] = { g.dPdu, g.dPdv, g.dNgdu, g.dNgdv };
            static const char *const names[4] = { "dPdu", "dPdv", "dNgdu", "dNgdv" };
            for (int j = 0; j < 4; j++)
                if (dist(got[j], want[j]) > tol * (1 + v3_length(want[j])))
                    fail_msg("%s: %s = (%g %g %g), finite difference (%g %g %g) at (%g, %g)",
                             fx[k].name, names[j], got[j].x, got[j].y, got[j].z,
                             want[j].x, want[j].y, want[j].z, u, v);
            checked++;
        }
    }
    printf("derivatives match finite differences at %d points\n", checked);
}

static vec3 newell(const geom_surface *s)
{
    vec3 nn = v3(0, 0, 0);
    for (int i = 0; i < s->nverts; i++) {
        vec3 a = s->verts[i], b = s->verts[(i + 1) % s->nverts];
        nn = v3_add(nn, v3_cross(a, b));
    }
    return nn;
}

/* the outward direction at P for the default quadrics */
static vec3 outward(const geom_surface *s, vec3 P)
{
    vec3 radial = v3(P.x, P.y, 0);
    switch (s->kind) {
    case GEOM_SPHERE:     return P;
    case GEOM_DISK:       return v3(0, 0, 1);
    case GEOM_PARABOLOID: return v3(P.x, P.y, -0.25);
    case GEOM_CONE:       return v3_add(radial, v3(0, 0, 0.5));
    case GEOM_TORUS:
        return v3_sub(P, v3_scale(v3_normalize(radial), s->majorrad));
    default:              return radial;
    }
}

static void test_orientation(void **state)
{
    (void)state;
    fx_seed(3);
    for (int kind = 0; kind < GEOM__COUNT; kind++) {
        if (kind == GEOM_SUBDIV) continue;    /* needs a mesh: test_geom_subdiv */
        if (kind == GEOM_NURBS) continue;     /* needs a NuPatch: test_geom_nurbs */
        geom_surface s = fx_default((geom_kind)kind);
        char why[200];
        assert_true(geom_surface_prepare(&s, why, sizeof why));
        for (int i = 0; i < 100; i++) {
            double u = fx_unit(), v = fx_range(0.01, 0.99);
            geom_sample g;
            geom_eval(&s, u, v, &g);
            vec3 want = kind == GEOM_POLYGON ? newell(&s)
                        : kind == GEOM_PATCH || kind == GEOM_BICUBIC ? v3(0, 0, 1)
                        : outward(&s, g.P);
            double c = v3_dot(v3_normalize(g.Ng), v3_normalize(want));
            if (!(c > 0.1))
                fail_msg("%s: Ng (%g %g %g) does not point outward at (%g, %g)",
                         geom_kind_name((geom_kind)kind), g.Ng.x, g.Ng.y, g.Ng.z, u, v);
        }
    }
}

static void test_eval_vs_dual(void **state)
{
    (void)state;
    fx_surface *fx;
    int n = fx_surfaces(&fx);
    fx_seed(4);
    for (int k = 0; k < n; k++)
        for (int i = 0; i < 20; i++) {
            double u = fx_unit(), v = fx_range(0.01, 1);
            geom_sample a, b;
            geom_eval(&fx[k].s, u, v, &a);
            geom_eval_dual(&fx[k].s, u, v, &b);
            assert_true(dist(a.P, b.P) == 0 && dist(a.dPdu, b.dPdu) == 0 &&
                        dist(a.dPdv, b.dPdv) == 0 && dist(a.Ng, b.Ng) == 0);
            assert_true(v3_length(a.dNgdu) == 0 && v3_length(a.dNgdv) == 0);
        }
}

/* The paraboloid's apex (zmin = 0, v = 0): dPdv is infinite there, but Ng
 * is finite and equals its limit. */
static void test_paraboloid_apex(void **state)
{
    (void)state;
    geom_surface s = fx_default(GEOM_PARABOLOID);
    assert_true(geom_surface_prepare(&s, NULL, 0));
    geom_sample at, near;
    geom_eval(&s, 0.3, 0, &at);
    geom_eval(&s, 0.3, 1e-14, &near);
    assert_true(isfinite(at.Ng.x) && isfinite(at.Ng.y) && isfinite(at.Ng.z));
    assert_true(dist(at.Ng, near.Ng) < 1e-5);
    assert_true(at.Ng.z < 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_oracle),
        cmocka_unit_test(test_finite_differences),
        cmocka_unit_test(test_orientation),
        cmocka_unit_test(test_eval_vs_dual),
        cmocka_unit_test(test_paraboloid_apex),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

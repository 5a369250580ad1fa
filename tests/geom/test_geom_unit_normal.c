/*
 * test_geom_unit_normal.c: geom_unit_normal_aa / _ia (surface_normal.c):
 * for every fixture surface and many (u,v) boxes, including boxes that
 * touch a sphere's pole, a disk's centre or a cone's apex, the enclosures
 * contain Ng/|Ng| at dense samples (where Ng is not 0), and on the
 * closed-form kinds they stay bounded (width <= 2 per component) even at
 * those degenerate points, where normalising Ng would give unbounded
 * results.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>

#include "geom_fixtures.h"

static bool closed_form(geom_kind k)
{
    return k == GEOM_SPHERE || k == GEOM_TORUS || k == GEOM_DISK ||
           k == GEOM_CYLINDER || k == GEOM_CONE || k == GEOM_POLYGON;
}

static void test_unit_normal_contains_and_stays_bounded(void **state)
{
    (void)state;
    fx_surface *surfs;
    int n = fx_surfaces(&surfs);
    long points = 0, violations = 0, boxes = 0;
    fx_seed(7);
    for (int si = 0; si < n; si++) {
        const geom_surface *s = &surfs[si].s;
        for (int b = 0; b < 120; b++) {
            double w = pow(10, -fx_range(0, 6));
            double u0 = fx_range(0, 1 - w), v0 = fx_range(0, 1 - w);
            if (b % 4 == 0) v0 = 1 - w;          /* touch v = 1: pole, centre, apex */
            if (b % 4 == 1) v0 = 0;
            double u1 = u0 + w, v1 = v0 + w;
            aa_context ctx;
            aa_context_init(&ctx, 16);
            aa_form u, v, Nn[3];
            aa_input(&ctx, &u, u0, u1);
            aa_input(&ctx, &v, v0, v1);
            geom_aa g;
            geom_eval_aa(&ctx, s, &u, &v, &g);
            geom_unit_normal_aa(&ctx, s, &u, &v, &g, Nn);
            geom_ia gi;
            ia_interval Ni[3];
            geom_eval_ia(s, ia_make(u0, u1), ia_make(v0, v1), &gi);
            geom_unit_normal_ia(s, ia_make(u0, u1), ia_make(v0, v1), &gi, Ni);
            ia_interval r[3];
            for (int i = 0; i < 3; i++) {
                r[i] = aa_range(&Nn[i]);
                if (closed_form(s->kind)) {
                    if (!(r[i].hi - r[i].lo <= 2.0 + 1e-9 && Ni[i].hi - Ni[i].lo <= 2.0 + 1e-9))
                        printf("%s box u [%g %g] v [%g %g]: component %d affine [%g, %g] interval [%g, %g]\n",
                               surfs[si].name, u0, u1, v0, v1, i, r[i].lo, r[i].hi, Ni[i].lo, Ni[i].hi);
                    assert_true(r[i].hi - r[i].lo <= 2.0 + 1e-9);
                    assert_true(Ni[i].hi - Ni[i].lo <= 2.0 + 1e-9);
                }
            }
            boxes++;
            for (int k = 0; k < 64; k++) {
                double us = u0 + w * fx_unit(), vs = v0 + w * fx_unit();
                if (k == 0) vs = v1;
                geom_sample gs;
                geom_eval(s, us, vs, &gs);
                double len = v3_length(gs.Ng);
                if (!(len > 1e-9 * (1 + v3_length(gs.P)))) continue;
                vec3 nn = v3_scale(gs.Ng, 1 / len);
                for (int i = 0; i < 3; i++) {
                    double x = v3_comp(nn, i), slack = 1e-9;
                    if (x < r[i].lo - slack || x > r[i].hi + slack ||
                        x < Ni[i].lo - slack || x > Ni[i].hi + slack)
                        violations++;
                }
                points++;
            }
        }
    }
    printf("unit normal: %d surfaces, %ld boxes, %ld points, %ld violations\n", n, boxes,
           points, violations);
    assert_int_equal(violations, 0);
    assert_true(points > 10000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unit_normal_contains_and_stays_bounded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

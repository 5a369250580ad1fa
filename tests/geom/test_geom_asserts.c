/*
 * test_geom_asserts.c: the death test of common/geom. The Bezier nets of
 * NuPatch and subdivision pieces hold orders 1 to GEOM_NURBS_MAX_ORDER
 * (bezier_net.c asserts it where the net is cut); this hands one an order
 * of 0 on purpose, so a build that compiled its asserts away fails here
 * instead of passing.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "death.h"
#include "geom/nurbs.h"
#include "geom/surface_internal.h"

static void cut_piece(void *arg)
{
    int order = *(int *)arg;
    double p[GEOM_NURBS_MAX_ORDER] = { 0 }, q[GEOM_NURBS_MAX_ORDER];
    geom_bezier_piece(p, 1, order, 0.25, 0.75, q, 1);
}

static void test_geom_asserts_are_live(void **state)
{
    (void)state;
    int zero = 0, two = 2;
    assert_death(cut_piece, &zero, "n >= 1 && n <= GEOM_NURBS_MAX_ORDER");
    char why[512];
    assert_false(death_run(cut_piece, &two, NULL, why, sizeof why));   /* a valid order lives */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_geom_asserts_are_live),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_aa_asserts.c: the death test of common/aa. The affine arithmetic's
 * invariants (a context's symbols within its capacity, within a form's
 * AA_MAX_SYMBOLS; a new error is an upper bound, never negative) are
 * asserted where they live (affine.c); this trips them on purpose, so a
 * build that compiled its asserts away fails here instead of passing.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "aa/affine.h"
#include "death.h"

/* A context whose counter ran past its capacity: the next symbol trips
 * check_context. */
static void overfull_context(void *arg)
{
    (void)arg;
    aa_context ctx;
    aa_context_init(&ctx, 4);
    ctx.used = 5;
    aa_form z;
    aa_input(&ctx, &z, 0.0, 1.0);
}

/* A negative "error bound" handed to aa_add_new_error. */
static void negative_error(void *arg)
{
    (void)arg;
    aa_context ctx;
    aa_context_init(&ctx, 4);
    aa_form z;
    aa_const(&z, 1.0);
    aa_add_new_error(&ctx, &z, -1.0);
}

static void living(void *arg)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_MAX_SYMBOLS);
    aa_form *z = arg;
    for (int i = 0; i < 2 * AA_MAX_SYMBOLS; i++)    /* past capacity: folded */
        aa_input(&ctx, &z[i % 2], 0.0, 1.0);
}

static void test_aa_asserts_are_live(void **state)
{
    (void)state;
    assert_death(overfull_context, NULL, "ctx->used <= ctx->capacity");
    assert_death(negative_error, NULL, "delta < 0.0");
    char why[512];
    aa_form z[2];
    assert_false(death_run(living, z, NULL, why, sizeof why));   /* the valid use lives */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_aa_asserts_are_live),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

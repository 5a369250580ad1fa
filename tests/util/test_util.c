/*
 * test_util.c: common/util's error convention and allocator, and the death
 * test helper the other modules' death tests rely on.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <assert.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "death.h"
#include "util/err.h"
#include "util/xalloc.h"

static bool fails_with_place(char *err, size_t errsz)
{
    return err_set(err, errsz, "%s:%d:%d: unknown shader '%s'", "a.rib", 3, 14, "mtl");
}

static void test_err_set(void **state)
{
    (void)state;
    char err[ERR_LEN] = "";
    assert_false(fails_with_place(err, sizeof err));
    assert_string_equal(err, "a.rib:3:14: unknown shader 'mtl'");
    /* a short buffer truncates, NUL-terminated; NULL drops the message */
    char small[8];
    assert_false(fails_with_place(small, sizeof small));
    assert_string_equal(small, "a.rib:3");
    assert_false(fails_with_place(NULL, 0));
    assert_false(err_prefix(err, sizeof err, "job %d", 7));
    assert_string_equal(err, "job 7: a.rib:3:14: unknown shader 'mtl'");
}

static void test_xalloc(void **state)
{
    (void)state;
    char *s = xstrndup("abcdef", 3);
    assert_string_equal(s, "abc");
    free(s);
    s = xstrdup("tile");
    assert_string_equal(s, "tile");
    free(s);
    int *z = xcalloc(16, sizeof *z);
    for (int i = 0; i < 16; i++)
        assert_int_equal(z[i], 0);
    z = xreallocarray(z, 32, sizeof *z);
    free(z);
    /* zero sizes still give a pointer that free accepts */
    void *p = xmalloc(0);
    assert_non_null(p);
    free(p);
    /* overflow of n * size is refused, not wrapped */
    assert_null(try_reallocarray(NULL, SIZE_MAX / 2, 4));
}

static void overflowing_array(void *arg)
{
    (void)arg;
    void *p = xreallocarray(NULL, SIZE_MAX / 2, 4);
    free(p);
}

static void test_xalloc_dies_naming_size(void **state)
{
    (void)state;
    assert_death(overflowing_array, NULL, "out of memory");
}

static void failing_assert(void *arg)
{
    int *n = arg;
    (void)n;   /* without asserts */
    assert(*n == 0 && "a test's own assert");
}

static void living(void *arg)
{
    (void)arg;
}

/* The test build keeps asserts (AAFARM_ASSERTS): this fails if NDEBUG
 * leaked into it. The death helper itself must tell a live child from
 * a dead one. */
static void test_asserts_are_on(void **state)
{
    (void)state;
    int one = 1;
    assert_death(failing_assert, &one, "a test's own assert");
    char why[512];
    assert_false(death_run(living, NULL, NULL, why, sizeof why));
    assert_non_null(strstr(why, "exited with 0"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_err_set),
        cmocka_unit_test(test_xalloc),
        cmocka_unit_test(test_xalloc_dies_naming_size),
        cmocka_unit_test(test_asserts_are_on),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * tests/scene/test_scene_suggest.c: the distance behind "did you mean"
 * (common/util/suggest.c), tested here beside its main user, the RIB
 * parser: Damerau's distance without case, the limit by length, the
 * closest name within it.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "util/suggest.h"

static void test_distance(void **state)
{
    (void)state;
    assert_int_equal(suggest_distance("", ""), 0);
    assert_int_equal(suggest_distance("", "abc"), 3);
    assert_int_equal(suggest_distance("abc", ""), 3);
    assert_int_equal(suggest_distance("WorldBegin", "WorldBegin"), 0);
    assert_int_equal(suggest_distance("worldbegin", "WorldBegin"), 0);   /* no case */
    assert_int_equal(suggest_distance("WorldBegn", "WorldBegin"), 1);    /* deletion */
    assert_int_equal(suggest_distance("WorldBeggin", "WorldBegin"), 1);  /* insertion */
    assert_int_equal(suggest_distance("WorldBagin", "WorldBegin"), 1);   /* substitution */
    assert_int_equal(suggest_distance("WorldBegni", "WorldBegin"), 1);   /* swap */
    assert_int_equal(suggest_distance("plastc", "plastic"), 1);
    assert_int_equal(suggest_distance("kitten", "sitting"), 3);
    assert_int_equal(suggest_distance("ca", "abc"), 3);   /* OSA, not full Damerau */
}

static void test_limit(void **state)
{
    (void)state;
    assert_int_equal(suggest_limit(1), 1);
    assert_int_equal(suggest_limit(4), 1);
    assert_int_equal(suggest_limit(5), 2);
    assert_int_equal(suggest_limit(8), 2);
    assert_int_equal(suggest_limit(9), 3);
    assert_int_equal(suggest_limit(40), 3);
}

static void test_closest(void **state)
{
    (void)state;
    const char *names[] = { "Sphere", "Disk", "WorldBegin", "WorldEnd", NULL, "Cone" };
    int n = (int)(sizeof names / sizeof names[0]);
    assert_string_equal(suggest_closest("WorldBegn", names, n), "WorldBegin");
    assert_string_equal(suggest_closest("worldend", names, n), "WorldEnd");
    assert_string_equal(suggest_closest("Spere", names, n), "Sphere");
    assert_string_equal(suggest_closest("Dsk", names, n), "Disk");
    assert_null(suggest_closest("Dk", names, n));           /* 2 away, limit 1 at 2 letters */
    assert_null(suggest_closest("Frobnicate", names, n));
    assert_null(suggest_closest("Sphere", names, 0));
    /* a tie goes to the first */
    assert_string_equal(suggest_closest("Cane", names, n), "Cone");
    const char *tie[] = { "bat", "cat" };
    assert_string_equal(suggest_closest("aat", tie, 2), "bat");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_distance),
        cmocka_unit_test(test_limit),
        cmocka_unit_test(test_closest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

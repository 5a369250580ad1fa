/*
 * test_trace_asserts.c: the death test of common/trace. The box cache's
 * invariants (pins never negative, an evicted brood unpinned, the budget a
 * hard limit, brood links consistent) and the BVH's node ranges are
 * asserted where they live (boxcache.c, bvh.c); this trips the pin count
 * on purpose (a brood unpinned twice), so a build that compiled its
 * asserts away fails here instead of passing.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>

#include "death.h"
#include "trace/boxcache.h"

static trace_brood_id insert_root(trace_boxcache *c)
{
    trace_box boxes[4];
    memset(boxes, 0, sizeof boxes);
    return trace_boxcache_insert(c, 0, TRACE_BROOD_NONE, 0, boxes);
}

/* Pinned once, unpinned twice. */
static void unpin_twice(void *arg)
{
    int times = *(int *)arg;
    trace_boxcache *c = trace_boxcache_new(0, 1);
    trace_brood_id id = insert_root(c);
    trace_boxcache_pin(c, id);
    for (int i = 0; i < times; i++) trace_boxcache_unpin(c, id);
    trace_boxcache_destroy(&c);
}

static void test_trace_asserts_are_live(void **state)
{
    (void)state;
    int twice = 2, once = 1;
    assert_death(unpin_twice, &twice, "unpinning a brood that is not pinned");
    char why[512];
    assert_false(death_run(unpin_twice, &once, NULL, why, sizeof why));   /* balanced: lives */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_trace_asserts_are_live),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

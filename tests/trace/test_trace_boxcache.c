/*
 * test_trace_boxcache.c: the box cache on its own: stored broods come back
 * unchanged, the byte budget is a hard limit, the least recently used
 * subtree goes first, pinned broods (the traversal's path) are never
 * evicted (a brood that finds no room is not stored, and nothing below it
 * is), and an unlimited cache never evicts. (A lookup leaves the boxes'
 * linear bounds as they were: out starts zeroed, as fill's are.)
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>

#include "trace/boxcache.h"

static void fill(trace_box b[4], double k)
{
    memset(b, 0, 4 * sizeof *b);
    for (int i = 0; i < 4; i++) {
        b[i].lo = v3(k, k + i, -k);
        b[i].hi = v3(k + 1, k + i + 1, -k + 1);
        b[i].flags = (unsigned)i & 1u;
    }
}

static void test_store_and_lookup(void **state)
{
    (void)state;
    trace_boxcache *c = trace_boxcache_new(0, 2);
    trace_box in[4], out[4] = {0};
    fill(in, 1);
    assert_int_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    trace_brood_id root = trace_boxcache_insert(c, 0, TRACE_BROOD_NONE, 0, in);
    assert_int_not_equal(root, TRACE_BROOD_NONE);
    assert_int_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), root);
    assert_memory_equal(in, out, sizeof in);
    /* another object's root is separate */
    assert_int_equal(trace_boxcache_lookup(c, 1, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    /* children of child 2 */
    fill(in, 7);
    trace_brood_id kid = trace_boxcache_insert(c, 0, root, 2, in);
    assert_int_equal(trace_boxcache_lookup(c, 0, root, 2, out), kid);
    assert_memory_equal(in, out, sizeof in);
    assert_int_equal(trace_boxcache_lookup(c, 0, root, 1, out), TRACE_BROOD_NONE);
    /* object ids out of range are refused, not a crash */
    assert_int_equal(trace_boxcache_insert(c, 5, TRACE_BROOD_NONE, 0, in), TRACE_BROOD_UNCACHED);
    assert_int_equal(trace_boxcache_stats_get(c)->evictions, 0);
    trace_boxcache_destroy(&c);
    assert_null(c);
}

static void test_budget_is_a_hard_limit_and_lru_goes_first(void **state)
{
    (void)state;
    size_t per = trace_boxcache_brood_bytes();
    trace_boxcache *c = trace_boxcache_new(3 * per, 4);
    trace_box in[4], out[4] = {0};
    fill(in, 0);
    trace_brood_id r[4];
    for (int o = 0; o < 3; o++) r[o] = trace_boxcache_insert(c, o, TRACE_BROOD_NONE, 0, in);
    /* touch object 0: object 1 is now the least recently used */
    assert_int_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), r[0]);
    r[3] = trace_boxcache_insert(c, 3, TRACE_BROOD_NONE, 0, in);
    assert_int_not_equal(r[3], TRACE_BROOD_NONE);
    assert_int_equal(trace_boxcache_lookup(c, 1, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    assert_int_not_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    assert_int_not_equal(trace_boxcache_lookup(c, 2, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    const trace_boxcache_stats *s = trace_boxcache_stats_get(c);
    assert_true(s->peak_bytes <= 3 * per);
    assert_int_equal(s->evictions, 1);
    trace_boxcache_destroy(&c);
}

static void test_eviction_takes_the_subtree(void **state)
{
    (void)state;
    size_t per = trace_boxcache_brood_bytes();
    trace_boxcache *c = trace_boxcache_new(3 * per, 2);
    trace_box in[4], out[4] = {0};
    fill(in, 0);
    trace_brood_id root = trace_boxcache_insert(c, 0, TRACE_BROOD_NONE, 0, in);
    trace_brood_id kid = trace_boxcache_insert(c, 0, root, 1, in);
    assert_int_not_equal(kid, TRACE_BROOD_NONE);
    /* make the root the oldest, its child newer */
    assert_int_equal(trace_boxcache_lookup(c, 0, root, 1, out), kid);
    trace_brood_id other = trace_boxcache_insert(c, 1, TRACE_BROOD_NONE, 0, in);
    assert_int_not_equal(other, TRACE_BROOD_NONE);
    /* full (3 broods); the next insert evicts the LRU, the root of object
     * 0, and with it its child: two broods go */
    assert_int_not_equal(trace_boxcache_insert(c, 1, other, 0, in), TRACE_BROOD_NONE);
    assert_int_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    assert_int_equal(trace_boxcache_stats_get(c)->evictions, 2);
    assert_int_equal(trace_boxcache_stats_get(c)->bytes, 2 * per);
    trace_boxcache_destroy(&c);
}

static void test_pinned_path_survives(void **state)
{
    (void)state;
    size_t per = trace_boxcache_brood_bytes();
    trace_boxcache *c = trace_boxcache_new(2 * per, 1);
    trace_box in[4], out[4] = {0};
    fill(in, 0);
    trace_brood_id root = trace_boxcache_insert(c, 0, TRACE_BROOD_NONE, 0, in);
    trace_boxcache_pin(c, root);
    trace_brood_id a = trace_boxcache_insert(c, 0, root, 0, in);
    trace_boxcache_pin(c, a);
    /* budget full and everything pinned: not stored, nothing evicted */
    trace_brood_id lost = trace_boxcache_insert(c, 0, a, 3, in);
    assert_int_equal(lost, TRACE_BROOD_UNCACHED);
    assert_int_equal(trace_boxcache_stats_get(c)->evictions, 0);
    assert_int_equal(trace_boxcache_stats_get(c)->not_stored, 1);
    /* below a brood that was not stored nothing is found or stored, and the
     * object's root brood is untouched (an unstored parent once read as the
     * root: a deep node got the root's children as its boxes) */
    trace_box deep[4];
    fill(deep, 7);
    assert_int_equal(trace_boxcache_lookup(c, 0, lost, 2, out), TRACE_BROOD_NONE);
    assert_int_equal(trace_boxcache_insert(c, 0, lost, 2, deep), TRACE_BROOD_UNCACHED);
    assert_int_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), root);
    assert_memory_equal(out, in, sizeof out);
    trace_boxcache_unpin(c, a);
    /* now a (unpinned, under the pinned root) can make room for a sibling */
    assert_true(trace_boxcache_insert(c, 0, root, 1, in) >= 0);
    assert_int_equal(trace_boxcache_lookup(c, 0, root, 0, out), TRACE_BROOD_NONE);
    assert_int_not_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    trace_boxcache_unpin(c, root);
    trace_boxcache_destroy(&c);
}

/* The insert's own contract (issue 27, item 7d): the parent a new brood
 * goes under stays in the cache while room is made for it, even when the
 * caller has not pinned it and it is the least recently used brood (the
 * walk pins its whole path, which would hide an insert that forgot). Two
 * roots fill the budget, the parent root is the older: the other root
 * must go, and the parent and its new child must both be found. */
static void test_insert_keeps_its_parent(void **state)
{
    (void)state;
    size_t per = trace_boxcache_brood_bytes();
    trace_boxcache *c = trace_boxcache_new(2 * per, 2);
    trace_box a_in[4], b_in[4], child_in[4], out[4] = {0};
    fill(a_in, 1);
    fill(b_in, 2);
    fill(child_in, 3);
    trace_brood_id a = trace_boxcache_insert(c, 0, TRACE_BROOD_NONE, 0, a_in);
    trace_brood_id b = trace_boxcache_insert(c, 1, TRACE_BROOD_NONE, 0, b_in);
    assert_true(a >= 0 && b >= 0);
    /* a is the least recently used; nothing is pinned */
    trace_brood_id child = trace_boxcache_insert(c, 0, a, 2, child_in);
    assert_true(child >= 0);
    assert_int_equal(trace_boxcache_stats_get(c)->evictions, 1);
    assert_int_equal(trace_boxcache_lookup(c, 0, TRACE_BROOD_NONE, 0, out), a);
    assert_memory_equal(out, a_in, sizeof out);
    assert_int_equal(trace_boxcache_lookup(c, 0, a, 2, out), child);
    assert_memory_equal(out, child_in, sizeof out);
    assert_int_equal(trace_boxcache_lookup(c, 1, TRACE_BROOD_NONE, 0, out), TRACE_BROOD_NONE);
    trace_boxcache_destroy(&c);
}

static void test_unlimited_never_evicts(void **state)
{
    (void)state;
    trace_boxcache *c = trace_boxcache_new(0, 1);
    trace_box in[4];
    fill(in, 0);
    trace_brood_id parent = trace_boxcache_insert(c, 0, TRACE_BROOD_NONE, 0, in);
    for (int i = 0; i < 5000; i++) {
        trace_brood_id id = trace_boxcache_insert(c, 0, parent, i & 3, in);
        assert_int_not_equal(id, TRACE_BROOD_NONE);
        if ((i & 3) == 3) parent = id;
    }
    assert_int_equal(trace_boxcache_stats_get(c)->evictions, 0);
    assert_int_equal(trace_boxcache_stats_get(c)->bytes, 5001 * trace_boxcache_brood_bytes());
    trace_boxcache_destroy(&c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_store_and_lookup),
        cmocka_unit_test(test_budget_is_a_hard_limit_and_lru_goes_first),
        cmocka_unit_test(test_eviction_takes_the_subtree),
        cmocka_unit_test(test_pinned_path_survives),
        cmocka_unit_test(test_insert_keeps_its_parent),
        cmocka_unit_test(test_unlimited_never_evicts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_farm_registry.c: the master's worker registry (master/registry.h):
 * lookups by routing id find live workers only, retired workers stay for
 * the summary (up to a bound), HELLO_FIRST answers are rate-limited per
 * peer, routing ids print as hex.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "registry.h"

static void test_find_live_workers_only(void **state)
{
    (void)state;
    registry *r = registry_new();
    const uint8_t a[] = {0, 0x80, 0, 0, 1}, b[] = {0, 0x80, 0, 0, 2};
    farm_worker *wa = registry_add(r, a, sizeof a, 10);
    farm_worker *wb = registry_add(r, b, sizeof b, 20);
    assert_non_null(wa);
    assert_ptr_equal(registry_find(r, a, sizeof a), wa);
    assert_ptr_equal(registry_find(r, b, sizeof b), wb);
    assert_null(registry_find(r, a, 4));                 /* a prefix is another id */
    assert_int_equal(registry_alive(r), 2);
    registry_retire(r, wa, "missed 3 heartbeats", 30);
    assert_null(registry_find(r, a, sizeof a));
    assert_int_equal(registry_alive(r), 1);
    assert_int_equal(registry_count(r), 2);              /* kept for the summary */
    assert_string_equal(registry_at(r, 0)->gone, "missed 3 heartbeats");
    /* the same id may come back as a new worker */
    farm_worker *again = registry_add(r, a, sizeof a, 40);
    assert_ptr_equal(registry_find(r, a, sizeof a), again);
    assert_int_equal(registry_count(r), 3);
    assert_null(registry_add(r, a, 0, 50));
    registry_destroy(&r);
    assert_null(r);
}

static void test_retired_workers_are_bounded(void **state)
{
    (void)state;
    registry *r = registry_new();
    uint8_t id[4];
    for (uint32_t i = 0; i < 5000; i++) {
        memcpy(id, &i, sizeof id);
        farm_worker *w = registry_add(r, id, sizeof id, i);
        registry_retire(r, w, "said Hello again", i);
    }
    assert_true(registry_count(r) <= 4097);
    /* the newest are kept */
    assert_true(registry_at(r, registry_count(r) - 1)->joined_ms == 4999);
    registry_destroy(&r);
}

static void test_hello_first_rate_limit(void **state)
{
    (void)state;
    registry *r = registry_new();
    const uint8_t p[] = {1, 2, 3}, q[] = {4, 5, 6};
    assert_true(registry_reject_due(r, p, sizeof p, 0, 1000));
    assert_false(registry_reject_due(r, p, sizeof p, 999, 1000));
    assert_true(registry_reject_due(r, q, sizeof q, 999, 1000));   /* another peer */
    assert_true(registry_reject_due(r, p, sizeof p, 1000, 1000));
    assert_false(registry_reject_due(r, p, sizeof p, 1500, 1000));
    registry_destroy(&r);
}

static void test_id_hex(void **state)
{
    (void)state;
    char buf[24];
    const uint8_t id[] = {0, 0x80, 0, 0, 1};
    assert_string_equal(registry_id_hex(id, sizeof id, buf, sizeof buf), "0080000001");
    uint8_t longid[40];
    memset(longid, 0xab, sizeof longid);
    assert_string_equal(registry_id_hex(longid, sizeof longid, buf, sizeof buf),
                        "abababababababababab...");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_find_live_workers_only),
        cmocka_unit_test(test_retired_workers_are_bounded),
        cmocka_unit_test(test_hello_first_rate_limit),
        cmocka_unit_test(test_id_hex),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

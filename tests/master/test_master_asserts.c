/*
 * tests/master/test_master_asserts.c: the master's asserts are live
 * (CONTRIBUTING.md, "Invariants"). The scheduler's entry points that
 * resolve a lease take a worker slot that scheduler_worker_add returned;
 * one that was never added is a bug of the master, and the assert stops
 * it before it counts a result against another worker's slot. A build
 * that compiled its asserts away fails here.
 *
 * No thread is started in this process (death_run forks).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "death.h"
#include "scheduler.h"

static void complete_for_unknown_slot(void *arg)
{
    (void)arg;
    scheduler *s = scheduler_new(2, 2, NULL);
    scheduler_complete(s, 3, 1, 0);   /* no worker was ever added */
    scheduler_destroy(&s);
}

static void test_scheduler_slot_assert(void **state)
{
    (void)state;
    assert_death(complete_for_unknown_slot, NULL, "worker < self->nworkers");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scheduler_slot_assert),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

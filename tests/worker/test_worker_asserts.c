/*
 * tests/worker/test_worker_asserts.c: the worker's asserts are live
 * (CONTRIBUTING.md, "Invariants"). A render thread takes tiles from its
 * own run only (0 <= t < nthreads); any other index is a bug of the
 * renderer, stopped by tile_runs' assert before it reads past the runs.
 * A build that compiled its asserts away fails here.
 *
 * No thread is started in this process (death_run forks).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "death.h"
#include "tile_runs.h"

static void take_for_unknown_thread(void *arg)
{
    (void)arg;
    tile_runs r;
    tile_runs_init(&r, 8, 2);
    tile_runs_take(&r, 2);   /* threads 0 and 1 only */
    tile_runs_clear(&r);
}

static void test_tile_runs_thread_assert(void **state)
{
    (void)state;
    assert_death(take_for_unknown_thread, NULL, "t < self->nthreads");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tile_runs_thread_assert),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

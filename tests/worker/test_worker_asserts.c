/*
 * tests/worker/test_worker_asserts.c: the worker's asserts are live
 * (CONTRIBUTING.md, "Invariants"). A render thread takes tiles from its
 * own run only (0 <= t < nthreads); any other index is a bug of the
 * renderer, stopped by tile_runs' assert before it reads past the runs.
 * The file store finishes (hashes and renames into the store) only a
 * transfer with every chunk written. A build that compiled its asserts
 * away fails here.
 *
 * No thread is started in this process (death_run forks).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "death.h"
#include "file_store.h"
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

/* arg: the store's folder */
static void finish_a_partial_transfer(void *arg)
{
    char err[1024];
    file_store *st = file_store_open(arg, 0, err, sizeof err);
    if (!st) {
        fprintf(stderr, "%s\n", err);
        exit(1);
    }
    static const char sha[] = "0123456789abcdef0123456789abcdef"
                              "0123456789abcdef0123456789abcdef";
    static const char bytes[4096];
    file_transfer *t = NULL;
    if (file_store_begin(st, sha, 3 * 1024, 1024, &t, err, sizeof err) != FILE_BEGIN_STARTED) {
        fprintf(stderr, "file_store_begin: %s\n", err);
        exit(1);
    }
    uint64_t off;
    uint32_t len;
    file_transfer_next(t, &off, &len);
    file_transfer_put(t, off, bytes, len, err, sizeof err);   /* one chunk of three */
    file_transfer_finish(&t, err, sizeof err);
    file_store_close(&st);
}

static void test_file_store_finish_assert(void **state)
{
    (void)state;
    char dir[] = "/tmp/aafarm-worker-asserts-XXXXXX";
    assert_non_null(mkdtemp(dir));
    assert_death(finish_a_partial_transfer, dir, "file_transfer_complete(t)");
    char cmd[sizeof dir + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tile_runs_thread_assert),
        cmocka_unit_test(test_file_store_finish_assert),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_tile_runs.c: the standalone renderer's tile runs (worker/tile_runs.c):
 * every tile is handed out exactly once, whatever the interleaving of the
 * threads; a thread's own run comes in order; an idle thread steals the
 * back half of the largest run; real threads racing for tiles lose none.
 */
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "tile_runs.h"

static void test_runs_are_contiguous(void **state)
{
    (void)state;
    tile_runs r;
    tile_runs_init(&r, 10, 3);
    /* 10 tiles over 3 threads: [0,3) [3,6) [6,10) */
    assert_int_equal(tile_runs_take(&r, 0), 0);
    assert_int_equal(tile_runs_take(&r, 1), 3);
    assert_int_equal(tile_runs_take(&r, 2), 6);
    assert_int_equal(tile_runs_take(&r, 0), 1);
    assert_int_equal(tile_runs_take(&r, 0), 2);
    /* thread 0 is done: the largest run left is thread 2's [7,10): it
     * takes the back half, from 9 */
    assert_int_equal(tile_runs_take(&r, 0), 9);
    assert_int_equal(tile_runs_take(&r, 2), 7);
    assert_int_equal(tile_runs_take(&r, 2), 8);
    tile_runs_clear(&r);
}

/* random interleavings: each tile exactly once, then -1 for everybody */
static void test_every_tile_once(void **state)
{
    (void)state;
    srand(12345);
    for (int trial = 0; trial < 200; trial++) {
        int ntiles = rand() % 300, nthreads = 1 + rand() % 9;
        unsigned char *seen = calloc((size_t)ntiles + 1, 1);
        tile_runs r;
        tile_runs_init(&r, ntiles, nthreads);
        int got = 0;
        for (int step = 0; step < 10 * ntiles + 100 && got < ntiles; step++) {
            int t = rand() % nthreads, i = tile_runs_take(&r, t);
            if (i < 0)
                continue;
            assert_in_range(i, 0, ntiles - 1);
            assert_int_equal(seen[i], 0);
            seen[i] = 1;
            got++;
        }
        assert_int_equal(got, ntiles);
        for (int t = 0; t < nthreads; t++)
            assert_int_equal(tile_runs_take(&r, t), -1);
        tile_runs_clear(&r);
        free(seen);
    }
}

typedef struct racer {
    tile_runs *runs;
    int me;
    int *count;                    /* tile -> times handed out */
} racer;

static void *race(void *arg)
{
    racer *rc = arg;
    int i;
    while ((i = tile_runs_take(rc->runs, rc->me)) >= 0)
        __atomic_fetch_add(&rc->count[i], 1, __ATOMIC_RELAXED);
    return NULL;
}

/* real threads racing (stealing included): each tile exactly once */
static void test_threads_race(void **state)
{
    (void)state;
    enum { NT = 4, TILES = 5000 };
    for (int trial = 0; trial < 20; trial++) {
        int *count = calloc(TILES, sizeof *count);
        tile_runs r;
        tile_runs_init(&r, TILES, NT);
        pthread_t tid[NT];
        racer rc[NT];
        for (int t = 0; t < NT; t++) {
            rc[t] = (racer){ &r, t, count };
            pthread_create(&tid[t], NULL, race, &rc[t]);
        }
        for (int t = 0; t < NT; t++)
            pthread_join(tid[t], NULL);
        for (int i = 0; i < TILES; i++)
            assert_int_equal(count[i], 1);
        tile_runs_clear(&r);
        free(count);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runs_are_contiguous),
        cmocka_unit_test(test_every_tile_once),
        cmocka_unit_test(test_threads_race),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_farm_scheduler.c: the master's tile scheduler (master/scheduler.h)
 * without sockets: runs of neighbouring tiles per worker, requeue to the
 * front, deadlines (and leases kept while a worker gets the job's files),
 * end-game duplicates, retries and the job failing, stale
 * and duplicate results, tiles already DONE from a resumed journal, tiles
 * appended while leases are out (a serving master's next job), and a
 * randomised run in which workers come, go,
 * fail and time out while every tile must end up taken exactly once.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "scheduler.h"

static scheduler *make(int tx, int ty, int attempts, int dups, int64_t lease_ms)
{
    scheduler_options o;
    scheduler_options_default(&o);
    o.max_attempts = attempts;
    o.max_duplicates = dups;
    o.lease_ms = lease_ms;
    o.duplicate_after_ms = 0;
    scheduler *s = scheduler_new(tx, ty, &o);
    assert_non_null(s);
    return s;
}

static int grant_tile(scheduler *s, int w, int64_t now, uint64_t *id)
{
    scheduler_lease l;
    if (id) *id = 0;
    if (!scheduler_grant(s, w, now, &l)) return -1;
    assert_int_equal(l.worker, w);
    if (id) *id = l.id;
    return l.tile;
}

static void test_one_worker_row_major(void **state)
{
    (void)state;
    scheduler *s = make(4, 3, 3, 0, 1000);
    int w = scheduler_worker_add(s);
    uint64_t ids[12];
    for (int i = 0; i < 12; i++) assert_int_equal(grant_tile(s, w, 0, &ids[i]), i);
    assert_int_equal(grant_tile(s, w, 0, NULL), -1);   /* no duplicates: off */
    assert_int_equal(scheduler_worker_leases(s, w), 12);
    for (int i = 0; i < 12; i++) {
        assert_false(scheduler_finished(s));
        assert_int_equal(scheduler_complete(s, w, ids[i], 0), SCHEDULER_TAKEN);
        assert_true(scheduler_tile_done(s, i));
    }
    assert_true(scheduler_finished(s));
    assert_int_equal(grant_tile(s, w, 0, NULL), -1);
    scheduler_destroy(&s);
    assert_null(s);
}

/* scheduler_each_lease: the live monitor's view of who holds what */
typedef struct seen_leases {
    int n, tiles[8], workers[8];
} seen_leases;

static void see_lease(void *arg, const scheduler_lease *l)
{
    seen_leases *s = arg;
    assert_true(s->n < 8);
    s->tiles[s->n] = l->tile;
    s->workers[s->n++] = l->worker;
}

static void test_each_lease_visits_the_valid_ones(void **state)
{
    (void)state;
    scheduler *s = make(4, 1, 3, 0, 1000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t ida, idb;
    int ta = grant_tile(s, a, 0, &ida), tb = grant_tile(s, b, 0, &idb);
    seen_leases seen = {0};
    scheduler_each_lease(s, see_lease, &seen);
    assert_int_equal(seen.n, 2);
    assert_int_equal(seen.tiles[0], ta);
    assert_int_equal(seen.workers[0], a);
    assert_int_equal(seen.tiles[1], tb);
    assert_int_equal(seen.workers[1], b);
    assert_int_equal(scheduler_complete(s, a, ida, 10), SCHEDULER_TAKEN);
    memset(&seen, 0, sizeof seen);
    scheduler_each_lease(s, see_lease, &seen);   /* the taken one is gone */
    assert_int_equal(seen.n, 1);
    assert_int_equal(seen.tiles[0], tb);
    scheduler_destroy(&s);
}

static void test_second_worker_splits_longest_run(void **state)
{
    (void)state;
    scheduler *s = make(10, 1, 3, 0, 1000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s), c = scheduler_worker_add(s);
    assert_int_equal(grant_tile(s, a, 0, NULL), 0);
    /* fresh run 1..9: b starts in its middle */
    assert_int_equal(grant_tile(s, b, 0, NULL), 5);
    /* runs now 1..4 and 6..9 (4 each): c takes the middle of the first */
    assert_int_equal(grant_tile(s, c, 0, NULL), 3);
    /* each continues its own run: neighbours stay with one worker */
    assert_int_equal(grant_tile(s, a, 0, NULL), 1);
    assert_int_equal(grant_tile(s, b, 0, NULL), 6);
    assert_int_equal(grant_tile(s, c, 0, NULL), 4);
    assert_int_equal(grant_tile(s, a, 0, NULL), 2);
    /* a's run hits c's tiles: it jumps to the longest run left (7..9) */
    assert_int_equal(grant_tile(s, a, 0, NULL), 8);
    scheduler_destroy(&s);
}

static void test_requeue_goes_first_oldest_first(void **state)
{
    (void)state;
    scheduler *s = make(8, 1, 3, 0, 1000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    assert_int_equal(grant_tile(s, a, 0, NULL), 0);
    assert_int_equal(grant_tile(s, a, 0, NULL), 1);
    uint64_t id2;
    assert_int_equal(grant_tile(s, a, 0, &id2), 2);
    assert_int_equal(scheduler_complete(s, a, id2, 0), SCHEDULER_TAKEN);
    /* a dies holding 0 and 1: both come back, before any fresh tile */
    assert_int_equal(scheduler_worker_remove(s, a), 2);
    assert_int_equal(grant_tile(s, b, 0, NULL), 0);
    assert_int_equal(grant_tile(s, b, 0, NULL), 1);
    assert_int_equal(grant_tile(s, b, 0, NULL), 3);
    /* a removed worker gets nothing, and its results are stale */
    assert_int_equal(grant_tile(s, a, 0, NULL), -1);
    assert_int_equal(scheduler_complete(s, a, 1, 0), SCHEDULER_STALE);
    scheduler_counts c;
    scheduler_counts_get(s, &c);
    assert_int_equal(c.requeued, 2);
    assert_int_equal(c.stale_results, 1);
    assert_int_equal(c.done, 1);
    scheduler_destroy(&s);
}

static void test_deadline_requeues_but_lease_stays_valid(void **state)
{
    (void)state;
    scheduler *s = make(2, 1, 3, 0, 100);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t slow, quick, again;
    assert_int_equal(grant_tile(s, a, 0, &slow), 0);
    assert_int_equal(grant_tile(s, b, 10, &quick), 1);
    assert_int_equal(scheduler_next_deadline(s), 100);
    assert_int_equal(scheduler_expire(s, 99), 0);
    assert_int_equal(grant_tile(s, b, 99, NULL), -1);
    assert_int_equal(scheduler_expire(s, 100), 1);            /* tile 0 is back */
    assert_int_equal(scheduler_next_deadline(s), 110);
    assert_int_equal(grant_tile(s, b, 101, &again), 0);
    /* the expired lease answers first: taken; the new one is a duplicate */
    assert_int_equal(scheduler_check_result(s, a, slow), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_complete(s, a, slow, 0), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_check_result(s, b, again), SCHEDULER_DUPLICATE);
    assert_int_equal(scheduler_complete(s, b, again, 0), SCHEDULER_DUPLICATE);
    assert_int_equal(scheduler_complete(s, b, quick, 0), SCHEDULER_TAKEN);
    assert_true(scheduler_finished(s));
    scheduler_counts c;
    scheduler_counts_get(s, &c);
    assert_int_equal(c.expired, 1);
    assert_int_equal(c.duplicate_results, 1);
    scheduler_destroy(&s);
}

static void test_end_game_duplicates(void **state)
{
    (void)state;
    scheduler *s = make(3, 1, 3, 1, 100000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s), c = scheduler_worker_add(s);
    uint64_t a0, a1, a2, b0, c1;
    assert_int_equal(grant_tile(s, a, 0, &a0), 0);
    assert_int_equal(grant_tile(s, a, 1, &a1), 1);
    assert_int_equal(grant_tile(s, a, 2, &a2), 2);
    /* nothing queued: b duplicates the tile leased longest ago */
    assert_int_equal(grant_tile(s, b, 3, &b0), 0);
    const scheduler_lease *l = scheduler_lease_find(s, b, b0);
    assert_non_null(l);
    assert_true(l->duplicate);
    /* tile 0 has its one duplicate: c gets the next oldest */
    assert_int_equal(grant_tile(s, c, 4, &c1), 1);
    /* a holds every tile already: nothing for it */
    assert_int_equal(grant_tile(s, a, 5, NULL), -1);
    /* first result wins */
    assert_int_equal(scheduler_complete(s, b, b0, 0), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_complete(s, a, a0, 0), SCHEDULER_DUPLICATE);
    assert_int_equal(scheduler_complete(s, a, a1, 0), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_complete(s, c, c1, 0), SCHEDULER_DUPLICATE);
    /* b may now duplicate tile 2 */
    uint64_t b2;
    assert_int_equal(grant_tile(s, b, 6, &b2), 2);
    assert_int_equal(scheduler_complete(s, a, a2, 0), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_complete(s, b, b2, 0), SCHEDULER_DUPLICATE);
    assert_true(scheduler_finished(s));
    scheduler_destroy(&s);
}

static void test_duplicates_wait_for_stragglers(void **state)
{
    (void)state;
    scheduler_options o;
    scheduler_options_default(&o);
    o.max_duplicates = 1;
    o.duplicate_after_ms = 100;
    scheduler *s = scheduler_new(3, 1, &o);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t b2;
    assert_int_equal(grant_tile(s, a, 0, NULL), 0);
    assert_int_equal(grant_tile(s, a, 0, NULL), 1);
    assert_int_equal(grant_tile(s, b, 0, &b2), 2);
    assert_int_equal(scheduler_complete(s, b, b2, 50), SCHEDULER_TAKEN);
    /* mean lease 50 ms: a duplicate only of a lease 150 ms old (3 x 50 > 100) */
    assert_int_equal(grant_tile(s, b, 100, NULL), -1);
    assert_int_equal(grant_tile(s, b, 149, NULL), -1);
    assert_int_equal(grant_tile(s, b, 150, NULL), 0);
    scheduler_destroy(&s);
}

static void test_failures_retry_elsewhere_then_fail_job(void **state)
{
    (void)state;
    scheduler *s = make(4, 1, 3, 0, 100000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t id;
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id, true), SCHEDULER_RETRY);
    assert_int_equal(scheduler_tile_attempts(s, 0), 1);
    /* a failed tile 0: a gets a fresh tile, b gets tile 0 */
    assert_int_equal(grant_tile(s, a, 0, NULL), 1);
    assert_int_equal(grant_tile(s, b, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, b, id, true), SCHEDULER_RETRY);
    /* both failed it: anyone may take it; third failure fails the job */
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_false(scheduler_failed(s));
    assert_int_equal(scheduler_fail(s, a, id, true), SCHEDULER_JOB_FAILED);
    assert_true(scheduler_failed(s));
    assert_int_equal(grant_tile(s, b, 0, NULL), -1);
    scheduler_destroy(&s);
}

/* No single worker ends the job (issue 11): a non-retryable failure is
 * retried on another worker and fails the job only when that one confirms
 * it; alone, a worker fails it only after max_attempts. */
static void test_not_retryable_needs_a_second_worker(void **state)
{
    (void)state;
    scheduler *s = make(2, 2, 5, 0, 1000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t id;
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id + 7, false), SCHEDULER_FAIL_IGNORED);
    assert_false(scheduler_failed(s));
    assert_int_equal(scheduler_fail(s, a, id, false), SCHEDULER_RETRY);
    assert_false(scheduler_failed(s));
    /* the tile goes to b, not back to a */
    assert_int_equal(grant_tile(s, a, 0, NULL), 1);
    assert_int_equal(grant_tile(s, b, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, b, id, false), SCHEDULER_JOB_FAILED);
    assert_true(scheduler_failed(s));
    scheduler_destroy(&s);
    /* alone: retried on the same worker, failed after max_attempts */
    s = make(1, 1, 3, 0, 1000);
    a = scheduler_worker_add(s);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(grant_tile(s, a, 0, &id), 0);
        assert_int_equal(scheduler_fail(s, a, id, false), SCHEDULER_RETRY);
    }
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id, false), SCHEDULER_JOB_FAILED);
    scheduler_destroy(&s);
}

/* Issue 27: while another worker can join (join_window_ms > 0), a tile that
 * one worker alone failed max_attempts times does not end the job: that
 * worker never gets it again, the tile waits for another one, and fails
 * the job only after the window with no one able to take it, or when a
 * second worker agrees. */
static void test_one_worker_alone_waits_for_another(void **state)
{
    (void)state;
    scheduler_options o;
    scheduler_options_default(&o);
    o.max_attempts = 3;
    o.max_duplicates = 0;
    o.lease_ms = 100000;
    o.join_window_ms = 5000;
    scheduler *s = scheduler_new(2, 1, &o);
    int a = scheduler_worker_add(s);
    uint64_t id;
    for (int i = 0; i < 2; i++) {
        assert_int_equal(grant_tile(s, a, 0, &id), 0);
        assert_int_equal(scheduler_fail(s, a, id, i == 0), SCHEDULER_RETRY);
    }
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id, false), SCHEDULER_AWAIT_OTHER);
    assert_false(scheduler_failed(s));
    /* a never gets tile 0 again; it may render the other tile */
    assert_int_equal(grant_tile(s, a, 0, &id), 1);
    assert_int_equal(scheduler_complete(s, a, id, 10), SCHEDULER_TAKEN);
    assert_int_equal(grant_tile(s, a, 20, NULL), -1);
    /* the window runs from the first check with no one to take it */
    assert_int_equal(scheduler_check_given_up(s, 1000), -1);
    assert_int_equal(scheduler_check_given_up(s, 5999), -1);
    /* b joins in time: it gets the tile, the clock stops, it delivers */
    int b = scheduler_worker_add(s);
    assert_int_equal(scheduler_check_given_up(s, 6000), -1);
    assert_int_equal(grant_tile(s, b, 6001, &id), 0);
    assert_int_equal(scheduler_check_given_up(s, 60000), -1);
    assert_int_equal(scheduler_complete(s, b, id, 60001), SCHEDULER_TAKEN);
    assert_true(scheduler_finished(s));
    assert_false(scheduler_failed(s));
    scheduler_destroy(&s);

    /* nobody comes: the job fails once the window has passed */
    s = scheduler_new(1, 1, &o);
    a = scheduler_worker_add(s);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(grant_tile(s, a, 0, &id), 0);
        assert_int_equal(scheduler_fail(s, a, id, true), i < 2 ? SCHEDULER_RETRY
                                                               : SCHEDULER_AWAIT_OTHER);
    }
    assert_int_equal(scheduler_check_given_up(s, 100), -1);
    assert_int_equal(scheduler_check_given_up(s, 5099), -1);
    assert_false(scheduler_failed(s));
    assert_int_equal(scheduler_check_given_up(s, 5100), 0);
    assert_true(scheduler_failed(s));
    scheduler_destroy(&s);

    /* a second worker that fails it too agrees: the job fails at once */
    s = scheduler_new(1, 1, &o);
    a = scheduler_worker_add(s);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(grant_tile(s, a, 0, &id), 0);
        scheduler_fail(s, a, id, true);
    }
    b = scheduler_worker_add(s);
    assert_int_equal(grant_tile(s, b, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, b, id, true), SCHEDULER_JOB_FAILED);
    scheduler_destroy(&s);

    /* one that cannot be granted it (an overdue lease: a hoarder) does not
     * stop the clock */
    s = scheduler_new(2, 1, &o);
    a = scheduler_worker_add(s);
    b = scheduler_worker_add(s);
    assert_int_equal(grant_tile(s, b, 0, NULL), 0);
    assert_int_equal(scheduler_expire(s, 200000), 1);   /* b's lease is overdue */
    assert_true(scheduler_worker_overdue(s, b));
    assert_int_equal(grant_tile(s, a, 200000, &id), 0);
    assert_int_equal(scheduler_complete(s, a, id, 200000), SCHEDULER_TAKEN);
    for (int i = 0; i < 3; i++) {   /* b cannot take it: back to a */
        assert_int_equal(grant_tile(s, a, 200000, &id), 1);
        assert_int_equal(scheduler_fail(s, a, id, true), SCHEDULER_RETRY);
    }
    assert_int_equal(grant_tile(s, a, 200000, NULL), -1);   /* given up */
    assert_int_equal(scheduler_check_given_up(s, 200000), -1);
    assert_int_equal(scheduler_check_given_up(s, 205000), 1);
    scheduler_destroy(&s);
}

/* Without a window (no other worker can join: embedded mode), a tile every
 * worker there is gave up on fails the job at once, also when the worker
 * that could have tried it left. */
static void test_no_window_fails_when_no_one_is_left(void **state)
{
    (void)state;
    /* a gives tile 0 up while b could take it: retried; b leaves before it
     * does: the job fails at the next check */
    scheduler *s = make(1, 1, 1, 0, 100000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t id;
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id, true), SCHEDULER_RETRY);
    assert_int_equal(grant_tile(s, a, 0, NULL), -1);   /* never back to a */
    assert_int_equal(scheduler_check_given_up(s, 1), -1);
    scheduler_worker_remove(s, b);
    assert_false(scheduler_failed(s));
    assert_int_equal(scheduler_check_given_up(s, 2), 0);
    assert_true(scheduler_failed(s));
    scheduler_destroy(&s);
    /* the only worker left exhausts the attempts: it fails at once */
    s = make(1, 1, 2, 0, 100000);
    a = scheduler_worker_add(s);
    b = scheduler_worker_add(s);
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id, true), SCHEDULER_RETRY);
    scheduler_worker_remove(s, b);
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id, true), SCHEDULER_JOB_FAILED);
    scheduler_destroy(&s);
}

/* A lease lasts lease_factor x the measured grant-to-result time (the
 * worker's own once known), at least lease_min_ms: a worker that takes a
 * tile and never returns it loses it soon after the others' speed is
 * known, and gets nothing new while it holds an overdue lease. */
static void test_lease_deadline_follows_measured_rate(void **state)
{
    (void)state;
    scheduler_options o;
    scheduler_options_default(&o);
    o.lease_ms = 120000;
    o.lease_factor = 4;
    o.lease_min_ms = 500;
    o.max_duplicates = 0;
    scheduler *s = scheduler_new(8, 1, &o);
    int honest = scheduler_worker_add(s), hoarder = scheduler_worker_add(s);
    assert_int_equal(scheduler_lease_limit(s, hoarder), 120000);   /* nothing measured */
    scheduler_lease h, l;
    assert_true(scheduler_grant(s, hoarder, 0, &h));
    /* the honest worker takes two tiles in 300 ms each */
    for (int i = 0; i < 2; i++) {
        assert_true(scheduler_grant(s, honest, 1000 * i, &l));
        assert_int_equal(scheduler_complete(s, honest, l.id, 1000 * i + 300), SCHEDULER_TAKEN);
    }
    assert_int_equal(scheduler_lease_limit(s, honest), 1200);
    assert_int_equal(scheduler_lease_limit(s, hoarder), 1200);   /* the farm's measure */
    /* the hoarder's lease, granted before anything was measured, now
     * passes its deadline at 1200 ms, not 120 s */
    assert_int_equal(scheduler_expire(s, 1100), 0);
    assert_int_equal(scheduler_expire(s, 1200), 1);
    assert_true(scheduler_worker_overdue(s, hoarder));
    assert_false(scheduler_grant(s, hoarder, 1300, &l));   /* nothing new for it */
    assert_true(scheduler_grant(s, honest, 1300, &l));
    assert_int_equal(l.tile, h.tile);                      /* its tile went to another */
    /* a late result is still taken and lifts the block */
    assert_int_equal(scheduler_complete(s, hoarder, h.id, 5000), SCHEDULER_TAKEN);
    assert_false(scheduler_worker_overdue(s, hoarder));
    assert_int_equal(scheduler_lease_limit(s, hoarder), 4 * 5000);   /* its own measure */
    assert_true(scheduler_grant(s, hoarder, 5000, &l));
    /* the honest worker's copy of that tile is a duplicate now */
    assert_int_equal(scheduler_complete(s, honest, l.id - 1, 1310), SCHEDULER_DUPLICATE);
    scheduler_destroy(&s);
}

/* A worker getting the job's files (scheduler_worker_waiting) keeps the
 * leases it holds while it makes progress: they last the longest lease
 * from its last progress, not the farm's measured rate from the grant;
 * from FilesReady on, the measured rate from then; one that stops making
 * progress loses them lease_ms after its last chunk; its fetch does not
 * count in its speed. */
static void test_waiting_for_files_keeps_leases(void **state)
{
    (void)state;
    scheduler_options o;
    scheduler_options_default(&o);
    o.lease_ms = 10000;
    o.lease_factor = 4;
    o.lease_min_ms = 500;
    o.max_duplicates = 0;
    scheduler *s = scheduler_new(8, 1, &o);
    int fast = scheduler_worker_add(s), fetcher = scheduler_worker_add(s);
    scheduler_lease l, f1, f2;
    for (int i = 0; i < 2; i++) {             /* the farm's rate: 300 ms a tile */
        assert_true(scheduler_grant(s, fast, 1000 * i, &l));
        assert_int_equal(scheduler_complete(s, fast, l.id, 1000 * i + 300), SCHEDULER_TAKEN);
    }
    assert_int_equal(scheduler_lease_limit(s, fetcher), 1200);
    scheduler_worker_waiting(s, fetcher, true, 2000);   /* the Job went to it */
    assert_int_equal(scheduler_lease_limit(s, fetcher), 10000);
    assert_true(scheduler_grant(s, fetcher, 2000, &f1));
    assert_true(scheduler_grant(s, fetcher, 2000, &f2));
    for (int64_t now = 2000; now <= 30000; now += 1000) {   /* a chunk a second, 28 s */
        scheduler_worker_waiting(s, fetcher, true, now);
        assert_int_equal(scheduler_expire(s, now + 999), 0);
    }
    assert_false(scheduler_worker_overdue(s, fetcher));
    scheduler_worker_waiting(s, fetcher, false, 31000); /* FilesReady */
    assert_int_equal(scheduler_expire(s, 31000 + 1199), 0);
    assert_int_equal(scheduler_complete(s, fetcher, f1.id, 31500), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_lease_limit(s, fetcher), 4 * 500);   /* not 4 x 29.5 s */
    /* another fetch that stalls: the lease goes lease_ms after the last chunk */
    scheduler_worker_waiting(s, fetcher, true, 40000);
    assert_int_equal(scheduler_expire(s, 40000 + 9999), 0);
    assert_int_equal(scheduler_expire(s, 40000 + 10000), 1);
    assert_true(scheduler_worker_overdue(s, fetcher));
    (void)f2;
    scheduler_destroy(&s);
}

static void test_only_worker_gets_its_failed_tile_back(void **state)
{
    (void)state;
    scheduler *s = make(1, 1, 3, 0, 1000);
    int a = scheduler_worker_add(s);
    uint64_t id;
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_fail(s, a, id, true), SCHEDULER_RETRY);
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_complete(s, a, id, 0), SCHEDULER_TAKEN);
    assert_true(scheduler_finished(s));
    scheduler_destroy(&s);
}

static void test_stale_results(void **state)
{
    (void)state;
    scheduler *s = make(2, 1, 3, 0, 1000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t id;
    assert_int_equal(grant_tile(s, a, 0, &id), 0);
    assert_int_equal(scheduler_check_result(s, b, id), SCHEDULER_STALE);  /* not b's */
    assert_int_equal(scheduler_complete(s, b, id, 0), SCHEDULER_STALE);
    assert_int_equal(scheduler_complete(s, a, 0, 0), SCHEDULER_STALE);
    assert_int_equal(scheduler_complete(s, a, 999, 0), SCHEDULER_STALE);
    assert_int_equal(scheduler_complete(s, a, id, 0), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_complete(s, a, id, 0), SCHEDULER_STALE);      /* resolved */
    assert_null(scheduler_lease_find(s, a, id));
    assert_null(scheduler_new(0, 5, NULL));
    assert_null(scheduler_new(1 << 16, 1 << 16, NULL));
    scheduler_destroy(&s);
}

/* Random workers that join, die, fail, stall and answer in random order;
 * at the end every tile must have been taken exactly once. */
/* The end of the queue: 5 tiles, two workers of one thread each. While
 * more tiles are queued than the 2 threads, a busy worker gets a second
 * tile for its pipeline; after that a tile goes only to a worker with an
 * idle thread, so the last one does not wait behind a busy worker's tile
 * while the other worker is idle. A worker that never told its threads
 * is not held back. */
static void test_end_of_queue_goes_to_idle_threads(void **state)
{
    (void)state;
    scheduler *s = make(5, 1, 3, 0, 100000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    scheduler_worker_threads(s, a, 1);
    scheduler_worker_threads(s, b, 1);
    uint64_t ia, ia2, ib, ib2;
    assert_int_equal(grant_tile(s, a, 0, &ia), 0);    /* 4 left queued */
    assert_int_equal(grant_tile(s, a, 0, &ia2), 1);   /* pipelined: 3 > 2 threads */
    assert_true(grant_tile(s, b, 0, &ib) >= 2);       /* b is idle: 2 left */
    assert_int_equal(grant_tile(s, b, 0, NULL), -1);  /* 2 <= 2: no pipeline for b */
    assert_int_equal(grant_tile(s, a, 0, NULL), -1);  /* nor for a */
    assert_int_equal(scheduler_complete(s, b, ib, 10), SCHEDULER_TAKEN);
    assert_true(grant_tile(s, b, 10, &ib2) >= 2);     /* b's thread is idle again */
    assert_int_equal(grant_tile(s, b, 10, NULL), -1);
    assert_int_equal(scheduler_complete(s, a, ia, 20), SCHEDULER_TAKEN);
    assert_int_equal(grant_tile(s, a, 20, NULL), -1); /* a's pipeline holds tile 1 */
    assert_int_equal(scheduler_complete(s, a, ia2, 30), SCHEDULER_TAKEN);
    assert_true(grant_tile(s, a, 30, NULL) >= 2);     /* the last one */
    assert_int_equal(scheduler_complete(s, b, ib2, 40), SCHEDULER_TAKEN);
    scheduler_destroy(&s);

    /* threads never told: pipelined to the end, as before the rule */
    s = make(3, 1, 3, 0, 100000);
    a = scheduler_worker_add(s);
    for (int t = 0; t < 3; t++) assert_int_equal(grant_tile(s, a, 0, NULL), t);
    scheduler_destroy(&s);
}

static void test_random_farm_takes_every_tile_once(void **state)
{
    (void)state;
    srand(12345);
    for (int round = 0; round < 20; round++) {
        int tx = 1 + rand() % 9, ty = 1 + rand() % 7, n = tx * ty;
        scheduler *s = make(tx, ty, 1000, rand() % 3, 50);
        int *taken = calloc((size_t)n, sizeof *taken);
        typedef struct { int w; uint64_t id; } held;
        held *out = NULL;
        size_t nout = 0;
        int workers[64], nw = 0;
        workers[nw++] = scheduler_worker_add(s);
        int64_t now = 0;
        scheduler_counts c;
        for (int step = 0; step < 100000 && !scheduler_finished(s); step++) {
            now += rand() % 7;
            int r = rand() % 100;
            if (r < 3 && nw < 64) {
                workers[nw++] = scheduler_worker_add(s);
                /* some told their threads (the end of the queue's rule) */
                if (rand() % 3) scheduler_worker_threads(s, workers[nw - 1], 1 + rand() % 2);
            } else if (r < 5 && nw > 1) {
                int k = rand() % nw;
                scheduler_worker_remove(s, workers[k]);
                workers[k] = workers[--nw];
            } else if (r < 45) {
                int w = workers[rand() % nw];
                scheduler_lease l;
                if (scheduler_grant(s, w, now, &l)) {
                    out = realloc(out, sizeof *out * (nout + 1));
                    out[nout++] = (held){w, l.id};
                }
            } else if (r < 90 && nout > 0) {
                size_t k = (size_t)rand() % nout;
                held h = out[k];
                out[k] = out[--nout];
                const scheduler_lease *l = scheduler_lease_find(s, h.w, h.id);
                int tile = l ? l->tile : -1;
                if (rand() % 10 == 0) {
                    scheduler_fail(s, h.w, h.id, true);
                } else if (scheduler_complete(s, h.w, h.id, now) == SCHEDULER_TAKEN) {
                    assert_true(tile >= 0);
                    taken[tile]++;
                }
            } else {
                scheduler_expire(s, now);
            }
            /* its running count of queued tiles agrees with a count of
             * the tiles (an assert in scheduler_counts_get) */
            scheduler_counts_get(s, &c);
            assert_true(c.queued + c.leased + c.done == c.tiles);
        }
        assert_true(scheduler_finished(s));
        assert_false(scheduler_failed(s));
        for (int i = 0; i < n; i++) assert_int_equal(taken[i], 1);
        free(taken);
        free(out);
        scheduler_destroy(&s);
    }
}

/* --resume: journaled tiles are DONE before any grant and never granted */
static void test_resumed_tiles_never_granted(void **state)
{
    (void)state;
    scheduler *s = make(4, 3, 3, 1, 1000);
    int done[] = {0, 1, 5, 6, 11};
    for (int i = 0; i < 5; i++) assert_true(scheduler_mark_done(s, done[i]));
    assert_false(scheduler_mark_done(s, 5));    /* twice */
    assert_false(scheduler_mark_done(s, 12));   /* out of range */
    assert_false(scheduler_mark_done(s, -1));
    assert_int_equal(scheduler_tiles_done(s), 5);
    int w = scheduler_worker_add(s);
    uint64_t ids[7];
    int want[] = {7, 8, 9, 10, 2, 3, 4};   /* the longest run of fresh tiles first */
    for (int i = 0; i < 7; i++) assert_int_equal(grant_tile(s, w, 0, &ids[i]), want[i]);
    int t = grant_tile(s, w, 0, NULL);   /* end game: a duplicate at most, never a DONE tile */
    assert_true(t == -1 || (t != 0 && t != 1 && t != 5 && t != 6 && t != 11));
    assert_false(scheduler_mark_done(s, 2));    /* leased */
    for (int i = 0; i < 7; i++) assert_int_equal(scheduler_complete(s, w, ids[i], 0), SCHEDULER_TAKEN);
    assert_true(scheduler_finished(s));
    scheduler_destroy(&s);
}

/* A serving master's next job joins the queue while the last tiles of
 * the previous one are leased: its tiles go to the idle worker at once
 * (before any duplicate), the old leases' results are still taken, and
 * the queue is finished only when both jobs' tiles are in. */
static void test_extend_while_leases_are_out(void **state)
{
    (void)state;
    scheduler *s = make(4, 1, 3, 1, 1000);
    int a = scheduler_worker_add(s), b = scheduler_worker_add(s);
    uint64_t ids[4];
    for (int i = 0; i < 4; i++) assert_true(grant_tile(s, i < 2 ? a : b, 0, &ids[i]) >= 0);
    assert_int_equal(scheduler_complete(s, a, ids[0], 10), SCHEDULER_TAKEN);
    assert_true(scheduler_extend(s, 3));
    scheduler_counts c;
    scheduler_counts_get(s, &c);
    assert_int_equal(c.tiles, 7);
    assert_int_equal(c.queued, 3);
    assert_int_equal(c.leased, 3);
    uint64_t more[3];
    for (int i = 0; i < 3; i++) assert_int_equal(grant_tile(s, a, 20, &more[i]), 4 + i);
    assert_int_equal(scheduler_complete(s, a, ids[1], 30), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_complete(s, b, ids[2], 30), SCHEDULER_TAKEN);
    assert_int_equal(scheduler_complete(s, b, ids[3], 30), SCHEDULER_TAKEN);
    assert_false(scheduler_finished(s));
    for (int i = 0; i < 3; i++) assert_int_equal(scheduler_complete(s, a, more[i], 40), SCHEDULER_TAKEN);
    assert_true(scheduler_finished(s));
    assert_false(scheduler_extend(s, INT_MAX / 2));   /* too many to count: unchanged */
    assert_true(scheduler_finished(s));
    scheduler_destroy(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_worker_row_major),
        cmocka_unit_test(test_second_worker_splits_longest_run),
        cmocka_unit_test(test_requeue_goes_first_oldest_first),
        cmocka_unit_test(test_deadline_requeues_but_lease_stays_valid),
        cmocka_unit_test(test_end_game_duplicates),
        cmocka_unit_test(test_duplicates_wait_for_stragglers),
        cmocka_unit_test(test_failures_retry_elsewhere_then_fail_job),
        cmocka_unit_test(test_not_retryable_needs_a_second_worker),
        cmocka_unit_test(test_lease_deadline_follows_measured_rate),
        cmocka_unit_test(test_waiting_for_files_keeps_leases),
        cmocka_unit_test(test_only_worker_gets_its_failed_tile_back),
        cmocka_unit_test(test_one_worker_alone_waits_for_another),
        cmocka_unit_test(test_no_window_fails_when_no_one_is_left),
        cmocka_unit_test(test_stale_results),
        cmocka_unit_test(test_each_lease_visits_the_valid_ones),
        cmocka_unit_test(test_resumed_tiles_never_granted),
        cmocka_unit_test(test_end_of_queue_goes_to_idle_threads),
        cmocka_unit_test(test_random_farm_takes_every_tile_once),
        cmocka_unit_test(test_extend_while_leases_are_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

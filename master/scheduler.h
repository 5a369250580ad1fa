/*
 * scheduler.h: which tile goes to which worker, and when it comes back
 * (the master's tile bookkeeping of docs/protocol.md, "The master's state
 * machine"). Pure logic: no sockets, no clocks (the caller passes the time
 * in milliseconds), so every rule is unit-tested in
 * tests/master/test_farm_scheduler.c.
 *
 * Terms:
 *   tile    one rectangle of the image's tile grid, numbered row-major;
 *           PENDING until a result is taken, then DONE.
 *   lease   one grant of one tile to one worker, with a deadline. A tile
 *           is "queued" while it is PENDING and no unexpired lease holds
 *           it. A lease past its deadline stays valid (its result is still
 *           taken) but no longer keeps the tile out of the queue.
 *   worker  a slot number handed out by scheduler_worker_add(); the master
 *           maps routing ids to slots (registry.h).
 *
 * Rules (each one a test):
 *   - requeued tiles (deadline passed, worker gone, failure) are granted
 *     before fresh ones, oldest first ("the queue's front");
 *   - fresh tiles are granted in runs: a worker continues after its last
 *     tile in row-major order, so neighbouring tiles go to the same worker
 *     and its box caches stay warm (Heidrich & Seidel §6; Pharr & Hanrahan
 *     on tile orders); a worker without a run starts a new one in the
 *     longest run of queued tiles: in its middle when another worker's run
 *     is about to continue into it, at its start otherwise;
 *   - end game: when nothing is queued, a worker may get a duplicate lease
 *     of the outstanding tile leased longest ago that it does not hold
 *     (at most max_duplicates extra leases per tile), once that lease is
 *     older than duplicate_after_ms and 3 x the mean lease time so far (a
 *     straggler, not a tile about to arrive: duplicates cost CPU); the
 *     first result wins, later ones are duplicates (results are
 *     deterministic);
 *   - a failed tile is requeued, avoiding the workers that failed it while
 *     another worker is there to take it. The job fails only when two
 *     different workers agree (issues 11 and 27): on a non-retryable
 *     failure once a second, different worker confirms it (until then it
 *     counts as a retryable one), and after max_attempts failures when
 *     they came from two workers. A tile that one worker alone failed
 *     max_attempts times is "given up" by it: it never gets that tile
 *     again, and the tile waits for another worker; only when no active
 *     worker that has not failed it is there for join_window_ms (0: at
 *     once, when no other worker can join) does it fail the job
 *     (scheduler_check_given_up);
 *   - the end of the queue: a worker whose threads are all busy (it holds
 *     as many leases as it has threads, scheduler_worker_threads) gets no
 *     further tile while no more tiles are queued than the active workers
 *     have threads in all: near the end a tile goes to a worker with an
 *     idle thread rather than waiting in a busy worker's pipeline (2 leases
 *     a thread: worker_loop.c) while other workers run dry. A worker whose
 *     threads were never told is not held back;
 *   - lease deadlines follow the measured speed: a lease lasts
 *     lease_factor x the mean grant-to-result time of its worker (of all
 *     workers until this one has delivered a tile; lease_ms until anyone
 *     has), clamped to [lease_min_ms, lease_ms], judged when it is checked,
 *     so a worker that takes tiles and never returns them (a hoarder) loses
 *     them to others soon after the others' speed is known; a worker
 *     holding an expired lease gets no new tile until it delivers.
 *
 * Cost: grants, results and failures are O(log leases) except when a
 * worker starts a new run, which scans the tile states once (O(tiles)).
 */
#ifndef MASTER_SCHEDULER_H
#define MASTER_SCHEDULER_H

#include <stdbool.h>
#include <stdint.h>

typedef struct scheduler_options {
    int max_attempts;      /* failures of one tile that fail the job (3) */
    int max_duplicates;    /* extra end-game leases per tile (1; 0: none) */
    int64_t lease_ms;      /* a lease's duration (120000) */
    int64_t duplicate_after_ms; /* duplicate only leases at least this old, and
                                   at least 3 x the mean time from grant to
                                   result so far (1000) */
    int lease_factor;      /* a lease lasts lease_factor x the measured mean
                              grant-to-result time (4; 0: always lease_ms) */
    int64_t lease_min_ms;  /* but at least this long (2000) */
    int64_t join_window_ms; /* how long a tile one worker alone gave up on
                               waits for another worker before it fails the
                               job (0: no other worker can join, fail at once) */
} scheduler_options;

void scheduler_options_default(scheduler_options *opt);

typedef struct scheduler_lease {
    uint64_t id;           /* 1, 2, 3 ... in grant order */
    int worker;            /* the slot it was granted to */
    int tile;              /* row-major tile index */
    int64_t granted_ms;
    int64_t from_ms;       /* its clock: the grant, or its worker's last progress
                              while that waited for the job's files */
    int64_t deadline_ms;
    bool duplicate;        /* granted while another live lease held the tile */
    bool expired;          /* its deadline passed (still valid) */
} scheduler_lease;

/* What became of a result. */
typedef enum scheduler_verdict {
    SCHEDULER_TAKEN,       /* the tile is DONE now */
    SCHEDULER_DUPLICATE,   /* the tile was already DONE: dropped */
    SCHEDULER_STALE        /* no such lease for this worker: dropped */
} scheduler_verdict;

/* What became of a failure. */
typedef enum scheduler_failure {
    SCHEDULER_RETRY,       /* the tile will be granted again */
    SCHEDULER_JOB_FAILED,  /* two workers agree (attempts exhausted or not
                              retryable), or one alone and none can join */
    SCHEDULER_FAIL_IGNORED,/* stale lease, or the tile is DONE already */
    SCHEDULER_AWAIT_OTHER  /* this worker alone exhausted the attempts and no
                              other one is there: the tile waits for one
                              (join_window_ms; scheduler_check_given_up) */
} scheduler_failure;

/* Counters for logs and the statistics file. */
typedef struct scheduler_counts {
    int tiles, done, queued, leased;  /* leased: tiles with a live lease */
    uint64_t grants, duplicate_grants;
    uint64_t requeued;                /* tiles put back in the queue */
    uint64_t expired;                 /* leases that passed their deadline */
    uint64_t duplicate_results, stale_results, failures;
} scheduler_counts;

typedef struct scheduler scheduler;

/* A scheduler for a tiles_x by tiles_y grid (both >= 1); NULL when the
 * grid is too large to count (more than INT_MAX/2 tiles). opt NULL means
 * the defaults. */
scheduler *scheduler_new(int tiles_x, int tiles_y, const scheduler_options *opt);
void scheduler_destroy(scheduler **self_p);

/* Appends `more` (>= 1) PENDING tiles after the last one (a serving
 * master's next job joins the queue while the last tiles of the previous
 * one are out: docs/farm.md "A job queue"); numbers, leases and workers
 * stay as they are. False (nothing changed) when the total would be too
 * large to count. */
bool scheduler_extend(scheduler *self, int more);

/* A new worker slot (0, 1, 2 ...; never reused). */
int scheduler_worker_add(scheduler *self);

/* The worker renders with `threads` (>= 1) threads (its Hello): the end of
 * the queue's rule above. */
void scheduler_worker_threads(scheduler *self, int worker, int threads);

/* The worker is gone, or blocklisted for the job (the master stops
 * granting to it while it stays connected): its leases become unknown (their results are stale)
 * and their tiles go back to the queue's front. Returns the number of
 * tiles requeued. */
int scheduler_worker_remove(scheduler *self, int worker);

/* Grants one tile to the worker, or returns false when there is nothing it
 * should take (everything done or leased, or the job failed). */
bool scheduler_grant(scheduler *self, int worker, int64_t now_ms, scheduler_lease *out);

/* The live lease with this id held by this worker, or NULL. The pointer is
 * valid until the next call that changes the scheduler. */
const scheduler_lease *scheduler_lease_find(const scheduler *self, int worker,
                                            uint64_t lease_id);

/* Would a result for this lease be taken? (No change; lets the caller
 * validate the tile's bytes before committing.) */
scheduler_verdict scheduler_check_result(const scheduler *self, int worker, uint64_t lease_id);

/* Resolves the lease with a result at now_ms: TAKEN marks the tile DONE
 * (and counts the lease's time for the end game's threshold); the lease is
 * gone in every case. */
scheduler_verdict scheduler_complete(scheduler *self, int worker, uint64_t lease_id,
                                     int64_t now_ms);

/* Resolves the lease with a failure. */
scheduler_failure scheduler_fail(scheduler *self, int worker, uint64_t lease_id, bool retryable);

/* The tiles one worker alone gave up on (SCHEDULER_AWAIT_OTHER): a tile
 * that has had no active worker able to take it (one that has not failed
 * it and holds no overdue lease) and no lease for join_window_ms fails the
 * job now. Returns that tile (the job is failed), or -1. Call it from the
 * timers. */
int scheduler_check_given_up(scheduler *self, int64_t now_ms);

/* A tile that is already in the output (a resumed render's journal):
 * DONE before any grant. False when the tile is out of range, DONE or
 * leased already. */
bool scheduler_mark_done(scheduler *self, int tile);

/* Marks leases whose deadline (granted + scheduler_lease_limit of their
 * worker now) is <= now_ms as expired and requeues their tiles. Returns
 * the number of tiles requeued. */
int scheduler_expire(scheduler *self, int64_t now_ms);
/* The same, and the first max of the requeued tiles into tiles (NULL when
 * max is 0), for the master's log line. */
int scheduler_expire_list(scheduler *self, int64_t now_ms, int *tiles, int max);

/* The worker is getting the job's files (waiting: the Job was sent to it
 * and its FilesReady has not come; docs/textures.md): its live leases'
 * clocks start again now, and while it waits they last lease_ms (the
 * longest), so a long fetch or hash does not requeue the tiles it holds.
 * The master calls it when it sends such a worker the Job and each file
 * chunk (waiting), and at FilesReady (not waiting: from then on the
 * measured speed rules). A worker that stops making progress loses its
 * leases lease_ms after its last chunk. */
void scheduler_worker_waiting(scheduler *self, int worker, bool waiting, int64_t now_ms);

/* How long a lease granted to this worker now would last (ms): see the
 * rule above. */
int64_t scheduler_lease_limit(const scheduler *self, int worker);

/* Does the worker hold a lease that passed its deadline (it gets no new
 * grant until it delivers or is gone)? */
bool scheduler_worker_overdue(const scheduler *self, int worker);

/* The earliest deadline of an unexpired lease, or INT64_MAX. */
int64_t scheduler_next_deadline(const scheduler *self);

bool scheduler_finished(const scheduler *self);   /* every tile DONE */
int scheduler_tiles_done(const scheduler *self);
bool scheduler_failed(const scheduler *self);     /* the job failed */
bool scheduler_tile_done(const scheduler *self, int tile);
int scheduler_tile_attempts(const scheduler *self, int tile);  /* failures so far */
int scheduler_worker_leases(const scheduler *self, int worker); /* live leases held */
void scheduler_counts_get(const scheduler *self, scheduler_counts *out);
/* Calls fn with every valid lease (expired or not), oldest grant first
 * (the live monitor's tile states). fn must not change the scheduler. */
void scheduler_each_lease(const scheduler *self,
                          void (*fn)(void *arg, const scheduler_lease *lease), void *arg);

#endif

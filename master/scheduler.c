/*
 * scheduler.c: tiles, leases, requeues, end-game duplicates and retries
 * (see scheduler.h for the rules and docs/protocol.md for where they come
 * from).
 *
 * Data:
 *   tiles[]   per tile: done, failures so far, live leases (unexpired) and
 *             held leases (all valid ones), whether it sits in the requeue
 *             list. "Queued" = PENDING and no live lease.
 *   leases[]  every valid lease, appended in grant order; since ids grow
 *             with every grant the array stays sorted by id, so a lookup is
 *             a binary search. A resolved lease becomes a hole (id 0) and
 *             the holes are squeezed out when they are half the array.
 *   rq[]      the requeue list ("the queue's front"): tiles that were
 *             leased before and came back, oldest first, each at most once;
 *             entries that are no longer queued are skipped lazily.
 *   failed[]  (tile, worker) pairs of failures, to prefer other workers.
 *   given_up[] tiles one worker alone failed max_attempts times, each with
 *             the time since which no other worker could take it (0: one
 *             can, or holds it), for join_window_ms.
 */
#include "scheduler.h"
#include "util/xalloc.h"

#include <assert.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

typedef struct tile_state {
    uint8_t done;
    uint8_t in_rq;
    uint8_t given_up;  /* its failers never get it again (scheduler.h) */
    uint16_t attempts;
    uint32_t live;     /* unexpired leases */
    uint32_t held;     /* valid leases, expired or not */
} tile_state;

typedef struct worker_slot {
    bool active;
    int cursor;        /* last fresh tile granted, -1: none yet */
    int taken;         /* results taken from it, and their grant-to-result time */
    int64_t taken_ms_sum;
    int overdue;       /* its valid leases past their deadline */
    bool waiting;      /* getting the job's files (scheduler_worker_waiting) */
    int threads;       /* its rendering threads (0: not told) */
    int held;          /* its valid leases */
} worker_slot;

typedef struct failed_pair {
    int tile, worker;
} failed_pair;

typedef struct given_up_tile {
    int tile;
    int64_t since_ms;  /* no one else could take it since then; 0: someone can */
} given_up_tile;

struct scheduler {
    scheduler_options opt;
    int ntiles;
    tile_state *tiles;
    scheduler_lease *leases;
    size_t nleases, cap_leases, holes;
    uint64_t next_id;
    int *rq;
    int rq_head, rq_len;
    worker_slot *workers;
    int nworkers;
    failed_pair *failed;
    size_t nfailed;
    given_up_tile *given_up;
    size_t ngiven_up;
    bool job_failed;
    int done;
    int nqueued;               /* tiles queued(): PENDING, no live lease */
    int threads;               /* the active workers' threads told, in all */
    int64_t taken_ms_sum;      /* grant-to-result time of taken leases */
    int taken;                 /* their number (done counts resumed tiles too) */
    scheduler_counts counts;
};

void scheduler_options_default(scheduler_options *opt)
{
    opt->max_attempts = 3;
    opt->lease_factor = 4;
    opt->lease_min_ms = 2000;
    opt->max_duplicates = 1;
    opt->lease_ms = 120000;
    opt->duplicate_after_ms = 1000;
    opt->join_window_ms = 0;
}

scheduler *scheduler_new(int tiles_x, int tiles_y, const scheduler_options *opt)
{
    if (tiles_x < 1 || tiles_y < 1 || tiles_x > INT_MAX / 2 / tiles_y)
        return NULL;
    scheduler *self = xcalloc(1, sizeof *self);
    if (opt) self->opt = *opt;
    else scheduler_options_default(&self->opt);
    if (self->opt.max_attempts < 1) self->opt.max_attempts = 1;
    if (self->opt.max_attempts > 1000) self->opt.max_attempts = 1000;
    if (self->opt.max_duplicates < 0) self->opt.max_duplicates = 0;
    if (self->opt.lease_ms < 1) self->opt.lease_ms = 1;
    self->ntiles = tiles_x * tiles_y;
    self->tiles = xcalloc((size_t)self->ntiles, sizeof *self->tiles);
    self->rq = xcalloc((size_t)self->ntiles, sizeof *self->rq);
    self->next_id = 1;
    self->counts.tiles = self->ntiles;
    self->nqueued = self->ntiles;
    return self;
}

void scheduler_destroy(scheduler **self_p)
{
    scheduler *self = *self_p;
    if (!self) return;
    free(self->tiles);
    free(self->leases);
    free(self->rq);
    free(self->workers);
    free(self->failed);
    free(self->given_up);
    free(self);
    *self_p = NULL;
}

bool scheduler_extend(scheduler *self, int more)
{
    assert(more >= 1);   /* a job has tiles */
    if (more > INT_MAX / 2 - self->ntiles) return false;
    int n = self->ntiles + more;
    self->tiles = xreallocarray(self->tiles, (size_t)n, sizeof *self->tiles);
    memset(&self->tiles[self->ntiles], 0, (size_t)more * sizeof *self->tiles);
    self->rq = xreallocarray(self->rq, (size_t)n, sizeof *self->rq);
    self->ntiles = n;
    self->counts.tiles = n;
    self->nqueued += more;
    return true;
}

int scheduler_worker_add(scheduler *self)
{
    self->workers = xrealloc(self->workers, sizeof *self->workers * (size_t)(self->nworkers + 1));
    self->workers[self->nworkers] = (worker_slot){.active = true, .cursor = -1};
    return self->nworkers++;
}

static bool worker_ok(const scheduler *self, int worker)
{
    return worker >= 0 && worker < self->nworkers && self->workers[worker].active;
}

void scheduler_worker_threads(scheduler *self, int worker, int threads)
{
    assert(threads >= 1);
    if (!worker_ok(self, worker)) return;
    self->threads += threads - self->workers[worker].threads;
    self->workers[worker].threads = threads;
}

/* ---- tiles and the requeue list ---- */

static bool queued(const scheduler *self, int tile)
{
    const tile_state *t = &self->tiles[tile];
    return !t->done && t->live == 0;
}

/* Drops resolved entries and holes from the requeue list. */
static void rq_compact(scheduler *self)
{
    int j = 0;
    for (int i = self->rq_head; i < self->rq_len; i++) {
        int t = self->rq[i];
        if (t < 0) continue;
        if (queued(self, t)) self->rq[j++] = t;
        else self->tiles[t].in_rq = 0;
    }
    self->rq_head = 0;
    self->rq_len = j;
}

static void rq_push(scheduler *self, int tile)
{
    if (self->tiles[tile].in_rq) return;
    if (self->rq_len == self->ntiles) rq_compact(self);
    self->rq[self->rq_len++] = tile;
    self->tiles[tile].in_rq = 1;
    self->counts.requeued++;
}

static void rq_take(scheduler *self, int i)
{
    assert(self->rq[i] >= 0 && self->tiles[self->rq[i]].in_rq);
    self->tiles[self->rq[i]].in_rq = 0;
    self->rq[i] = -1;
    while (self->rq_head < self->rq_len && self->rq[self->rq_head] < 0) self->rq_head++;
}

/* A tile lost a live lease: back to the queue when nothing else holds it. */
static void tile_lost_live(scheduler *self, int tile)
{
    tile_state *t = &self->tiles[tile];
    assert(t->live > 0);   /* lease counts balance: a live lease was counted */
    t->live--;
    if (!t->done && t->live == 0) {
        self->nqueued++;
        rq_push(self, tile);
    }
}

static bool failed_by(const scheduler *self, int tile, int worker)
{
    for (size_t i = 0; i < self->nfailed; i++)
        if (self->failed[i].tile == tile && self->failed[i].worker == worker) return true;
    return false;
}

/* Is there an active worker other than `worker` that has not failed tile
 * (and, with ready, holds no overdue lease, so it would be granted it)? */
static bool other_for(const scheduler *self, int tile, int worker, bool ready)
{
    for (int w = 0; w < self->nworkers; w++)
        if (w != worker && self->workers[w].active && !failed_by(self, tile, w) &&
            (!ready || self->workers[w].overdue == 0))
            return true;
    return false;
}

static bool someone_else_for(const scheduler *self, int tile, int worker)
{
    return other_for(self, tile, worker, false);
}

/* ---- leases ---- */

static scheduler_lease *lease_lookup(const scheduler *self, uint64_t id)
{
    size_t lo = 0, hi = self->nleases;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        uint64_t at = self->leases[mid].id;
        /* holes (id 0) keep their neighbours' order: search past them */
        size_t probe = mid;
        while (at == 0 && probe + 1 < hi) at = self->leases[++probe].id;
        if (at == 0 || at > id) hi = mid;
        else if (at < id) lo = probe + 1;
        else return &self->leases[probe];
    }
    return NULL;
}

static void leases_compact(scheduler *self)
{
    size_t j = 0;
    for (size_t i = 0; i < self->nleases; i++)
        if (self->leases[i].id) self->leases[j++] = self->leases[i];
    self->nleases = j;
    self->holes = 0;
}

static void lease_remove(scheduler *self, scheduler_lease *l)
{
    int tile = l->tile;
    bool was_live = !l->expired;
    if (l->expired && l->worker >= 0 && l->worker < self->nworkers) {
        assert(self->workers[l->worker].overdue > 0);
        self->workers[l->worker].overdue--;
    }
    assert(l->id != 0 && self->tiles[tile].held > 0);   /* a lease is held once */
    if (l->worker >= 0 && l->worker < self->nworkers) {
        assert(self->workers[l->worker].held > 0);
        self->workers[l->worker].held--;
    }
    l->id = 0;
    self->holes++;
    self->tiles[tile].held--;
    if (was_live) tile_lost_live(self, tile);
    if (self->holes * 2 > self->nleases) leases_compact(self);
}

static void lease_add(scheduler *self, int worker, int tile, int64_t now, bool dup,
                      scheduler_lease *out)
{
    if (self->nleases == self->cap_leases) {
        self->cap_leases = self->cap_leases ? self->cap_leases * 2 : 64;
        self->leases = xrealloc(self->leases, sizeof *self->leases * self->cap_leases);
    }
    scheduler_lease *l = &self->leases[self->nleases++];
    *l = (scheduler_lease){.id = self->next_id++, .worker = worker, .tile = tile,
                           .granted_ms = now, .from_ms = now,
                           .deadline_ms = now + scheduler_lease_limit(self, worker),
                           .duplicate = dup};
    assert(!self->tiles[tile].done);
    if (self->tiles[tile].live == 0) {
        assert(self->nqueued > 0);
        self->nqueued--;
    }
    self->workers[worker].held++;
    self->tiles[tile].live++;
    self->tiles[tile].held++;
    assert(self->tiles[tile].live <= self->tiles[tile].held);
    self->counts.grants++;
    if (dup) self->counts.duplicate_grants++;
    *out = *l;
}

static bool worker_holds(const scheduler *self, int worker, int tile)
{
    for (size_t i = 0; i < self->nleases; i++) {
        const scheduler_lease *l = &self->leases[i];
        if (l->id && l->worker == worker && l->tile == tile) return true;
    }
    return false;
}

/* ---- choosing a tile ---- */

/* The oldest requeued tile for this worker, or -1. */
static int pick_requeued(scheduler *self, int worker)
{
    for (int i = self->rq_head; i < self->rq_len; i++) {
        int t = self->rq[i];
        if (t < 0) continue;
        if (!queued(self, t)) {
            rq_take(self, i);
            continue;
        }
        if (failed_by(self, t, worker) &&
            (self->tiles[t].given_up || other_for(self, t, worker, true)))
            continue;
        rq_take(self, i);
        return t;
    }
    return -1;
}

static bool fresh(const scheduler *self, int tile)
{
    return queued(self, tile) && !self->tiles[tile].in_rq;
}

/* Is another active worker's run about to continue into tile? */
static bool run_heading_into(const scheduler *self, int tile, int worker)
{
    for (int w = 0; w < self->nworkers; w++)
        if (tile > 0 && w != worker && self->workers[w].active &&
            self->workers[w].cursor == tile - 1)
            return true;
    return false;
}

/* The next tile of the worker's run, or else a new run in the longest run
 * of fresh tiles: in its middle when another worker's run is about to
 * continue into it, at its start otherwise; -1 when none. */
static int pick_fresh(scheduler *self, int worker)
{
    int c = self->workers[worker].cursor;
    if (c >= 0 && c + 1 < self->ntiles && fresh(self, c + 1)) return c + 1;
    int best_start = -1, best_len = 0;
    for (int i = 0; i < self->ntiles;) {
        if (!fresh(self, i)) { i++; continue; }
        int j = i;
        while (j < self->ntiles && fresh(self, j)) j++;
        if (j - i > best_len) { best_len = j - i; best_start = i; }
        i = j;
    }
    if (best_start < 0) return -1;
    return run_heading_into(self, best_start, worker) ? best_start + best_len / 2 : best_start;
}

/* End game: the outstanding tile leased longest ago that this worker does
 * not hold, that has room for one more lease and whose lease is old
 * enough to be a straggler; -1 when none. */
static int pick_duplicate(const scheduler *self, int worker, int64_t now)
{
    if (self->opt.max_duplicates == 0) return -1;
    int64_t wait = self->opt.duplicate_after_ms;
    if (self->done > 0 && 3 * (self->taken_ms_sum / self->done) > wait)
        wait = 3 * (self->taken_ms_sum / self->done);
    for (size_t i = 0; i < self->nleases; i++) {
        const scheduler_lease *l = &self->leases[i];
        if (!l->id || l->worker == worker) continue;
        if (now - l->granted_ms < wait) break;   /* the rest are younger still */
        if (now - l->from_ms < wait) continue;   /* its worker was getting files */
        const tile_state *t = &self->tiles[l->tile];
        if (t->done || t->live == 0 || t->held > (uint32_t)self->opt.max_duplicates) continue;
        if (!worker_holds(self, worker, l->tile) && !failed_by(self, l->tile, worker))
            return l->tile;
    }
    return -1;
}

bool scheduler_grant(scheduler *self, int worker, int64_t now_ms, scheduler_lease *out)
{
    if (!worker_ok(self, worker) || self->job_failed || self->done == self->ntiles) return false;
    const worker_slot *ws = &self->workers[worker];
    if (ws->overdue > 0) return false;   /* a hoarder, or a stalled worker */
    /* the end of the queue: a tile for a worker whose threads are all busy
     * would wait in its pipeline while other workers' threads may run dry */
    if (ws->threads > 0 && ws->held >= ws->threads && self->nqueued <= self->threads)
        return false;
    int tile = pick_requeued(self, worker);
    if (tile >= 0) {
        lease_add(self, worker, tile, now_ms, self->tiles[tile].held > 0, out);
        return true;
    }
    tile = pick_fresh(self, worker);
    if (tile >= 0) {
        self->workers[worker].cursor = tile;
        lease_add(self, worker, tile, now_ms, false, out);
        return true;
    }
    tile = pick_duplicate(self, worker, now_ms);
    if (tile < 0) return false;
    lease_add(self, worker, tile, now_ms, true, out);
    return true;
}

/* ---- resolving leases ---- */

const scheduler_lease *scheduler_lease_find(const scheduler *self, int worker, uint64_t lease_id)
{
    if (lease_id == 0) return NULL;
    const scheduler_lease *l = lease_lookup(self, lease_id);
    return l && l->worker == worker ? l : NULL;
}

scheduler_verdict scheduler_check_result(const scheduler *self, int worker, uint64_t lease_id)
{
    const scheduler_lease *l = scheduler_lease_find(self, worker, lease_id);
    if (!l) return SCHEDULER_STALE;
    return self->tiles[l->tile].done ? SCHEDULER_DUPLICATE : SCHEDULER_TAKEN;
}

scheduler_verdict scheduler_complete(scheduler *self, int worker, uint64_t lease_id,
                                     int64_t now_ms)
{
    assert(worker >= 0 && worker < self->nworkers);   /* a slot of scheduler_worker_add */
    scheduler_lease *l = (scheduler_lease *)scheduler_lease_find(self, worker, lease_id);
    if (!l) {
        self->counts.stale_results++;
        return SCHEDULER_STALE;
    }
    tile_state *t = &self->tiles[l->tile];
    if (t->done) {
        self->counts.duplicate_results++;
        lease_remove(self, l);
        return SCHEDULER_DUPLICATE;
    }
    if (t->live == 0) self->nqueued--;   /* its lease had expired: it was queued */
    t->done = 1;
    self->done++;
    assert(self->done <= self->ntiles);
    int64_t took = now_ms > l->from_ms ? now_ms - l->from_ms : 0;   /* files not counted */
    self->taken_ms_sum += took;
    self->taken++;
    self->workers[worker].taken++;
    self->workers[worker].taken_ms_sum += took;
    lease_remove(self, l);
    return SCHEDULER_TAKEN;
}

scheduler_failure scheduler_fail(scheduler *self, int worker, uint64_t lease_id, bool retryable)
{
    assert(worker >= 0 && worker < self->nworkers);   /* a slot of scheduler_worker_add */
    scheduler_lease *l = (scheduler_lease *)scheduler_lease_find(self, worker, lease_id);
    if (!l) return SCHEDULER_FAIL_IGNORED;
    int tile = l->tile;
    if (self->tiles[tile].done) {
        lease_remove(self, l);
        return SCHEDULER_FAIL_IGNORED;
    }
    self->counts.failures++;
    self->tiles[tile].attempts++;
    if (!failed_by(self, tile, worker)) {
        self->failed = xrealloc(self->failed, sizeof *self->failed * (self->nfailed + 1));
        self->failed[self->nfailed++] = (failed_pair){tile, worker};
    }
    lease_remove(self, l);
    /* only two workers' agreement fails the job (issues 11 and 27) */
    int failers = 0;
    for (size_t i = 0; i < self->nfailed; i++)
        if (self->failed[i].tile == tile) failers++;
    bool exhausted = self->tiles[tile].attempts >= self->opt.max_attempts;
    if (failers >= 2 && (!retryable || exhausted)) {
        self->job_failed = true;
        return SCHEDULER_JOB_FAILED;
    }
    if (!exhausted) return SCHEDULER_RETRY;
    /* one worker alone used up the attempts: it gives the tile up */
    if (!self->tiles[tile].given_up) {
        self->tiles[tile].given_up = 1;
        self->given_up = xrealloc(self->given_up, sizeof *self->given_up * (self->ngiven_up + 1));
        self->given_up[self->ngiven_up++] = (given_up_tile){tile, 0};
    }
    if (someone_else_for(self, tile, worker)) return SCHEDULER_RETRY;
    if (self->opt.join_window_ms <= 0) {   /* no other worker can come */
        self->job_failed = true;
        return SCHEDULER_JOB_FAILED;
    }
    return SCHEDULER_AWAIT_OTHER;
}

int scheduler_check_given_up(scheduler *self, int64_t now_ms)
{
    if (self->job_failed) return -1;
    for (size_t i = 0; i < self->ngiven_up; i++) {
        given_up_tile *g = &self->given_up[i];
        const tile_state *t = &self->tiles[g->tile];
        if (t->done || t->live > 0 || other_for(self, g->tile, -1, true)) {
            g->since_ms = 0;   /* someone works on it (an unexpired lease), or could */
            continue;
        }
        if (g->since_ms == 0) g->since_ms = now_ms;
        if (now_ms - g->since_ms >= self->opt.join_window_ms) {
            self->job_failed = true;
            return g->tile;
        }
    }
    return -1;
}

int scheduler_worker_remove(scheduler *self, int worker)
{
    if (!worker_ok(self, worker)) return 0;
    uint64_t before = self->counts.requeued;
    self->workers[worker].active = false;
    self->threads -= self->workers[worker].threads;
    for (size_t i = 0; i < self->nleases; i++) {
        scheduler_lease *l = &self->leases[i];
        if (l->id && l->worker == worker) {
            size_t n = self->nleases;
            lease_remove(self, l);
            if (self->nleases != n) i = (size_t)-1;   /* compacted: start over */
        }
    }
    return (int)(self->counts.requeued - before);
}

int scheduler_expire(scheduler *self, int64_t now_ms)
{
    return scheduler_expire_list(self, now_ms, NULL, 0);
}

int scheduler_expire_list(scheduler *self, int64_t now_ms, int *tiles, int max)
{
    uint64_t before = self->counts.requeued;
    for (size_t i = 0; i < self->nleases; i++) {
        scheduler_lease *l = &self->leases[i];
        if (!l->id || l->expired) continue;
        l->deadline_ms = l->from_ms + scheduler_lease_limit(self, l->worker);
        if (l->deadline_ms > now_ms) continue;
        l->expired = true;
        if (l->worker >= 0 && l->worker < self->nworkers) self->workers[l->worker].overdue++;
        self->counts.expired++;
        uint64_t requeued = self->counts.requeued;
        tile_lost_live(self, l->tile);
        int n = (int)(requeued - before);
        if (self->counts.requeued > requeued && n < max) tiles[n] = l->tile;
    }
    return (int)(self->counts.requeued - before);
}

void scheduler_worker_waiting(scheduler *self, int worker, bool waiting, int64_t now_ms)
{
    if (!worker_ok(self, worker)) return;
    self->workers[worker].waiting = waiting;
    for (size_t i = 0; i < self->nleases; i++) {
        scheduler_lease *l = &self->leases[i];
        if (!l->id || l->expired || l->worker != worker) continue;
        l->from_ms = now_ms;
        l->deadline_ms = now_ms + scheduler_lease_limit(self, worker);
    }
}

int64_t scheduler_lease_limit(const scheduler *self, int worker)
{
    if (worker >= 0 && worker < self->nworkers && self->workers[worker].waiting)
        return self->opt.lease_ms;
    int64_t sum = self->taken_ms_sum, n = self->taken;
    if (worker >= 0 && worker < self->nworkers && self->workers[worker].taken > 0) {
        sum = self->workers[worker].taken_ms_sum;
        n = self->workers[worker].taken;
    }
    if (self->opt.lease_factor <= 0 || n == 0) return self->opt.lease_ms;
    int64_t limit = self->opt.lease_factor * (sum / n);
    if (limit < self->opt.lease_min_ms) limit = self->opt.lease_min_ms;
    return limit < self->opt.lease_ms ? limit : self->opt.lease_ms;
}

bool scheduler_worker_overdue(const scheduler *self, int worker)
{
    return worker_ok(self, worker) && self->workers[worker].overdue > 0;
}

int64_t scheduler_next_deadline(const scheduler *self)
{
    int64_t next = INT64_MAX;
    for (size_t i = 0; i < self->nleases; i++) {
        const scheduler_lease *l = &self->leases[i];
        if (l->id && !l->expired && l->deadline_ms < next) next = l->deadline_ms;
    }
    return next;
}

bool scheduler_mark_done(scheduler *self, int tile)
{
    if (tile < 0 || tile >= self->ntiles) return false;
    tile_state *t = &self->tiles[tile];
    if (t->done || t->held) return false;
    self->nqueued--;
    t->done = 1;
    self->done++;
    return true;
}

/* ---- questions ---- */

bool scheduler_finished(const scheduler *self) { return self->done == self->ntiles; }
bool scheduler_failed(const scheduler *self) { return self->job_failed; }
int scheduler_tiles_done(const scheduler *self) { return self->done; }

bool scheduler_tile_done(const scheduler *self, int tile)
{
    return tile >= 0 && tile < self->ntiles && self->tiles[tile].done;
}

int scheduler_tile_attempts(const scheduler *self, int tile)
{
    return tile >= 0 && tile < self->ntiles ? self->tiles[tile].attempts : 0;
}

int scheduler_worker_leases(const scheduler *self, int worker)
{
    int n = 0;
    for (size_t i = 0; i < self->nleases; i++)
        if (self->leases[i].id && self->leases[i].worker == worker) n++;
    return n;
}

void scheduler_each_lease(const scheduler *self,
                          void (*fn)(void *arg, const scheduler_lease *lease), void *arg)
{
    for (size_t i = 0; i < self->nleases; i++)
        if (self->leases[i].id) fn(arg, &self->leases[i]);
}

void scheduler_counts_get(const scheduler *self, scheduler_counts *out)
{
    *out = self->counts;
    out->done = self->done;
    out->queued = out->leased = 0;
    for (int i = 0; i < self->ntiles; i++) {
        if (self->tiles[i].done) continue;
        if (self->tiles[i].live) out->leased++;
        else out->queued++;
    }
    assert(out->queued == self->nqueued);   /* the running count agrees */
}

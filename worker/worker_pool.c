/*
 * worker_pool.c: render threads, their task queue and done list (see
 * worker_pool.h). One mutex guards the queue, the done list, each
 * thread's current task and the board of tiles being rendered; a
 * condition variable wakes idle threads, the board's the owners of tiles
 * whose helpers left; a pipe wakes the connection loop. A thread that
 * finds the queue empty helps the tiles on the board (tile_share.h): it
 * traces blocks of the one with the most blocks left, so the last tiles of
 * a job end within a block when the worker has idle threads.
 */
#include "worker_pool.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "tile_render.h"
#include "tile_share.h"
#include "trace/thread.h"
#include "util/xalloc.h"

typedef struct render_thread {
    struct worker_pool *pool;
    pthread_t tid;
    bool started;
    long last_tile;            /* index of the last tile rendered, -1: none */
    worker_task *current;      /* being rendered (under the pool's lock) */
} render_thread;

/* A task's tile share and what its helpers did (under the pool's lock);
 * on the board by its first member, sh. */
typedef struct pool_share {
    tile_share sh;
    held_job *job;             /* the task's (the helpers' VM and world) */
    worker_tile_stats helped;  /* the helpers' work: rays ... CPU seconds */
} pool_share;
/* the board hands back &ps->sh, which render_main turns back into ps */
_Static_assert(offsetof(pool_share, sh) == 0, "pool_share starts with its tile_share");

struct worker_pool {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    tile_board board;          /* the tiles being rendered (tile_share.h) */
    worker_task *queue;        /* submitted, not started (a list) */
    worker_task *done, *done_tail;
    render_thread *threads;
    int nthreads;
    bool stopping;
    atomic_int abort_render;   /* set when stopping: running tiles end at once */
    int pipe_fd[2];
    int tile_delay_ms;
};

worker_task *worker_task_new(uint64_t lease_id, uint32_t tile_index, image_rect rect,
                             held_job *held)
{
    worker_task *t = xcalloc(1, sizeof *t);
    t->lease_id = lease_id;
    t->tile_index = tile_index;
    t->rect = rect;
    t->job = held_job_retain(held);
    return t;
}

void worker_task_destroy(worker_task **self_p)
{
    worker_task *t = *self_p;
    if (!t) return;
    held_job_release(&t->job);
    free(t->exr);
    free(t);
    *self_p = NULL;
}

/* ---- rendering one task (in a render thread, without the lock) ---- */

static double clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {}
}

static void stats_delta(worker_tile_stats *out, const trace_stats *a, const trace_stats *b)
{
    out->rays = (uint64_t)((b->primary_rays - a->primary_rays) + (b->shadow_rays - a->shadow_rays));
    out->boxes = (uint64_t)(b->boxes - a->boxes);
    out->shader_evals = (uint64_t)((b->evals_affine - a->evals_affine) +
                                   (b->evals_interval - a->evals_interval) +
                                   (b->evals_dual - a->evals_dual) +
                                   (b->evals_float - a->evals_float));
    out->cache_hits = (uint64_t)(b->cache_hits - a->cache_hits);
    out->cache_misses = (uint64_t)(b->cache_misses - a->cache_misses);
    out->cache_evictions = (uint64_t)(b->cache_evictions - a->cache_evictions);
    out->peak_cache_bytes = (uint64_t)b->cache_peak_bytes;
}

static void stats_add(worker_tile_stats *to, const worker_tile_stats *d)
{
    to->rays += d->rays;
    to->boxes += d->boxes;
    to->shader_evals += d->shader_evals;
    to->cache_hits += d->cache_hits;
    to->cache_misses += d->cache_misses;
    to->cache_evictions += d->cache_evictions;
    if (d->peak_cache_bytes > to->peak_cache_bytes) to->peak_cache_bytes = d->peak_cache_bytes;
    to->cpu_seconds += d->cpu_seconds;
    to->helped_blocks += d->helped_blocks;
}

/* A failed tile's message from th; th is cleared for the next tile. */
static void take_error(trace_thread *th, image_rect r, char *err, size_t errsz)
{
    snprintf(err, errsz, "tile at (%d,%d): %s", r.x0, r.y0, th->error);
    th->failed = false;
    th->error[0] = '\0';
}

static void render_task(worker_pool *p, int me, trace_thread *th, worker_task *t)
{
    if (p->tile_delay_ms > 0) sleep_ms(p->tile_delay_ms);
    const held_job *h = t->job;
    double wall0 = clock_s(CLOCK_MONOTONIC), cpu0 = clock_s(CLOCK_THREAD_CPUTIME_ID);
    trace_thread_sync_stats(th);
    trace_stats before = th->stats;
    pool_share ps = {.job = t->job};
    tile_share_init(&ps.sh, h->js->renderer, t->rect);
    tile_board_publish(&p->board, me, &ps.sh);
    bool ok = tile_share_trace(&ps.sh, th, NULL);
    tile_board_withdraw(&p->board, me, &ps.sh);
    worker_nonfinite nf = {0, 0, 0};
    if (!ok) {
        take_error(th, t->rect, t->error, sizeof t->error);
    } else if (ps.sh.failed) {
        snprintf(t->error, sizeof t->error, "%s", ps.sh.error);
    } else {
        image_tile *tile = worker_filter_tile(h->js, ps.sh.ts, t->rect, h->fmt.layers, &nf,
                                              t->error, sizeof t->error);
        if (tile)
            t->ok = image_tile_encode_exr(tile, &h->fmt, &t->exr, &t->exr_len, t->error,
                                          sizeof t->error);
        image_tile_destroy(&tile);
    }
    tile_share_clear(&ps.sh);
    trace_thread_sync_stats(th);
    stats_delta(&t->stats, &before, &th->stats);
    t->stats.nonfinite_samples = t->ok ? nf.count : 0;
    t->stats.cpu_seconds = clock_s(CLOCK_THREAD_CPUTIME_ID) - cpu0;
    t->stats.wall_seconds = clock_s(CLOCK_MONOTONIC) - wall0;
    if (t->stats.cpu_seconds < 0) t->stats.cpu_seconds = 0;
    if (t->stats.wall_seconds < 0) t->stats.wall_seconds = 0;
    stats_add(&t->stats, &ps.helped);
}

/* The end of a thread's work on a job: its work-limit warnings (one line
 * per object, trace_object_work_report), then its VM and box cache go. */
static void retire_thread(trace_thread **th, const held_job *held)
{
    if (*th && held)
        trace_object_work_report(&held->js->world, (*th)->work, "aafarm-worker", stderr);
    trace_thread_destroy(th);
}

/* This thread's VM and box cache for the job (new ones when it worked on
 * another job). */
static void use_job(worker_pool *p, trace_thread **th, held_job **cur, held_job *want)
{
    if (*cur == want) return;
    retire_thread(th, *cur);
    held_job_release(cur);
    *cur = held_job_retain(want);
    *th = trace_thread_new(&(*cur)->js->world);
    trace_thread_set_cancel(*th, &p->abort_render);
    trace_thread_set_print(*th, worker_print_shader_line, NULL);
}

/* Helps share ps, picked from the board (called and returns under the
 * lock). */
static void help(worker_pool *p, pool_share *ps, trace_thread **th, held_job **cur)
{
    pthread_mutex_unlock(&p->lock);
    use_job(p, th, cur, ps->job);
    double cpu0 = clock_s(CLOCK_THREAD_CPUTIME_ID);
    trace_thread_sync_stats(*th);
    trace_stats before = (*th)->stats;
    long blocks = 0;
    bool ok = tile_share_trace(&ps->sh, *th, &blocks);
    trace_thread_sync_stats(*th);
    worker_tile_stats d;
    stats_delta(&d, &before, &(*th)->stats);
    d.cpu_seconds = clock_s(CLOCK_THREAD_CPUTIME_ID) - cpu0;
    if (d.cpu_seconds < 0) d.cpu_seconds = 0;
    d.helped_blocks = (uint64_t)blocks;
    pthread_mutex_lock(&p->lock);
    stats_add(&ps->helped, &d);
    tile_board_leave(&p->board, &ps->sh, ok, *th);
    (*th)->failed = false;               /* its next tile starts afresh */
    (*th)->error[0] = '\0';
}

/* ---- the lists (under the lock) ---- */

static void push_done(worker_pool *p, worker_task *t)
{
    t->next = NULL;
    if (p->done_tail) p->done_tail->next = t;
    else p->done = t;
    p->done_tail = t;
}

static void wake_loop(worker_pool *p)
{
    char c = 1;
    while (write(p->pipe_fd[1], &c, 1) < 0 && errno == EINTR) {}
    /* EAGAIN: the pipe is full of wake-ups already; nothing is lost */
}

static long tile_distance(long a, long b) { return a > b ? a - b : b - a; }

/* Unlinks the queued task nearest to tile `last` (to tile 0 when -1). */
static worker_task *take_nearest(worker_pool *p, long last)
{
    worker_task **best = &p->queue;
    long ref = last >= 0 ? last : 0;
    for (worker_task **at = &p->queue; *at; at = &(*at)->next)
        if (tile_distance((long)(*at)->tile_index, ref) <
            tile_distance((long)(*best)->tile_index, ref))
            best = at;
    worker_task *t = *best;
    *best = t->next;
    t->next = NULL;
    return t;
}

static void *render_main(void *arg)
{
    render_thread *rt = arg;
    worker_pool *p = rt->pool;
    trace_thread *th = NULL;
    held_job *cur = NULL;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->stopping && !p->queue) {
            tile_share *sh = tile_board_pick(&p->board);
            if (sh) help(p, (pool_share *)sh, &th, &cur);   /* its first member */
            else pthread_cond_wait(&p->wake, &p->lock);
        }
        if (p->stopping) break;
        worker_task *t = take_nearest(p, rt->last_tile);
        rt->current = t;
        pthread_mutex_unlock(&p->lock);
        use_job(p, &th, &cur, t->job);   /* another job: a new VM and box cache */
        render_task(p, (int)(rt - p->threads), th, t);
        pthread_mutex_lock(&p->lock);
        rt->current = NULL;
        rt->last_tile = (long)t->tile_index;
        push_done(p, t);
        wake_loop(p);
    }
    pthread_mutex_unlock(&p->lock);
    retire_thread(&th, cur);
    held_job_release(&cur);
    return NULL;
}

/* ---- the pool ---- */

worker_pool *worker_pool_new(int threads, int tile_delay_ms)
{
    worker_pool *p = xcalloc(1, sizeof *p);
    atomic_init(&p->abort_render, 0);
    p->nthreads = threads < 1 ? 1 : threads;
    p->tile_delay_ms = tile_delay_ms;
    p->threads = xcalloc((size_t)p->nthreads, sizeof *p->threads);
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    tile_board_init(&p->board, &p->lock, &p->wake, p->nthreads);
    p->pipe_fd[0] = p->pipe_fd[1] = -1;
    if (pipe(p->pipe_fd) != 0) {
        worker_pool_destroy(&p);
        return NULL;
    }
    for (int i = 0; i < 2; i++) {
        fcntl(p->pipe_fd[i], F_SETFL, fcntl(p->pipe_fd[i], F_GETFL) | O_NONBLOCK);
        fcntl(p->pipe_fd[i], F_SETFD, FD_CLOEXEC);
    }
    for (int i = 0; i < p->nthreads; i++) {
        p->threads[i] = (render_thread){.pool = p, .last_tile = -1};
        if (pthread_create(&p->threads[i].tid, NULL, render_main, &p->threads[i]) != 0) {
            worker_pool_destroy(&p);
            return NULL;
        }
        p->threads[i].started = true;
    }
    return p;
}

static void free_list(worker_task *t)
{
    while (t) {
        worker_task *next = t->next;
        worker_task_destroy(&t);
        t = next;
    }
}

void worker_pool_destroy(worker_pool **self_p)
{
    worker_pool *p = *self_p;
    if (!p) return;
    pthread_mutex_lock(&p->lock);
    p->stopping = true;
    atomic_store(&p->abort_render, 1);
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    for (int i = 0; i < p->nthreads; i++)
        if (p->threads[i].started) pthread_join(p->threads[i].tid, NULL);
    free_list(p->queue);
    free_list(p->done);
    for (int i = 0; i < 2; i++)
        if (p->pipe_fd[i] >= 0) close(p->pipe_fd[i]);
    pthread_cond_destroy(&p->wake);
    tile_board_clear(&p->board);
    pthread_mutex_destroy(&p->lock);
    free(p->threads);
    free(p);
    *self_p = NULL;
}

int worker_pool_wake_fd(const worker_pool *self) { return self->pipe_fd[0]; }

void worker_pool_submit(worker_pool *self, worker_task *task)
{
    pthread_mutex_lock(&self->lock);
    task->next = self->queue;
    self->queue = task;
    pthread_cond_signal(&self->wake);
    pthread_mutex_unlock(&self->lock);
}

worker_task *worker_pool_take_done(worker_pool *self)
{
    char buf[64];
    while (read(self->pipe_fd[0], buf, sizeof buf) > 0) {}
    pthread_mutex_lock(&self->lock);
    worker_task *t = self->done;
    if (t) {
        self->done = t->next;
        if (!self->done) self->done_tail = NULL;
        t->next = NULL;
    }
    pthread_mutex_unlock(&self->lock);
    return t;
}

static bool matches(const worker_task *t, const char *job_hash)
{
    return !job_hash || strcmp(t->job->hash, job_hash) == 0;
}

void worker_pool_cancel(worker_pool *self, const char *job_hash)
{
    pthread_mutex_lock(&self->lock);
    for (worker_task **at = &self->queue; *at;) {
        worker_task *t = *at;
        if (!matches(t, job_hash)) {
            at = &t->next;
            continue;
        }
        *at = t->next;
        t->cancelled = true;
        push_done(self, t);
    }
    for (int i = 0; i < self->nthreads; i++) {
        worker_task *t = self->threads[i].current;
        if (t && matches(t, job_hash)) t->cancelled = true;
    }
    bool any = self->done != NULL;
    pthread_mutex_unlock(&self->lock);
    if (any) {
        char c = 1;
        while (write(self->pipe_fd[1], &c, 1) < 0 && errno == EINTR) {}
    }
}

int worker_pool_busy(worker_pool *self)
{
    pthread_mutex_lock(&self->lock);
    int n = 0;
    for (worker_task *t = self->queue; t; t = t->next) n++;
    for (int i = 0; i < self->nthreads; i++) n += self->threads[i].current != NULL;
    pthread_mutex_unlock(&self->lock);
    return n;
}

size_t worker_pool_leases(worker_pool *self, uint64_t *out, size_t max)
{
    size_t n = 0;
    pthread_mutex_lock(&self->lock);
    for (worker_task *t = self->queue; t && n < max; t = t->next)
        if (!t->cancelled) out[n++] = t->lease_id;
    for (int i = 0; i < self->nthreads && n < max; i++) {
        worker_task *t = self->threads[i].current;
        if (t && !t->cancelled) out[n++] = t->lease_id;
    }
    pthread_mutex_unlock(&self->lock);
    return n;
}

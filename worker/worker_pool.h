/*
 * worker_pool.h: the render threads of a farm worker. The connection loop
 * (worker_loop.c, the only thread that touches the ZeroMQ socket) submits
 * granted tiles as tasks; N threads render them, encode each as a one-tile
 * EXR in memory and put it on the done list, then write one byte to a
 * pipe whose read end is in the loop's zmq_poll set. Heartbeats go on
 * while the threads render.
 *
 * Each thread keeps its trace_thread (its VM and its box cache, Heidrich &
 * Seidel §6) across tiles of the same job and makes a new one when a
 * tile of another job arrives. A free thread takes the queued tile whose
 * index is nearest to the last one it rendered, so runs of neighbouring
 * tiles granted by the master stay on one box cache where possible.
 *
 * Cancelling (JobDone, a lost master) removes queued tasks at once and
 * marks running ones; cancelled tasks come back on the done list with
 * cancelled set, to be dropped by the loop.
 */
#ifndef WORKER_POOL_H
#define WORKER_POOL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image/format.h"
#include "worker_jobs.h"

typedef struct worker_tile_stats {
    uint64_t rays, boxes, shader_evals;
    uint64_t cache_hits, cache_misses, cache_evictions, peak_cache_bytes;
    double cpu_seconds, wall_seconds;
    uint64_t nonfinite_samples;    /* NaN/Inf samples written as 0 */
    uint64_t helped_blocks;        /* blocks traced by idle threads (tile_share.h);
                                      the counts and CPU above include them */
} worker_tile_stats;

typedef struct worker_task {
    /* set by the loop */
    uint64_t lease_id;
    uint32_t tile_index;
    image_rect rect;
    held_job *job;             /* a reference, released by worker_task_destroy */
    /* set by the pool */
    bool cancelled;
    bool ok;
    void *exr;                 /* the tile file (malloc'd) when ok */
    size_t exr_len;
    char error[2 * ERR_LEN];   /* why not ok: a tile's place and a render thread's ERR_LEN message */
    worker_tile_stats stats;
    struct worker_task *next;
} worker_task;

/* A task for a lease (takes a new reference to held). */
worker_task *worker_task_new(uint64_t lease_id, uint32_t tile_index, image_rect rect,
                             held_job *held);
void worker_task_destroy(worker_task **self_p);

typedef struct worker_pool worker_pool;

/* Starts `threads` render threads. tile_delay_ms: sleep before each tile
 * (0 normally; a testing aid, see docs/farm.md). NULL when the pipe or a
 * thread cannot be created. */
worker_pool *worker_pool_new(int threads, int tile_delay_ms);

/* Stops the threads (a tile being rendered ends within one ray: its
 * trace_thread watches the pool's abort flag) and frees
 * everything still queued or done. */
void worker_pool_destroy(worker_pool **self_p);

/* The pipe's read end: readable when tasks are done. */
int worker_pool_wake_fd(const worker_pool *self);

void worker_pool_submit(worker_pool *self, worker_task *task);

/* One finished (or cancelled) task, or NULL. Empties the pipe. */
worker_task *worker_pool_take_done(worker_pool *self);

/* Cancels the tasks of the job with this hash (NULL: every task). */
void worker_pool_cancel(worker_pool *self, const char *job_hash);

/* Tasks queued or rendering (cancelled running ones included: they hold
 * a thread). */
int worker_pool_busy(worker_pool *self);

/* Lease ids of the tasks not cancelled, queued or rendering (at most
 * max); returns how many. */
size_t worker_pool_leases(worker_pool *self, uint64_t *out, size_t max);

#endif

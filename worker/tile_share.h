/*
 * tile_share.h: one tile traced by the thread that took it (its owner) and
 * by threads that have nothing else to do (helpers): the end of a frame,
 * where one expensive tile would otherwise keep one core busy while the
 * others wait. The tile's samples come in blocks of 8 x 8 pixels
 * (trace/render.h, trace_tile_samples); owner and helpers take blocks from
 * one atomic counter, each traces its blocks with its own trace_thread,
 * and the owner filters the tile once every block is traced. Who traces a
 * block changes no bit of the tile.
 *
 * The shares being traced stand on a board (tile_board: one slot per
 * thread) under the caller's own mutex, which also guards the caller's
 * state (the standalone renderer's writer, the farm worker's pool's
 * queue). The protocol:
 *   owner:  tile_share_init, tile_board_publish, tile_share_trace,
 *           tile_board_withdraw (its helpers have finished when it
 *           returns), then read `failed`, filter (trace_tile_samples_filter),
 *           tile_share_clear;
 *   helper: under the lock tile_board_pick; without it tile_share_trace;
 *           under it again tile_board_leave.
 */
#ifndef WORKER_TILE_SHARE_H
#define WORKER_TILE_SHARE_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>

#include "image/format.h"
#include "trace/render.h"
#include "util/err.h"

typedef struct tile_share {
    const trace_renderer *renderer;
    trace_tile_samples *ts;
    image_rect rect;
    int nblocks;
    atomic_int next;               /* the next block to take */
    int helpers;                   /* helpers on it (the board's lock) */
    bool failed;                   /* a helper failed (the board's lock) */
    char error[ERR_LEN];
} tile_share;

void tile_share_init(tile_share *self, const trace_renderer *renderer, image_rect rect);
void tile_share_clear(tile_share *self);

/* Blocks not taken yet (0 when none). */
int tile_share_left(tile_share *self);

/* Takes and traces blocks with th until none is left; *blocks (may be
 * NULL) gets how many this call traced. False when a shader failed or th
 * was cancelled (th->error says why; then no block is taken any more). */
bool tile_share_trace(tile_share *self, trace_thread *th, long *blocks);

/* The shares being traced, one slot per thread, under the caller's lock. */
typedef struct tile_board {
    pthread_mutex_t *lock;         /* the caller's */
    pthread_cond_t *wake;          /* broadcast when a share is published
                                      (idle threads sleep on it), or NULL */
    pthread_cond_t helped;         /* a helper left a share */
    tile_share **slot;             /* per thread: the share it owns, or NULL */
    int n;
} tile_board;

/* A board of n (>= 1) empty slots; every slot is set before any thread
 * that reads them starts. */
void tile_board_init(tile_board *self, pthread_mutex_t *lock, pthread_cond_t *wake, int n);
void tile_board_clear(tile_board *self);

/* Owner `me` puts sh on the board (takes the lock). */
void tile_board_publish(tile_board *self, int me, tile_share *sh);
/* Owner `me` takes sh off the board, so no helper comes, and waits for
 * those on it to finish their blocks (takes the lock). */
void tile_board_withdraw(tile_board *self, int me, tile_share *sh);

/* Under the lock: the share with the most blocks left (none failed), with
 * this helper counted on it; NULL when no share has any. */
tile_share *tile_board_pick(tile_board *self);
/* Under the lock: the helper is done with sh; ok false: its failure
 * (th->error) goes to the owner (the first one is kept). */
void tile_board_leave(tile_board *self, tile_share *sh, bool ok, const trace_thread *th);

#endif

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
 * The caller keeps the shares where its threads find them, under its own
 * lock: `helpers` and `failed` are read and written under that lock (the
 * standalone renderer's and the farm worker's pool's). The protocol:
 *   owner:  tile_share_init, publish it, tile_share_trace; withdraw it,
 *           wait (under the lock) until helpers == 0, then read failed,
 *           filter (trace_tile_samples_filter), tile_share_clear;
 *   helper: (under the lock) pick a published share with
 *           tile_share_left() > 0 and !failed, helpers++; then without
 *           the lock tile_share_trace; then (under the lock) record a
 *           failure (tile_share_fail), helpers--, wake the owner.
 */
#ifndef WORKER_TILE_SHARE_H
#define WORKER_TILE_SHARE_H

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
    int helpers;                   /* helpers on it (the caller's lock) */
    bool failed;                   /* a helper failed (the caller's lock) */
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

/* A helper's failure (th->error) recorded for the owner (under the
 * caller's lock); the first one is kept. */
void tile_share_fail(tile_share *self, const trace_thread *th);

#endif

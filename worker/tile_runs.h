/*
 * tile_runs.h: how the standalone renderer's threads share the tiles of one
 * image: each thread owns a contiguous run of tiles (in scanline order of
 * tiles) and works through it from its start, so its box cache stays warm
 * over neighbouring tiles (Heidrich & Seidel §6: the cache pays off across
 * neighbouring rays) and the threads do not interleave; a thread whose run
 * is done takes the second half of the largest run left (work stealing), so
 * all threads finish together. The farm gives its workers tile runs in the
 * same spirit (master/scheduler.c, worker_pool.c's nearest-tile order).
 *
 * Which thread renders a tile never changes its pixels: a tile's pixels
 * depend only on the scene and the tile (docs/farm.md).
 */
#ifndef WORKER_TILE_RUNS_H
#define WORKER_TILE_RUNS_H

#include <pthread.h>

typedef struct tile_run { int next, end; } tile_run;

typedef struct tile_runs {
    pthread_mutex_t lock;
    int nthreads;
    tile_run *runs;                /* one per thread: [next, end) left to do */
} tile_runs;

/* Splits tiles [0, ntiles) into nthreads runs as equal as can be. */
void tile_runs_init(tile_runs *self, int ntiles, int nthreads);
/* Frees the runs and zeroes the struct (the struct itself is the caller's). */
void tile_runs_clear(tile_runs *self);
/* The next tile for thread t (0 <= t < nthreads), or -1 when all are taken. */
int tile_runs_take(tile_runs *self, int t);

#endif

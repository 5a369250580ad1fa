/*
 * tile_share.c: one tile's sample blocks shared by its owner and helper
 * threads (see tile_share.h).
 */
#include "tile_share.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "util/xalloc.h"

void tile_share_init(tile_share *self, const trace_renderer *renderer, image_rect rect)
{
    memset(self, 0, sizeof *self);
    self->renderer = renderer;
    self->rect = rect;
    self->ts = trace_tile_samples_new(renderer, rect.x0, rect.y0, rect.w, rect.h);
    self->nblocks = trace_tile_samples_blocks(self->ts);
    atomic_init(&self->next, 0);
}

void tile_share_clear(tile_share *self)
{
    assert(self->helpers == 0);   /* the owner waited for its helpers */
    trace_tile_samples_destroy(&self->ts);
}

int tile_share_left(tile_share *self)
{
    int left = self->nblocks - atomic_load(&self->next);
    return left > 0 ? left : 0;
}

bool tile_share_trace(tile_share *self, trace_thread *th, long *blocks)
{
    long mine = 0;
    bool ok = true;
    for (int b; ok && (b = atomic_fetch_add(&self->next, 1)) < self->nblocks; mine++)
        ok = trace_tile_samples_trace(self->renderer, th, self->ts, b);
    if (!ok) atomic_store(&self->next, self->nblocks);   /* nobody takes more */
    if (blocks) *blocks = mine;
    return ok;
}

void tile_board_init(tile_board *self, pthread_mutex_t *lock, pthread_cond_t *wake, int n)
{
    assert(n >= 1);
    self->lock = lock;
    self->wake = wake;
    pthread_cond_init(&self->helped, NULL);
    self->slot = xcalloc((size_t)n, sizeof *self->slot);
    self->n = n;
}

void tile_board_clear(tile_board *self)
{
    pthread_cond_destroy(&self->helped);
    free(self->slot);
    self->slot = NULL;
    self->n = 0;
}

void tile_board_publish(tile_board *self, int me, tile_share *sh)
{
    assert(me >= 0 && me < self->n);
    pthread_mutex_lock(self->lock);
    self->slot[me] = sh;
    if (self->wake) pthread_cond_broadcast(self->wake);   /* idle threads may help */
    pthread_mutex_unlock(self->lock);
}

void tile_board_withdraw(tile_board *self, int me, tile_share *sh)
{
    pthread_mutex_lock(self->lock);
    assert(self->slot[me] == sh);
    self->slot[me] = NULL;
    while (sh->helpers > 0) pthread_cond_wait(&self->helped, self->lock);
    pthread_mutex_unlock(self->lock);
}

tile_share *tile_board_pick(tile_board *self)
{
    tile_share *best = NULL;
    int most = 0;
    for (int t = 0; t < self->n; t++) {
        tile_share *sh = self->slot[t];
        int left = sh && !sh->failed ? tile_share_left(sh) : 0;
        if (left > most) {
            most = left;
            best = sh;
        }
    }
    if (best) best->helpers++;
    return best;
}

void tile_board_leave(tile_board *self, tile_share *sh, bool ok, const trace_thread *th)
{
    assert(sh->helpers > 0);
    if (!ok && !sh->failed) {
        sh->failed = true;
        err_set(sh->error, sizeof sh->error, "tile at (%d,%d): %s", sh->rect.x0,
                sh->rect.y0, th->error);
    }
    sh->helpers--;
    pthread_cond_broadcast(&self->helped);
}

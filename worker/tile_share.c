/*
 * tile_share.c: one tile's sample blocks shared by its owner and helper
 * threads (see tile_share.h).
 */
#include "tile_share.h"

#include <assert.h>
#include <string.h>

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

void tile_share_fail(tile_share *self, const trace_thread *th)
{
    if (self->failed) return;
    self->failed = true;
    err_set(self->error, sizeof self->error, "tile at (%d,%d): %s", self->rect.x0,
            self->rect.y0, th->error);
}

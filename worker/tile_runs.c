/*
 * tile_runs.c: contiguous tile runs per thread with work stealing (see
 * tile_runs.h). A mutex, not atomics: a thread takes one tile per lock,
 * and a tile takes milliseconds to render.
 */
#include "tile_runs.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "util/xalloc.h"

void tile_runs_init(tile_runs *self, int ntiles, int nthreads)
{
    assert(ntiles >= 0 && nthreads >= 1);
    pthread_mutex_init(&self->lock, NULL);
    self->nthreads = nthreads;
    self->runs = xcalloc((size_t)nthreads, sizeof *self->runs);
    for (int t = 0; t < nthreads; t++) {
        self->runs[t].next = (int)((long)ntiles * t / nthreads);
        self->runs[t].end = (int)((long)ntiles * (t + 1) / nthreads);
    }
}

void tile_runs_clear(tile_runs *self)
{
    pthread_mutex_destroy(&self->lock);
    free(self->runs);
    memset(self, 0, sizeof *self);
}

int tile_runs_take(tile_runs *self, int t)
{
    assert(t >= 0 && t < self->nthreads);
    pthread_mutex_lock(&self->lock);
    tile_run *mine = &self->runs[t];
    if (mine->next >= mine->end) {
        /* steal the back half of the largest run left */
        int victim = -1, most = 0;
        for (int v = 0; v < self->nthreads; v++) {
            int left = self->runs[v].end - self->runs[v].next;
            if (left > most) {
                most = left;
                victim = v;
            }
        }
        if (victim >= 0) {
            tile_run *r = &self->runs[victim];
            int mid = r->next + (most + 1) / 2;   /* a run of 1 goes whole */
            if (most == 1) mid = r->next;
            assert(r->next <= mid && mid < r->end);   /* the thief takes at least one */
            mine->next = mid;
            mine->end = r->end;
            r->end = mid;
        }
    }
    /* a run never runs backwards: next passes end only by being empty */
    assert(mine->next <= mine->end);
    int tile = mine->next < mine->end ? mine->next++ : -1;
    pthread_mutex_unlock(&self->lock);
    return tile;
}

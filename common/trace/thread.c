/*
 * thread.c: per-thread rendering state (see thread.h).
 */
#include "trace/thread.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void trace_options_default(trace_options *opt)
{
    opt->arith = TRACE_ARITH_AFFINE;
    opt->cache_bytes = 0;
    opt->aa_capacity = 16;   /* a sphere alone takes 11 symbols (docs/renderer.md) */
    opt->max_instructions = 1000000;
    opt->leaf_fraction = 1.0;
}

trace_thread *trace_thread_new(const trace_world *world)
{
    trace_thread *self = calloc(1, sizeof *self);
    if (!self) abort();
    self->world = world;
    sl_limits limits = {.max_instructions = world->options.max_instructions,
                        .max_loop_iterations = 64};
    self->vm = sl_vm_new(&limits);
    self->shade_vm = sl_vm_new(&limits);
    aa_context_init(&self->ctx, world->options.aa_capacity);
    self->cache = trace_boxcache_new(world->options.cache_bytes, world->nobjects);
    return self;
}

void trace_thread_destroy(trace_thread **self_p)
{
    trace_thread *self = *self_p;
    if (!self) return;
    sl_vm_destroy(&self->vm);
    sl_vm_destroy(&self->shade_vm);
    trace_boxcache_destroy(&self->cache);
    free(self);
    *self_p = NULL;
}

void trace_thread_fail(trace_thread *self, const char *message)
{
    if (self->failed) return;
    self->failed = true;
    snprintf(self->error, sizeof self->error, "%s", message);
}

void trace_thread_sync_stats(trace_thread *self)
{
    const trace_boxcache_stats *c = trace_boxcache_stats_get(self->cache);
    self->stats.cache_hits = c->hits;
    self->stats.cache_misses = c->misses;
    self->stats.cache_evictions = c->evictions;
    self->stats.cache_peak_bytes = c->peak_bytes;
}

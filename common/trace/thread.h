/*
 * thread.h: the mutable state of one rendering thread: its shader VM, its
 * affine context, its box cache (one per thread, Heidrich & Seidel §6) and
 * its statistics. Nothing in here is shared, so threads never lock while
 * tracing. A render error (a shader over its budget) is recorded here and
 * makes the tile fail; tracing goes on conservatively until the tile ends.
 */
#ifndef TRACE_THREAD_H
#define TRACE_THREAD_H

#include <stdbool.h>

#include "aa/affine.h"
#include "sl/shader.h"
#include "trace/boxcache.h"
#include "trace/world.h"

#include "trace/stats.h"

typedef struct trace_thread {
    const trace_world *world;
    sl_vm *vm;                     /* displacement shaders (boxes, points) */
    sl_vm *shade_vm;               /* surface shaders: their light callbacks
                                      trace shadow rays, which use vm */
    aa_context ctx;
    trace_boxcache *cache;
    trace_stats stats;
    bool failed;
    char error[512];
} trace_thread;

trace_thread *trace_thread_new(const trace_world *world);
void trace_thread_destroy(trace_thread **self_p);

/* Records the first error of this thread (later ones are dropped). */
void trace_thread_fail(trace_thread *self, const char *message);

/* Folds the cache's counters into stats (call before reading stats). */
void trace_thread_sync_stats(trace_thread *self);

#endif

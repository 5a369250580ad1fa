/*
 * thread.h: the mutable state of one rendering thread: its shader VM, its
 * affine context, its box cache (one per thread, Heidrich & Seidel §6) and
 * its statistics. Nothing in here is shared, so threads never lock while
 * tracing. A render error (a shader over its budget) is recorded here and
 * makes the tile fail; tracing goes on conservatively until the tile ends.
 */
#ifndef TRACE_THREAD_H
#define TRACE_THREAD_H

#include <stdatomic.h>
#include <stdbool.h>

#include "aa/affine.h"
#include "sl/shader.h"
#include "trace/boxcache.h"
#include "trace/world.h"

#include "trace/stats.h"
#include "util/err.h"
#include <stdio.h>

/* Per object: the rays whose walk hit the work limit (intersect.c) and the
 * (u,v) region where those walks stopped, for one warning per object. */
typedef struct trace_object_work {
    bool probed;                   /* trace_surface_converges was asked ... */
    bool diverges;                 /* ... and said no */
    long limited_rays;
    double u0, u1, v0, v1;         /* union of the stopped nodes' ranges */
} trace_object_work;

/* trace() from surface shaders (RI Spec 3.2 §15.6): a hit seen through
 * max_ray_depth traced rays (trace_options; default TRACE_MAX_RAY_DEPTH,
 * at most TRACE_RAY_DEPTH_LIMIT) is shaded; a ray deeper sees black. */
enum { TRACE_MAX_RAY_DEPTH = 4, TRACE_RAY_DEPTH_LIMIT = 16 };
/* Rays that trace() and shadow() may trace for one primary hit, all depths
 * together: a shader calling them in loops at every depth cannot multiply
 * its work without bound; beyond, the tile fails with a message. */
enum { TRACE_MAX_SHADER_RAYS = 1024 };

typedef struct trace_thread {
    const trace_world *world;
    sl_vm *vm;                     /* displacement shaders (boxes, points) */
    sl_vm *shade_vm;               /* surface shaders: their light callbacks
                                      trace shadow rays, which use vm */
    sl_vm *light_vm;               /* light shaders, run from shade_vm's
                                      light callback (sl_light_eval) */
    long shader_rays;              /* trace()/shadow() rays of this primary hit */
    sl_vm *ray_vm[TRACE_RAY_DEPTH_LIMIT];  /* surface shaders of the hits of
                                      trace() rays, one per depth (1..), made
                                      on first use (trace_thread_shade_vm) */
    sl_print_fn print;             /* shaders' printf lines (NULL: dropped); */
    void *print_ctx;               /* trace_thread_set_print */
    aa_context ctx;
    trace_boxcache *cache;
    struct trace_slope_cache *slopes;  /* prove.c's, made on first use */
    struct trace_wall_cache *walls;    /* intersect.c's, made on first use */
    struct trace_move_cache *moves;    /* intersect.c's, made on first use */
    struct trace_case_cache *cases;    /* intersect.c's, made on first use */
    struct trace_plane_cache *planes;  /* displace.c's, made on first use */
    struct trace_tape_memo *tapes;     /* tape_memo.c's, made on first use */
    struct trace_views *views;     /* mesh.c's views of pieces, made on first use */
    struct trace_normal_memo *normals; /* normal_memo.c's, made on first use */
    trace_stats stats;
    trace_object_work *work;       /* world->nobjects entries (by trace_object.top) */
    const atomic_int *cancel;      /* non-zero: stop tracing at once (a signal,
                                      the pool stopping); NULL: never */
    bool failed;
    char error[ERR_LEN];
} trace_thread;

trace_thread *trace_thread_new(const trace_world *world);
/* Hands the shaders' printf() lines of every VM of this thread (those
 * made later too) to fn(ctx, text); the library prints nothing itself. */
void trace_thread_set_print(trace_thread *self, sl_print_fn fn, void *ctx);
/* Sets the flag this thread and its shader VMs watch (default: the
 * world's options.cancel): non-zero stops the walk and any shader run. */
void trace_thread_set_cancel(trace_thread *self, const atomic_int *flag);
void trace_thread_destroy(trace_thread **self_p);

/* The VM that runs surface shaders at trace() depth `depth` (0: primary
 * hits, shade_vm; 1..TRACE_RAY_DEPTH_LIMIT: made on first use). */
sl_vm *trace_thread_shade_vm(trace_thread *self, int depth);

/* Records the first error of this thread (later ones are dropped). */
void trace_thread_fail(trace_thread *self, const char *message);

/* Has the render been cancelled? Then the thread is failed with
 * "interrupted" and every walk unwinds without finding more hits. */
static inline bool trace_thread_cancelled(trace_thread *self)
{
    if (!self->cancel || !atomic_load_explicit(self->cancel, memory_order_relaxed))
        return false;
    trace_thread_fail(self, "interrupted");
    return true;
}

/* Adds src's per-object work records into dst (nobjects entries each). */
void trace_object_work_add(trace_object_work *dst, const trace_object_work *src,
                           int nobjects);

/* One warning line per object whose rays hit the work limit (nothing when
 * none did): what, where in (u,v), and what it means for the image. */
void trace_object_work_report(const trace_world *world, const trace_object_work *work,
                              const char *prog, FILE *out);

/* Folds the cache's counters into stats (call before reading stats). */
void trace_thread_sync_stats(trace_thread *self);

/* Runs fn on each of the n shares (shares[i] at shares + i * size): share
 * 0 on the calling thread, the others on threads of their own, joined
 * before it returns; a share whose thread cannot be started runs on the
 * calling thread after share 0. For the world's build over
 * trace_options.build_threads (mesh.c, world.c); util_run_shares. */
void trace_run_shares(void *shares, size_t size, int n, void *(*fn)(void *));

#endif

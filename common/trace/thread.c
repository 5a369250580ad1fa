/*
 * thread.c: per-thread rendering state (see thread.h).
 */
#include "trace/thread.h"
#include "trace/mesh.h"
#include "trace/normal_memo.h"
#include "trace/tape_memo.h"
#include "util/err.h"
#include "util/shares.h"
#include "util/xalloc.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void trace_options_default(trace_options *opt)
{
    opt->arith = TRACE_ARITH_AFFINE;
    opt->cache_bytes = 0;
    opt->roots_bytes = 0;
    opt->aa_capacity = 16;   /* a sphere alone takes 11 symbols (docs/renderer.md) */
    opt->max_instructions = 1000000;
    opt->leaf_fraction = 1.0;
    opt->max_nodes_per_ray = TRACE_DEFAULT_MAX_NODES_PER_RAY;
    opt->max_ray_depth = TRACE_MAX_RAY_DEPTH;
    opt->prove_hits = true;
    opt->light_memo = true;
    opt->lazy_roots = true;
    opt->lazy_children = true;
    opt->tape_pruning = true;
    opt->leaf_start = true;
    opt->cancel = NULL;
}

/* A VM for this world's shaders, with what every shader may ask of the
 * scene: depth() (RIB Clipping) and option() (RI Spec 3.2 §15.7), the
 * same for every run. */
static sl_vm *new_vm(const trace_world *world)
{
    sl_limits limits = {.max_instructions = world->options.max_instructions,
                        .max_loop_iterations = 64};
    sl_vm *vm = sl_vm_new(&limits);
    const trace_camera *cam = &world->camera;
    double format[3] = {cam->xres, cam->yres, 1.0};
    double clipping[3] = {cam->near_clip, cam->far_clip, 0.0};
    sl_vm_set_clipping(vm, cam->near_clip, cam->far_clip);
    /* "screen", "NDC", "raster": the projection trace_camera_ray inverts */
    double fov = atan(cam->tan_half_fov) * (360.0 / M_PI);
    mat4 screen = cam->orthographic ? sl_projection_orthographic(cam->near_clip, cam->far_clip)
                                    : sl_projection_perspective(fov, cam->near_clip,
                                                                cam->far_clip);
    sl_vm_set_projection(vm, &screen, cam->screen, cam->xres, cam->yres);
    sl_vm_set_textures(vm, world->textures);
    /* the renderer's affine runs are displacements' boxes: P alone is read
     * (displace.c, region.c), so a run leaves out what only reaches N */
    sl_vm_set_box_runs(vm, true);
    sl_vm_set_message(vm, SL_MSG_OPTION, "Format", SL_TYPE_POINT, format, NULL);
    sl_vm_set_message(vm, SL_MSG_OPTION, "Clipping", SL_TYPE_POINT, clipping, NULL);
    return vm;
}

/* What the thread hands each of its VMs: the print callback and the
 * cancel flag (trace_thread_set_print, trace_thread_set_cancel). */
static void hand_over(const trace_thread *self, sl_vm *vm)
{
    sl_vm_set_print(vm, self->print, self->print_ctx);
    sl_vm_set_cancel(vm, self->cancel);
}

static void hand_over_all(const trace_thread *self)
{
    hand_over(self, self->vm);
    hand_over(self, self->shade_vm);
    hand_over(self, self->light_vm);
    for (int d = 0; d < TRACE_RAY_DEPTH_LIMIT; d++)
        if (self->ray_vm[d]) hand_over(self, self->ray_vm[d]);
}

trace_thread *trace_thread_new(const trace_world *world)
{
    trace_thread *self = xcalloc(1, sizeof *self);
    self->world = world;
    self->cancel = world->options.cancel;
    self->vm = new_vm(world);
    self->shade_vm = new_vm(world);
    self->light_vm = new_vm(world);
    hand_over_all(self);
    aa_context_init(&self->ctx, world->options.aa_capacity);
    self->cache = trace_boxcache_new(world->options.cache_bytes,
                                     world->nids > world->nobjects ? world->nids : world->nobjects);
    self->work = xcalloc(world->nobjects > 0 ? (size_t)world->nobjects : 1, sizeof *self->work);
    return self;
}

void trace_thread_set_print(trace_thread *self, sl_print_fn fn, void *ctx)
{
    self->print = fn;
    self->print_ctx = ctx;
    hand_over_all(self);
}

void trace_thread_set_cancel(trace_thread *self, const atomic_int *flag)
{
    self->cancel = flag;
    hand_over_all(self);
}

void trace_thread_destroy(trace_thread **self_p)
{
    trace_thread *self = *self_p;
    if (!self) return;
    sl_vm_destroy(&self->vm);
    sl_vm_destroy(&self->shade_vm);
    sl_vm_destroy(&self->light_vm);
    for (int d = 0; d < TRACE_RAY_DEPTH_LIMIT; d++)
        sl_vm_destroy(&self->ray_vm[d]);
    trace_boxcache_destroy(&self->cache);
    free(self->slopes);
    trace_normal_memo_free(self);
    free(self->walls);
    free(self->moves);
    free(self->cases);
    free(self->planes);
    trace_tape_memo_free(self);
    trace_views_free(self);
    free(self->work);
    free(self);
    *self_p = NULL;
}

sl_vm *trace_thread_shade_vm(trace_thread *self, int depth)
{
    if (depth <= 0 || depth > TRACE_RAY_DEPTH_LIMIT) return self->shade_vm;
    if (!self->ray_vm[depth - 1]) {
        self->ray_vm[depth - 1] = new_vm(self->world);
        hand_over(self, self->ray_vm[depth - 1]);
    }
    return self->ray_vm[depth - 1];
}

void trace_thread_fail(trace_thread *self, const char *message)
{
    if (self->failed) return;
    self->failed = true;
    err_set(self->error, sizeof self->error, "%s", message);
}

void trace_object_work_add(trace_object_work *dst, const trace_object_work *src,
                           int nobjects)
{
    for (int i = 0; i < nobjects; i++) {
        const trace_object_work *s = &src[i];
        trace_object_work *d = &dst[i];
        if (s->limited_rays == 0) continue;
        if (d->limited_rays == 0) {
            *d = *s;
            continue;
        }
        d->limited_rays += s->limited_rays;
        if (s->u0 < d->u0) d->u0 = s->u0;
        if (s->u1 > d->u1) d->u1 = s->u1;
        if (s->v0 < d->v0) d->v0 = s->v0;
        if (s->v1 > d->v1) d->v1 = s->v1;
    }
}

void trace_object_work_report(const trace_world *world, const trace_object_work *work,
                              const char *prog, FILE *out)
{
    for (int i = 0; i < world->nobjects; i++) {
        const trace_object_work *w = &work[i];
        if (w->limited_rays == 0) continue;
        const trace_object *obj = &world->objects[i];
        const char *shader = obj->displacement
            ? sl_program_name(sl_instance_program(obj->displacement)) : "(none)";
        fprintf(out, "%s: warning: %s, displacement shader '%s': %ld ray(s) reached the "
                "work limit of %ld quadtree nodes per ray in (u,v) [%.4g, %.4g] x [%.4g, %.4g]; "
                "the surface may be missing from those pixels (see docs/renderer.md, "
                "\"Bounded work\")\n", prog, obj->name, shader, w->limited_rays,
                world->options.max_nodes_per_ray, w->u0, w->u1, w->v0, w->v1);
    }
}

void trace_thread_sync_stats(trace_thread *self)
{
    const trace_boxcache_stats *c = trace_boxcache_stats_get(self->cache);
    self->stats.cache_hits = c->hits;
    self->stats.cache_misses = c->misses;
    self->stats.cache_evictions = c->evictions;
    self->stats.cache_peak_bytes = c->peak_bytes;
    self->stats.uniform_hits = sl_vm_uniform_hits(self->vm);
}

void trace_run_shares(void *shares, size_t size, int n, void *(*fn)(void *))
{
    util_run_shares(shares, size, n, fn);
}

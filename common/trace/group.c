/*
 * group.c: instances kept as references (see group.h): the placements'
 * camera-space boxes and BVH, their traversal, and their views.
 */
#include "trace/group.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/err.h"
#include "util/xalloc.h"

bool trace_group_view_make(trace_thread *th, const trace_object *g, int k, trace_view *out)
{
    const trace_group *gr = g->group;
    assert(gr && k >= 0 && k < gr->n);
    const trace_world *world = th->world;
    trace_object *v = &out->obj;
    *v = world->objects[gr->proto];
    v->place = gr->first + k + 1;
    v->primvars = out->pv;
    gr->transform(gr->user, k, &v->to_camera, &v->from_camera);
    char err[ERR_LEN];
    if (!gr->place(gr->user, k, v, out->pv)) {
        trace_thread_fail(th, "an instance could not be made again (internal error)");
        return false;
    }
    if (!trace_object_derive(world, v, !v->mesh, err, sizeof err)) {
        trace_thread_fail(th, err);    /* trace_world_check passed it: never */
        return false;
    }
    trace_object_camera_bound(v, &v->root, &v->bound);
    return true;
}

void trace_group_build(trace_group *gr, const trace_world *world, trace_object *g)
{
    assert(!gr->bvh);
    const trace_object *proto = &world->objects[gr->proto];
    float (*bounds)[6] = xmalloc(sizeof *bounds * (size_t)(gr->n > 0 ? gr->n : 1));
    trace_object moved = *proto;
    for (int k = 0; k < gr->n; k++) {
        trace_box b;
        gr->transform(gr->user, k, &moved.to_camera, &moved.from_camera);
        trace_object_camera_bound(&moved, &proto->root, &b);
        trace_float_box(&b, bounds[k]);
    }
    gr->bvh = trace_float_bvh_build((const float (*)[6])bounds, gr->n,
                                    world->options.build_threads);
    free(bounds);                      /* the tree keeps them, quantized */
    trace_float_bvh_root(gr->bvh, &g->root);
    g->bound = g->root;                /* camera space: the group's own space */
}

/* One group traversal: the placements' leaf test (trace_float_bvh_leaf) */
typedef struct group_walk {
    trace_thread *th;
    const trace_object *g;
    const trace_ray *ray;
    const trace_tolerance *tol;
    bool any;
    trace_hit *best;
} group_walk;

static int group_leaf(void *ctx, int k)
{
    group_walk *w = ctx;
    const trace_object *v = trace_view_get(w->th, TRACE_VIEWS_PLACES, w->g, k,
                                           trace_group_view_make);
    if (!v) return -1;
    if (v->mesh) {
        bool hit = trace_mesh_intersect(w->th, v, w->ray, w->tol, w->any, w->best);
        return w->th->failed ? -1 : hit;
    }
    if (!trace_intersect_object(w->th, v, w->ray, w->tol, w->any, w->best)) return 0;
    trace_view_hit(w->th, v, w->best);
    return 1;
}

bool trace_group_intersect(trace_thread *th, const trace_object *g, const trace_ray *ray,
                           const trace_tolerance *tol, bool any, trace_hit *best)
{
    const trace_group *gr = g->group;
    group_walk w = {th, g, ray, tol, any, best};
    return trace_float_bvh_walk(gr->bvh, ray, best, any, group_leaf, &w);
}

void trace_group_clear(trace_group *gr)
{
    trace_float_bvh_free(&gr->bvh);
}

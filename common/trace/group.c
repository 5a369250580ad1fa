/*
 * group.c: instances kept as references (see group.h): the placements'
 * camera-space boxes and BVH, their traversal, their views, and which
 * placements of a displaced prototype are its surface moved.
 */
#include "trace/group.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "trace/displace.h"
#include "trace/instance.h"
#include "util/err.h"
#include "util/xalloc.h"

/* Placement k as a full object: the prototype with the placement's
 * transforms, spaces, colour, orientation and primitive variables, its
 * scale, normal bounds and du/dv derived (boxes not set) */
static bool place_view(trace_thread *th, const trace_object *g, int k, trace_view *out)
{
    const trace_group *gr = g->group;
    assert(gr && k >= 0 && k < gr->n);
    const trace_world *world = th->world;
    trace_object *v = &out->obj;
    *v = world->objects[gr->proto];
    v->place = gr->first + k + 1;
    v->primvars = out->pv;
    if (gr->first_id >= 0) v->id = gr->first_id + k;
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
    return true;
}

bool trace_group_view_make(trace_thread *th, const trace_object *g, int k, trace_view *out)
{
    if (!place_view(th, g, k, out)) return false;
    const trace_group *gr = g->group;
    trace_object *v = &out->obj;
    if (gr->first_id >= 0 && gr->own[k] >= 0) {
        v->root = gr->own_roots[gr->own[k]];
    } else if (gr->first_id >= 0) {
        /* the prototype's displaced surface moved (trace/instance.c) */
        const trace_object *proto = &th->world->objects[gr->proto];
        v->box_proto = proto;
        trace_instance_set_motion(v, proto);
    }
    trace_object_camera_bound(v, &v->root, &v->bound);
    return true;
}

/* A displaced prototype's placements: which are its surface moved and
 * which have surfaces of their own (trace_group.own), and the latter's
 * root boxes. Whether the shader gives a placement the prototype's
 * surface moved is asked of up to PROBE_PLACEMENTS placements spread
 * over the group (trace_instance_moves: its points against the moved
 * ones); when one of them says no, every placement has its own surface.
 * Either way a placement's surface is what its view says, so the boxes
 * bound it: the probe only picks the definition RenderMan gives. */
enum { PROBE_PLACEMENTS = 64 };

static bool classify(trace_thread *th, trace_group *gr, const trace_object *g)
{
    const trace_object *proto = &th->world->objects[gr->proto];
    trace_view *tv = xmalloc(sizeof *tv);
    trace_object *v = &tv->obj;
    bool moves = true;
    int stride = gr->n <= PROBE_PLACEMENTS ? 1 : (gr->n + PROBE_PLACEMENTS - 1) / PROBE_PLACEMENTS;
    for (int k = 0; k < gr->n && moves; k += stride) {
        if (!place_view(th, g, k, tv)) break;
        if (trace_instance_rigid(v, proto)) moves = trace_instance_moves(th, v, proto);
        if (th->failed) break;
    }
    gr->own = xmalloc(sizeof *gr->own * (size_t)(gr->n > 0 ? gr->n : 1));
    gr->nown = 0;
    *v = *proto;
    for (int k = 0; k < gr->n && !th->failed; k++) {
        gr->transform(gr->user, k, &v->to_camera, &v->from_camera);
        v->primvars = tv->pv;
        if (!gr->place(gr->user, k, v, tv->pv)) {
            trace_thread_fail(th, "an instance could not be made again (internal error)");
            break;
        }
        gr->own[k] = moves && trace_instance_rigid(v, proto) ? -1 : gr->nown++;
    }
    gr->own_roots = xmalloc(sizeof *gr->own_roots * (size_t)(gr->nown > 0 ? gr->nown : 1));
    for (int k = 0; k < gr->n && !th->failed; k++) {
        if (gr->own[k] < 0) continue;
        if ((k & 255) == 0 && trace_thread_cancelled(th)) break;
        if (place_view(th, g, k, tv))
            trace_surface_box(th, v, 0, 1, 0, 1, &gr->own_roots[gr->own[k]]);
    }
    free(tv);
    return !th->failed && !trace_thread_cancelled(th);
}

bool trace_group_build(trace_thread *th, trace_group *gr, trace_object *g)
{
    assert(!gr->bvh && !gr->own);
    const trace_world *world = th->world;
    const trace_object *proto = &world->objects[gr->proto];
    if (gr->first_id >= 0 && !classify(th, gr, g)) return false;
    float (*bounds)[6] = xmalloc(sizeof *bounds * (size_t)(gr->n > 0 ? gr->n : 1));
    trace_object moved = *proto;
    for (int k = 0; k < gr->n; k++) {
        trace_box b;
        gr->transform(gr->user, k, &moved.to_camera, &moved.from_camera);
        bool own = gr->first_id >= 0 && gr->own[k] >= 0;
        trace_object_camera_bound(&moved, own ? &gr->own_roots[gr->own[k]] : &proto->root, &b);
        trace_float_box(&b, bounds[k]);
    }
    gr->bvh = trace_float_bvh_build((const float (*)[6])bounds, gr->n,
                                    world->options.build_threads);
    free(bounds);                      /* the tree keeps them, quantized */
    trace_float_bvh_root(gr->bvh, &g->root);
    g->bound = g->root;                /* camera space: the group's own space */
    return true;
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
    free(gr->own);
    free(gr->own_roots);
    gr->own = NULL;
    gr->own_roots = NULL;
    gr->nown = 0;
}

/*
 * group.c: instances kept as references (see group.h): the placements'
 * camera-space boxes and BVH, their traversal, their views, and which
 * placements of a displaced prototype are its surface moved.
 */
#include "trace/group.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
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
    if (gr->own && gr->own[k] >= 0) {
        v->root = gr->own_roots[gr->own[k]];
        if (gr->own_meshes) v->mesh = &gr->own_meshes[gr->own[k]];
    } else if (gr->own) {
        /* the prototype's displaced surface moved (trace/instance.c) */
        const trace_object *proto = &th->world->objects[gr->proto];
        v->box_proto = proto;
        trace_instance_set_motion(v, proto);
    }
    trace_object_camera_bound(v, &v->root, &v->bound);
    return true;
}

/* A displaced prototype's placements: which are its surface moved and
 * which have surfaces of their own (trace_group.own). Whether the shader
 * gives a placement the prototype's surface moved is asked of up to
 * PROBE_PLACEMENTS placements spread over the group (trace_instance_moves:
 * its points against the moved ones; a displaced mesh's at PROBE_PIECES
 * of its pieces spread over the mesh); when one of them says no, every
 * placement has its own surface. Either way a placement's surface is
 * what its view says, so the boxes bound it: the probe only picks the
 * definition RenderMan gives. */
enum { PROBE_PLACEMENTS = 64, PROBE_PIECES = 4 };

/* Whether placement v (a view, not yet the prototype moved) of a displaced mesh
 * prototype is the prototype moved at the probe's pieces (their views:
 * trace_instance_moves on each) */
static bool mesh_moves(trace_thread *th, const trace_object *v, const trace_object *proto)
{
    int np = proto->mesh->npieces;
    trace_view *pp = xmalloc(2 * sizeof *pp), *pv = pp + 1;
    bool moves = true;
    for (int i = 0; i < PROBE_PIECES && i < np && moves; i++) {
        int k = (int)((long)np * i / (np < PROBE_PIECES ? np : PROBE_PIECES));
        if (!trace_mesh_view_make(th, proto, k, false, pp) ||
            !trace_mesh_view_make(th, v, k, false, pv)) {
            moves = false;
            break;
        }
        moves = trace_instance_moves(th, &pv->obj, &pp->obj);
    }
    free(pp);
    return moves && !th->failed;
}

static bool classify(trace_thread *th, trace_group *gr, const trace_object *g)
{
    const trace_object *proto = &th->world->objects[gr->proto];
    trace_view *tv = xmalloc(sizeof *tv);
    trace_object *v = &tv->obj;
    bool moves = true;
    int stride = gr->n <= PROBE_PLACEMENTS ? 1 : (gr->n + PROBE_PLACEMENTS - 1) / PROBE_PLACEMENTS;
    for (int k = 0; k < gr->n && moves; k += stride) {
        if (!place_view(th, g, k, tv)) break;
        if (trace_instance_rigid(v, proto)) {
            if (proto->mesh) {
                moves = mesh_moves(th, v, proto);
            } else {
                moves = trace_instance_moves(th, v, proto);
            }
        }
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
    free(tv);
    return !th->failed;
}

/* The root boxes of the own placements: a displaced surface's over its
 * (u,v) square, a displaced mesh's from its own mesh (its pieces' BVH
 * over regions, as any displaced mesh: trace_mesh_build) */
static bool own_roots(trace_thread *th, trace_group *gr, const trace_object *g)
{
    trace_view *tv = xmalloc(sizeof *tv);
    trace_object *v = &tv->obj;
    const trace_mesh *pm = th->world->objects[gr->proto].mesh;
    size_t nb = pm ? (size_t)pm->npieces : 0;
    for (int k = 0; k < gr->n && !th->failed; k++) {
        if (gr->own[k] < 0) continue;
        if ((k & 255) == 0 && trace_thread_cancelled(th)) break;
        if (!place_view(th, g, k, tv)) break;
        if (!gr->own_meshes) {
            trace_surface_box(th, v, 0, 1, 0, 1, &gr->own_roots[gr->own[k]]);
            continue;
        }
        trace_mesh *m = &gr->own_meshes[gr->own[k]];
        v->mesh = m;
        m->bounds = xmalloc(sizeof *m->bounds * (nb > 0 ? nb : 1));
        if (nb > 0) memcpy(m->bounds, gr->proto_bounds, sizeof *m->bounds * nb);
        if (trace_mesh_build(th, v)) gr->own_roots[gr->own[k]] = v->root;
    }
    free(tv);
    free(gr->proto_bounds);
    gr->proto_bounds = NULL;
    return !th->failed && !trace_thread_cancelled(th);
}

bool trace_group_classify_meshes(trace_thread *th, trace_world *world)
{
    for (int i = 0; i < world->nobjects && !th->failed; i++) {
        trace_object *g = &world->objects[i];
        trace_group *gr = g->group;
        if (!gr || gr->own) continue;
        const trace_object *proto = &world->objects[gr->proto];
        if (!proto->mesh || !proto->displacement) continue;
        if (!classify(th, gr, g)) return false;
        const trace_mesh *pm = proto->mesh;
        long ids = (long)gr->nown * pm->npieces;
        if ((long)world->nids + ids > INT32_MAX / 64) {
            char msg[ERR_LEN];
            snprintf(msg, sizeof msg,
                     "%s: %d of them are surfaces of their own (the displacement shader "
                     "does not move with them: docs/renderer.md \"Instances as references\"), "
                     "%ld pieces with boxes of their own, more than a worker can number; "
                     "place them by rigid motions, or split the scene",
                     g->name, gr->nown, ids);
            trace_thread_fail(th, msg);
            return false;
        }
        gr->own_meshes = xcalloc((size_t)(gr->nown > 0 ? gr->nown : 1), sizeof *gr->own_meshes);
        for (int j = 0; j < gr->nown; j++) {
            trace_mesh *m = &gr->own_meshes[j];
            m->npieces = pm->npieces;
            m->nprimvars = pm->nprimvars;
            m->piece = pm->piece;
            m->outline = pm->outline;
            m->user = pm->user;
            m->first_id = world->nids;
            world->nids += pm->npieces;
            /* the pieces' shared edges are the prototype's (the same
             * object-space mesh): borrowed, never freed here */
            m->shared_edges = pm->shared_edges;
            m->wide = pm->wide;
            m->nwide = pm->nwide;
        }
        /* the undisplaced boxes the own meshes start from (the
         * prototype's build frees its own) */
        if (gr->nown > 0) {
            size_t nb = (size_t)(pm->npieces > 0 ? pm->npieces : 1);
            gr->proto_bounds = xmalloc(sizeof *gr->proto_bounds * nb);
            memcpy(gr->proto_bounds, pm->bounds, sizeof *gr->proto_bounds * (size_t)pm->npieces);
        }
    }
    return !th->failed;
}

bool trace_group_build(trace_thread *th, trace_group *gr, trace_object *g)
{
    assert(!gr->bvh);
    const trace_world *world = th->world;
    const trace_object *proto = &world->objects[gr->proto];
    /* a displaced surface's placements are sorted here, a displaced
     * mesh's before (trace_group_classify_meshes: they may need ids) */
    if (gr->first_id >= 0 && !gr->own && !classify(th, gr, g)) return false;
    if (gr->own && !own_roots(th, gr, g)) return false;
    float (*bounds)[6] = xmalloc(sizeof *bounds * (size_t)(gr->n > 0 ? gr->n : 1));
    trace_object moved = *proto;
    for (int k = 0; k < gr->n; k++) {
        trace_box b;
        gr->transform(gr->user, k, &moved.to_camera, &moved.from_camera);
        bool own = gr->own && gr->own[k] >= 0;
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

/* A displaced mesh's placement that is its prototype moved: the
 * prototype's walk, the ray moved rigidly into the prototype's camera
 * space (t is kept), every box and cache the prototype's; a hit becomes
 * the placement's piece (trace_view_hit_moved) */
static int moved_mesh_leaf(group_walk *w, const trace_object *v)
{
    trace_ray moved;
    trace_ray_init(&moved, mat4_xform_point(&v->to_proto, w->ray->o),
                   mat4_xform_vector(&v->to_proto, w->ray->d), w->ray->tmin, w->ray->tmax);
    trace_hit hit = *w->best;
    if (!trace_mesh_intersect(w->th, v->box_proto, &moved, w->tol, w->any, &hit))
        return w->th->failed ? -1 : 0;
    /* a shadow ray asks only whether (shade.c): its hit is not shaded */
    if (!w->any && !trace_view_hit_moved(w->th, v, &hit)) return -1;
    *w->best = hit;
    return 1;
}

static int group_leaf(void *ctx, int k)
{
    group_walk *w = ctx;
    const trace_object *v = trace_view_get(w->th, TRACE_VIEWS_PLACES, w->g, k,
                                           trace_group_view_make);
    if (!v) return -1;
    if (v->mesh && v->box_proto) return moved_mesh_leaf(w, v);
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
    for (int j = 0; gr->own_meshes && j < gr->nown; j++) {
        trace_mesh *m = &gr->own_meshes[j];
        m->shared_edges = NULL;        /* the prototype's */
        m->wide = NULL;
        m->nwide = 0;
        trace_mesh_clear(m);
    }
    free(gr->own_meshes);
    free(gr->proto_bounds);
    free(gr->own);
    free(gr->own_roots);
    gr->own_meshes = NULL;
    gr->proto_bounds = NULL;
    gr->own = NULL;
    gr->own_roots = NULL;
    gr->nown = 0;
}

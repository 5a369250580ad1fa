/*
 * mesh.h: mesh objects (issue 23): one world object for the many pieces
 * of a polygon mesh (trace_mesh in world.h), a BVH over the pieces'
 * object-space boxes (shared by the objects that place one undisplaced
 * mesh: instances), and the "views" that make a piece a full
 * trace_object where a ray reaches it.
 *
 * A view is piece k of mesh object M: M's transforms, shaders and
 * attributes, the piece's surface and primitive variables, its own id
 * (M's first_id + k: box cache and cell caches keep pieces apart), its
 * du/dv, shared edges and root box, each a pure function of the scene,
 * so a view made twice, on any thread or host, is the same object. A
 * thread keeps the views it made last in a small direct-mapped cache;
 * the hit a traversal returns is a copy in the thread's hit slot, and a
 * hit being shaded is a copy per trace() depth (trace_view_hold), so the
 * shadow and trace() rays its shader casts cannot overwrite it.
 *
 * Per piece, a worker holds the scene's 16-byte piece, its shared edges
 * and its share of the BVH (docs/renderer.md "Meshes"), and a displaced
 * piece's root box and du/dv once a ray has reached it (lazy_roots.h); the
 * box cache holds the displaced pieces' refinement trees under its budget,
 * as for any object.
 */
#ifndef TRACE_MESH_H
#define TRACE_MESH_H

#include "trace/intersect.h"
#include "trace/thread.h"
#include "trace/world.h"

typedef struct trace_view {
    trace_object obj;
    trace_primvar pv[TRACE_MAX_PRIMVARS];
} trace_view;

/* Makes piece k of mesh object `mesh_obj` into *out, with its root and
 * bound boxes when `boxes` (a displaced piece's root box runs its shader
 * over the whole piece); false (the thread failed) when the piece cannot
 * be made. */
bool trace_mesh_view_make(trace_thread *th, const trace_object *mesh_obj, int k, bool boxes,
                          trace_view *out);

/* The view of piece k from the thread's cache (made on a miss). */
const trace_object *trace_mesh_view(trace_thread *th, const trace_object *mesh_obj, int k);

/* The thread's view caches: pieces of meshes, placements of groups. */
typedef enum trace_view_kind { TRACE_VIEWS_PIECES, TRACE_VIEWS_PLACES } trace_view_kind;
typedef bool (*trace_view_make_fn)(trace_thread *th, const trace_object *obj, int k,
                                   trace_view *out);

/* The view of element k of obj (its id, its placement and k are the key)
 * from the thread's cache `which`, made by `make` on a miss; NULL when
 * that failed (the thread failed). Valid until the next call for the same
 * cache. */
const trace_object *trace_view_get(trace_thread *th, trace_view_kind which, const trace_object *obj,
                                   int k, trace_view_make_fn make);

/* A view the traversal found the nearest hit on: the hit outlives the
 * cache slot, so best->obj becomes a copy of v in the thread's hit slot. */
void trace_view_hit(trace_thread *th, const trace_object *v, trace_hit *best);

/* The pieces of an object: a mesh's, or 1 (the object itself); a group
 * has none of its own (its placements are its prototype's surfaces
 * moved). */
static inline int trace_object_npieces(const trace_object *obj)
{
    return obj->group ? 0 : obj->mesh ? obj->mesh->npieces : 1;
}

/* Piece k of obj as an object: obj itself (k = 0) when it is not a mesh,
 * else the piece's view made into *storage with its boxes (NULL: the
 * thread failed). For tools and tests that visit every surface. */
const trace_object *trace_object_piece(trace_thread *th, const trace_object *obj, int k,
                                       trace_view *storage);

/* Copies a view (its primitive variables point at its own copy). */
void trace_view_copy(trace_view *dst, const trace_view *src);

/* The object-space float box of an undisplaced piece s (its bounds,
 * rounded outward). */
void trace_mesh_piece_bounds(const geom_surface *s, float out[6]);

/* The pieces' boxes and BVH of mesh object obj's mesh (once for the
 * objects that share it), and obj's root (their union, object space) and
 * camera-space bound; false when the thread failed (cancelled: no tree).
 * A displaced mesh's boxes come from regions of its tree (its pieces' root
 * boxes are made when a ray first reaches them: mesh.c), over world
 * options.build_threads threads (the same boxes, to the bit, for any
 * count). */
bool trace_mesh_build(trace_thread *th, trace_object *obj);

/* Nearest hit of the camera-space ray with the mesh's pieces in
 * (ray->tmin, best->t) (trace_intersect_object's contract); a hit's
 * object is the thread's hit slot (a view). */
bool trace_mesh_intersect(trace_thread *th, const trace_object *obj, const trace_ray *ray,
                          const trace_tolerance *tol, bool any, trace_hit *best);

/* A hit the walk of placement v's prototype found (v: a displaced mesh's
 * placement that is its prototype moved, v->box_proto; the hit's object
 * the prototype's piece in the thread's hit slot, its geometry in the
 * prototype's camera space) made the placement's: its object the
 * placement's piece, whose box_proto is the prototype's piece (kept
 * beside it), its point and wall normal moved into v's camera space.
 * False (the thread failed) when the piece cannot be made. */
bool trace_view_hit_moved(trace_thread *th, const trace_object *v, trace_hit *hit);

/* The object to shade for a hit at trace() depth `depth`: obj itself, or
 * when it is the thread's hit slot, its copy for that depth. */
const trace_object *trace_view_hold(trace_thread *th, const trace_object *obj, int depth);

/* The per-thread view storage (thread.c frees it). */
void trace_views_free(trace_thread *th);

/* Piece k's shared edges (trace_object.shared_edges): its byte, and its
 * wide bits when it has more than 8 corners. */
uint64_t trace_mesh_shared_edges(const trace_mesh *m, int k);

/* Marks edge `edge` of piece k shared (world.c); trace_mesh_edges_done
 * orders the wide bits once every edge is marked. */
void trace_mesh_mark_edge(trace_mesh *m, int k, int edge);
void trace_mesh_edges_done(trace_mesh *m);

/* Frees the derived arrays (shared edges, boxes, BVH); the source stays. */
void trace_mesh_clear(trace_mesh *self);

/* Bytes of the derived arrays (boxes, BVH, shared edges). */
size_t trace_mesh_bytes(const trace_mesh *self);

/* A BVH over float boxes (a mesh's pieces, a group's placements): binned
 * SAH, 32-byte nodes, each element's box kept in 6 bytes on its leaf's
 * grid, rounded outward (mesh.c): the caller's boxes may be freed once it
 * is built. Its subtrees are built over `threads` threads: the same tree,
 * to the bit, for any count. */
struct trace_mesh_bvh *trace_float_bvh_build(const float (*bounds)[6], int n, int threads);
void trace_float_bvh_free(struct trace_mesh_bvh **t);
size_t trace_float_bvh_bytes(const struct trace_mesh_bvh *t, int n);
/* Its root's box (all the boxes); false (an empty box) when it has none. */
bool trace_float_bvh_root(const struct trace_mesh_bvh *t, trace_box *out);
/* Visits, nearer nodes first, each element k whose box `ray` (in the
 * boxes' space) meets before best->t: leaf(ctx, k) returns 1 when it
 * found a hit (best updated), 0 when not, -1 to stop (a failure). True
 * when a leaf found a hit; `any`: stops at the first. */
typedef int (*trace_float_bvh_leaf)(void *ctx, int k);
bool trace_float_bvh_walk(const struct trace_mesh_bvh *t, const trace_ray *ray, trace_hit *best,
                          bool any, trace_float_bvh_leaf leaf, void *ctx);
/* Whether two trees are the same to the bit (nodes, order, element boxes). */
bool trace_float_bvh_equal(const struct trace_mesh_bvh *a, const struct trace_mesh_bvh *b, int n);
/* b as a float box (lo, hi), rounded outward. */
void trace_float_box(const trace_box *b, float f[6]);

/* The camera-space box of an object-space box b of obj (its 8 corners,
 * widened by a relative hair for the rounding). */
void trace_object_camera_bound(const trace_object *obj, const trace_box *b, trace_box *out);

/* A 64-bit digest of what the world derived for mesh m: its BVH (nodes,
 * order, quantized boxes) and its pieces' shared edges; equal worlds have
 * equal digests (benchmarks and tests compare builds with it). */
uint64_t trace_mesh_digest(const trace_mesh *self);

#endif

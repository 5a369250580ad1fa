/*
 * intersect.h: ray / object intersection.
 *
 * Displaced objects: the hierarchical subdivision of Heidrich & Seidel §3
 * with the box cache and closest-first traversal of §6 and the
 * discontinuity rule of §5:
 *
 *   visit(node): get the four child boxes (box cache, or evaluate them);
 *     intersect the ray with each; in order of entry distance, skipping
 *     any child that starts beyond the best hit so far:
 *       a small child (at most 16 tolerances) well inside a polygon is
 *       first put to the hit proof (prove.h): a proven miss drops it, a
 *       proven hit is the surface's own point, and only an undecided
 *       child goes on;
 *       the child is a LEAF if its size is below the tolerance at its
 *       distance (primary rays: a pixel footprint scaled by ShadingRate;
 *       shadow rays: a fixed world size from the pixel footprint at the
 *       shaded point), or it is discontinuous and stopped shrinking (a
 *       vertical wall, §5), or the depth cap is reached;
 *       a leaf reports a hit, anything else is visited recursively.
 *
 * Objects without displacement: exact intersection (geom_intersect).
 *
 * Boxes live in object space (see displace.h); the ray is mapped into each
 * object's space (t is preserved by affine maps).
 */
#ifndef TRACE_INTERSECT_H
#define TRACE_INTERSECT_H

#include <stdbool.h>

#include "trace/box.h"
#include "trace/displace.h"
#include "trace/thread.h"
#include "trace/world.h"

enum { TRACE_MAX_DEPTH = 22 };       /* (u,v) cells down to 2^-22 */

/* Leaf size tolerance at ray parameter t: at + bt * t (camera units). */
typedef struct trace_tolerance { double a, b; } trace_tolerance;

typedef enum trace_leaf_kind {
    TRACE_LEAF_SMALL,      /* box below the tolerance */
    TRACE_LEAF_WALL,       /* §5: discontinuous and no longer shrinking */
    TRACE_LEAF_DEPTH,      /* depth cap */
    TRACE_LEAF_EXACT,      /* analytic intersection, no boxes */
    TRACE_LEAF_PROVEN,     /* a cell with one hit, proven (prove.h) */
} trace_leaf_kind;

typedef struct trace_hit {
    double t;                      /* ray parameter; init to the ray's tmax */
    const trace_object *obj;       /* NULL: no hit */
    double u, v;                   /* centre of the leaf, or the exact hit */
    double leaf_size;              /* camera-space size of the leaf box (0: exact) */
    trace_leaf_kind kind;
    vec3 wall_normal;              /* TRACE_LEAF_WALL: camera space, unit */
    bool has_point;                /* point holds the surface at (u, v) */
    trace_surface_point point;     /* small and depth-cap leaves: the dual
                                      evaluation the hit was placed with,
                                      reused for shading */
} trace_hit;

/* Intersects one object; updates *best when a hit nearer than best->t is
 * found (returns true then). any: stop at the first hit (shadow rays). */
bool trace_intersect_object(trace_thread *th, const trace_object *obj,
                            const trace_ray *ray, const trace_tolerance *tol,
                            bool any, trace_hit *best);

#endif

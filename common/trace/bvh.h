/*
 * bvh.h: a bounding volume hierarchy over the objects of a world, built
 * from each object's camera-space root box (its affine box over the whole
 * (u,v) square, or its exact bounds when undisplaced). Binary, split at the
 * median of the longest axis; traversal visits the nearer child first and
 * skips nodes beyond the best hit (the same rule the box cache traversal
 * uses inside objects, Heidrich & Seidel §6).
 */
#ifndef TRACE_BVH_H
#define TRACE_BVH_H

#include "trace/intersect.h"

typedef struct trace_bvh trace_bvh;

trace_bvh *trace_bvh_new(const trace_world *world);
void trace_bvh_destroy(trace_bvh **self_p);

/* Nearest hit along the camera-space ray in (ray->tmin, best->t); true if
 * one was found. any: the first hit will do (shadow rays). */
bool trace_bvh_intersect(const trace_bvh *self, trace_thread *th,
                         const trace_ray *ray, const trace_tolerance *tol,
                         bool any, trace_hit *best);

#endif

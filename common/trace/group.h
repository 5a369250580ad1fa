/*
 * group.h: instances kept as references (issue 23; trace_group in
 * world.h): one world object stands for the placements of a prototype,
 * a BVH over their camera-space boxes, and a placement becomes a full
 * trace_object (a view) only where a ray reaches it.
 *
 * A placement's view is the prototype with the placement's transforms,
 * shaders' spaces, colour, orientation and primitive variables, its
 * scale, normal bounds and du/dv derived again, and the prototype's ids:
 * the placements of an undisplaced surface or mesh are the same surface
 * in object space, where boxes and cell caches live, so they share them
 * (its `place` keeps their views apart). A displaced surface's or
 * displaced mesh's placement is either the prototype's displaced surface
 * moved rigidly (trace/instance.c: its boxes are the prototype's) or its
 * own surface with its own boxes, decided for every placement before
 * the group is built (group.c, docs/renderer.md "Instances as
 * references"). A displaced surface's placement has an id of its own; a
 * displaced mesh's moved placement is walked as its prototype, the ray
 * moved into the prototype's camera space, and an own one gets a mesh of
 * its own (ids, BVH and root boxes over the prototype's pieces). A view
 * is a pure function of the scene: the same on any thread or host.
 *
 * Per placement the world holds a 24-byte float box, ~16 bytes of BVH and
 * what the adapter keeps to make it again (job_scene.c: its scene object's
 * index), a displaced one 4 bytes more (and its root box when it has its
 * own surface, and a displaced mesh's own mesh then: as an object of its
 * own); the scene holds the placement's scene_object.
 */
#ifndef TRACE_GROUP_H
#define TRACE_GROUP_H

#include "trace/mesh.h"

/* The placements' boxes and BVH of group object g (its prototype's root
 * must be known) and g's root and bound (their union, camera space); for
 * a displaced prototype first which placements are its surface moved
 * (the shader runs on th). False when the thread failed or was
 * cancelled. */
bool trace_group_build(trace_thread *th, trace_group *group, trace_object *g);

/* Sorts the placements of every group whose prototype is a displaced
 * mesh into its surface moved and surfaces of their own (the probe:
 * group.c), and gives each of the latter a mesh of its own over the
 * prototype's pieces, with ids from world->nids (which grows: a thread
 * made before has a box cache too small for them). Called by
 * trace_renderer_new after trace_world_prepare, before any mesh is
 * built. False (th failed) when a shader failed or the ids run out. */
bool trace_group_classify_meshes(trace_thread *th, trace_world *world);

/* Nearest hit of the camera-space ray with the placements in
 * (ray->tmin, best->t) (trace_intersect_object's contract); a hit's
 * object is the thread's hit slot (a view). With `any` (a shadow ray: only
 * whether), a displaced mesh's moved placement's hit stays its prototype's
 * piece, in the prototype's camera space. */
bool trace_group_intersect(trace_thread *th, const trace_object *g, const trace_ray *ray,
                           const trace_tolerance *tol, bool any, trace_hit *best);

/* Placement k of group object g as a full object into *out (with its
 * root and bound); false (the thread failed) when it cannot be made. */
bool trace_group_view_make(trace_thread *th, const trace_object *g, int k, trace_view *out);

/* Frees the derived arrays (boxes, BVH). */
void trace_group_clear(trace_group *group);

#endif

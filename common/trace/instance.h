/*
 * instance.h: instances that share one set of boxes (issue 14, "no copy
 * per instance"; docs/renderer.md "Instances").
 *
 * Every object an ObjectInstance places names the first object placed from
 * the same recorded surface (scene_object.instance_of, which the adapter
 * turns into trace_object.box_proto). trace_instances_share keeps that
 * link only where the instance's displaced surface is the prototype's,
 * moved rigidly; the object then uses the prototype's object-space boxes
 * and box cache entries (trace_box_owner), and its points are the
 * prototype's points moved into its camera space (displace.c).
 */
#ifndef TRACE_INSTANCE_H
#define TRACE_INSTANCE_H

#include "trace/thread.h"
#include "trace/world.h"

/* Decides, for every object of the world with a box_proto, whether it
 * keeps it (and sets from_proto, to_proto) or gets its own boxes
 * (box_proto = NULL). Runs the displacement shaders on th (a probe of the
 * surface). Returns how many objects share a prototype's boxes. Called by
 * trace_renderer_new after trace_world_prepare. */
int trace_instances_share(trace_thread *th, trace_world *world);

/* Whether obj (box_proto NULL) may be proto's displaced surface moved:
 * the same displacement instance without output parameters, orientation
 * and kind of surface, a rigid motion between their camera spaces (set
 * into obj->from_proto, to_proto), and every space the shader names
 * moving with it (no "world", "camera", screen, NDC or raster; "shader"
 * space only where it is the instance's). No shader runs. */
bool trace_instance_rigid(trace_object *obj, const trace_object *proto);

/* obj->from_proto and to_proto: proto's camera space to obj's and back. */
void trace_instance_set_motion(trace_object *obj, const trace_object *proto);

/* trace_instance_rigid, and the probe: obj's own displaced points and
 * normals on a 5 x 5 grid of (u,v) equal proto's moved ones (the shader
 * runs on th). obj->box_proto is NULL on return either way. */
bool trace_instance_moves(trace_thread *th, trace_object *obj, const trace_object *proto);

#endif

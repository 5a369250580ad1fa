/*
 * region.h: one sound box for MANY pieces of a displaced mesh (issue 23:
 * the building block of lazy root boxes, a box per BVH node made when a
 * ray first reaches it instead of one shader run per piece at world
 * build). Heidrich & Seidel 1998 §3.1 and §4.2: the displacement shader
 * runs once in affine arithmetic over a REGION, every global bound to an
 * enclosure that holds for every given piece at every (u,v) of it; see
 * region.c for the bindings and what is refused.
 */
#ifndef TRACE_REGION_H
#define TRACE_REGION_H

#include <stdbool.h>

#include "trace/thread.h"
#include "trace/world.h"

/* An OBJECT-space box (the space of mesh_obj's pieces' root boxes and of
 * its BVH) holding every displaced point of pieces[0..n) of mesh object
 * mesh_obj, hence each piece's own root box's points (not its box: the
 * piece's box may be wider than the surface). One affine run of the
 * displacement shader (none for an undisplaced mesh: the union of the
 * pieces' bounds); the pieces are visited without their shader.
 *
 * True with a finite box; n = 0 gives the empty box. False with the
 * unbounded box (flag AA_UNBOUNDED) where no sound finite box was found:
 * a primitive variable the region cannot bind (a shader parameter, an
 * unknown global, pieces whose variables differ), a failed or cancelled
 * shader run (th is NOT failed by it: the per-piece boxes remain the way
 * out), an unbounded or undefined result, or a piece that could not be
 * made (then th failed, as trace_mesh_view_make says). */
bool trace_mesh_region_box(trace_thread *th, const trace_object *mesh_obj, const int *pieces,
                           int n, trace_box *out);

#endif

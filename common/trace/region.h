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

/* The same in steps, for a pass over many pieces on several threads (the
 * lazy root boxes of mesh.c): a region's enclosures start empty, take
 * pieces (views) one by one, merge (the hulls are exact minima and
 * maxima: any order gives the same bits), and run the shader once. */
typedef struct trace_region trace_region;
trace_region *trace_region_new(void);
void trace_region_destroy(trace_region **self);

/* Adds piece view `piece` (made with its du/dv, trace_mesh_view_make),
 * or with `dudv` (not NULL) enclosures of its du and dv instead. False
 * where the region must refuse the piece (its primitive variables: see
 * above); the region then stays refused. */
bool trace_region_add(trace_thread *th, trace_region *self, const trace_object *piece,
                      const ia_interval *dudv);
/* A displaced piece's undisplaced object-space box over its whole (u,v)
 * square (lo, hi), rounded outward, from its surface: its displaced points
 * lie in it plus the `shift` of any region it is in (trace_region_run).
 * ctx: a context of at least 2 symbols, reset here. */
void trace_region_base(aa_context *ctx, const geom_surface *surf, float base[6]);
void trace_region_merge(trace_region *into, const trace_region *from);

/* The region's box, as trace_mesh_region_box; with `shift` (may be NULL)
 * also an enclosure of the displacement itself, P' - P in object space,
 * over every point of every piece: a piece's displaced points lie in its
 * trace_region_base box plus `shift`. False (the unbounded box) as above, and for an
 * empty or refused region. */
bool trace_region_run(trace_thread *th, const trace_object *mesh_obj, const trace_region *self,
                      trace_box *out, ia_interval shift[3]);

#endif

/*
 * normal_memo.h: the camera-space unit normal of a displaced surface's
 * base over a (u,v) box in affine arithmetic, through a per-thread memo
 * (issue 24): a planar bilinear patch (a height field's base) or a flat
 * polygon has the same symbol-free Ng in every box, so the same unit
 * normal, which cost a box 3,500-4,600 instructions (normalize and the
 * camera transform in affine arithmetic). See normal_memo.c.
 */
#ifndef TRACE_NORMAL_MEMO_H
#define TRACE_NORMAL_MEMO_H

#include "geom/surface.h"
#include "trace/thread.h"
#include "trace/world.h"

/* N = trace_camera_normal_aa of geom_unit_normal_aa (the same bits), in
 * th->ctx, copied from th's memo where this object slot last computed it
 * from the same Ng and object transform. */
void trace_camera_unit_normal_aa(trace_thread *th, const trace_object *obj, const aa_form *u,
                                 const aa_form *v, const geom_aa *g, aa_form N[3]);

/* th's memo, freed (trace_thread_destroy) */
void trace_normal_memo_free(trace_thread *th);

#endif

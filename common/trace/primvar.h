/*
 * primvar.h: primitive variables handed to shaders (RI Spec 3.2 §5.1, as
 * RenderMan does: a shader parameter of the variable's name takes its value
 * interpolated over the surface; "st" sets the globals s, t; "Cs", "Os"
 * the surface shader's globals). See trace_primvar (world.h) and
 * docs/renderer.md "Primitive variables".
 */
#ifndef TRACE_PRIMVAR_H
#define TRACE_PRIMVAR_H

#include "trace/world.h"

/* Sets the object's variables on vm for the coming run of its
 * displacement (surface false) or surface shader, after the globals are
 * bound (they last until the next sl_vm_clear_globals). The VM computes
 * them from the globals u, v in the run's arithmetic. */
void trace_primvars_bind(sl_vm *vm, const trace_object *obj, bool surface);

/* The value of global g (SL_G_Cs, SL_G_Os) at (u,v) from the object's
 * variables into out[3]; false when no variable sets it. */
bool trace_primvar_global(const trace_object *obj, sl_global g, double u, double v,
                          double out[3]);

#endif

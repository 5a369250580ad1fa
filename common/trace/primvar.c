/*
 * primvar.c: primitive variables handed to shaders (see primvar.h).
 *
 * Each variable is a polynomial of the object's (u,v), bicubic at most
 * (linear over a mesh triangle, bilinear over a patch, bicubic for the
 * vertex class of a bicubic patch; common/scene/rib_primvar.c). The VM evaluates it from its u, v globals in the run's
 * own arithmetic (sl_vm_set_varying_*), so a box of Heidrich & Seidel §3
 * over a (u,v) range bounds the variable conservatively (exactly, up to
 * rounding, where it is linear: an affine form of u and v), a dual run gets
 * its derivatives, and a range run that takes derivatives gets their
 * bounds.
 */
#include "trace/primvar.h"

void trace_primvars_bind(sl_vm *vm, const trace_object *obj, bool surface)
{
    for (int i = 0; i < obj->nprimvars; i++) {
        const trace_primvar *pv = &obj->primvars[i];
        if (pv->global != SL_G__COUNT)
            sl_vm_set_varying_global(vm, pv->global, pv->c);
        int param = surface ? pv->surface_param : pv->displacement_param;
        if (param >= 0)
            sl_vm_set_varying_param(vm, param, pv->size, pv->c);
    }
}

bool trace_primvar_global(const trace_object *obj, sl_global g, double u, double v,
                          double out[3])
{
    for (int i = obj->nprimvars - 1; i >= 0; i--) {
        const trace_primvar *pv = &obj->primvars[i];
        if (pv->global != g || pv->size != 3) continue;
        for (int k = 0; k < 3; k++) {
            double acc = 0;
            for (int j = 3; j >= 0; j--) {
                double q = 0;
                for (int a = 3; a >= 0; a--) q = q * u + pv->c[a + 4 * j][k];
                acc = acc * v + q;
            }
            out[k] = acc;
        }
        return true;
    }
    return false;
}

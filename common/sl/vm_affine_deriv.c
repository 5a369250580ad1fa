/*
 * vm_affine_deriv.c: the VM in affine arithmetic with derivative bounds
 * (vm_deriv.inc): for shaders that take derivatives (Du, Dv, Deriv,
 * calculatenormal, area), each slot is an affine form of its value plus
 * interval enclosures of its d/du and d/dv over the range (issue 9).
 * vm_affine_deriv_tape.c compiles this file once more with VM_TAPE, for
 * the box runs that take or record a tape (tape_plan.c).
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#define VM_OP(plain, deriv) deriv
#include "vm_affine_ops.h"
#undef VM_OP

typedef aa_form B;

static inline ia_interval b_hull(const B *x) { return aa_range(x); }
static inline void b_from_interval(sl_vm *vm, B *z, ia_interval r)
{
    aa_from_interval(vm->ctx, z, r);
}

#define VM_T sl_aderiv
#ifdef VM_TAPE
#define VM_SUFFIX affine_deriv_tape   /* vm_affine_deriv_tape.c */
#else
#define VM_SUFFIX affine_deriv
#endif
#define VM_FILE(vm) ((vm)->ad)
#define VM_VARIANT VM_VAR_AFFINE_DERIV
#define VM_BOX_RUNS 1                 /* box runs follow the program's plan */
#define VM_TEXTURE_ARGS 1             /* b_texture_args: no copies of the arguments */
#define VM_UNIFORM 1                  /* the uniform memo (vm_uniform.inc) */
#define VM_UNIFORM_DERIV 1
#define VM_SPLIT_BRANCHES 1           /* case splits take branches too */
#include "vm_deriv.inc"

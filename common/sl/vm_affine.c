/*
 * vm_affine.c: the VM in rounding-safe affine arithmetic (common/aa
 * affine.h) over the caller's aa_context: the range analysis of Heidrich
 * & Seidel 1998 §4. Slots are aa_forms written in place; a copy moves the
 * whole form (a fixed size, no libc call). A comparison looks at the
 * affine form of the difference of its operands, so correlated operands
 * (u against u + 0.1) decide where intervals could not; undecided ones
 * run both branches and merge with aa_merge (§4.1, §5). The operations
 * live in vm_affine_ops.h; programs that take derivatives run in
 * vm_affine_deriv.c instead, so here Du/Dv/Deriv/calculatenormal/area are
 * never reached with a meaning (unbounded if they were). vm_affine_tape.c
 * compiles this file once more with VM_TAPE, for the box runs that take
 * or record a tape (tape_plan.c).
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#define VM_T aa_form
#ifdef VM_TAPE
#define VM_SUFFIX affine_tape         /* vm_affine_tape.c */
#else
#define VM_SUFFIX affine
#endif
#define VM_FILE(vm) ((vm)->a)
#define VM_VARIANT VM_VAR_AFFINE
#define VM_OP(plain, deriv) plain
#include "vm_affine_ops.h"

#define VM_UNIFORM 1                  /* the uniform memo (vm_uniform.inc) */
#define VM_ROWS3 1                    /* transforms by rows (v_rows3) */
#define VM_SPLIT_BRANCHES 1           /* case splits take branches too */
#include "vm_exec.inc"

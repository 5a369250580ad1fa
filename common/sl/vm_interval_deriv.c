/*
 * vm_interval_deriv.c: the VM in interval arithmetic with derivative
 * bounds (vm_deriv.inc): for shaders that take derivatives (Du, Dv, Deriv,
 * calculatenormal, area), each slot is the interval of its value plus
 * interval enclosures of its d/du and d/dv over the range (issue 9).
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <string.h>

#define VM_OP(plain, deriv) deriv
#include "vm_interval_ops.h"
#undef VM_OP

typedef ia_interval B;

static inline ia_interval b_hull(const B *x) { return *x; }
static inline void b_from_interval(sl_vm *vm, B *z, ia_interval r)
{
    (void)vm;
    *z = r;
}

#define VM_T sl_ideriv
#define VM_SUFFIX interval_deriv
#define VM_FILE(vm) ((vm)->id)
#define VM_VARIANT VM_VAR_INTERVAL_DERIV
#define VM_BOX_RUNS 1                 /* box and slope runs follow the plans */
#include "vm_deriv.inc"

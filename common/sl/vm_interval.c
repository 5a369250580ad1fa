/*
 * vm_interval.c: the VM in rounding-safe interval arithmetic (common/aa
 * interval.h), the comparison peer of the affine mode (Heidrich & Seidel
 * 1998 §7.1). Every slot encloses all values the shader can compute over
 * the input box; comparisons are tri-state and undecided branches are run
 * both ways and merged (vm_exec.inc). The operations live in
 * vm_interval_ops.h; programs that take derivatives run in
 * vm_interval_deriv.c instead.
 */
#include "sl/noise.h"
#include "sl/vm_internal.h"

#include <math.h>
#include <string.h>

#define VM_T ia_interval
#define VM_SUFFIX interval
#define VM_FILE(vm) ((vm)->i)
#define VM_VARIANT VM_VAR_INTERVAL
#define VM_OP(plain, deriv) plain
#include "vm_interval_ops.h"

#include "vm_exec.inc"

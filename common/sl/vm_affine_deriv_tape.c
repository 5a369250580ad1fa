/*
 * vm_affine_deriv_tape.c: the derivative-carrying affine VM
 * (vm_affine_deriv.c) once more, with tape pruning (VM_TAPE: vm_exec.inc,
 * tape_plan.c), for the box runs that take or record a tape.
 */
#define VM_TAPE 1
#include "vm_affine_deriv.c"

/*
 * vm_affine_tape.c: the affine VM (vm_affine.c) once more, with tape
 * pruning (VM_TAPE: vm_exec.inc, tape_plan.c): the box runs that take a
 * tape's plan or note their tape sites' decisions run here, so that a run
 * without a tape pays nothing for it (its checks cost dented's box runs
 * 10 % when every run had them).
 */
#define VM_TAPE 1
#include "vm_affine.c"

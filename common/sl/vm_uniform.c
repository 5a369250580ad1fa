/*
 * vm_uniform.c: the untyped half of the uniform memo of the affine VMs
 * (vm_uniform.inc holds the typed half and says what the memo is): which
 * operations may be remembered, and the memo blocks' lifetime.
 */
#include "sl/vm_internal.h"
#include "util/xalloc.h"

#include <stdlib.h>

int vm_uniform_arity(int op)
{
    switch ((sl_opcode)op) {
    case SL_OP_NEG: case SL_OP_SQRT: case SL_OP_INVSQRT: case SL_OP_EXP: case SL_OP_LOG:
    case SL_OP_SIN: case SL_OP_COS: case SL_OP_TAN: case SL_OP_ASIN: case SL_OP_ACOS:
    case SL_OP_ATAN: case SL_OP_ABS: case SL_OP_SIGN: case SL_OP_NOT:
        return 1;
    case SL_OP_DU: case SL_OP_DV:
        return VM_UNIFORM_DERIVS_OF_B;
    case SL_OP_ADD: case SL_OP_SUB: case SL_OP_MUL: case SL_OP_DIV:
    case SL_OP_POW: case SL_OP_ATAN2: case SL_OP_MIN: case SL_OP_MAX:
    case SL_OP_LT: case SL_OP_LE: case SL_OP_GT: case SL_OP_GE: case SL_OP_EQ: case SL_OP_NE:
    case SL_OP_AND: case SL_OP_OR: case SL_OP_DERIV:
        return 2;
    case SL_OP_CLAMP: case SL_OP_SMOOTHSTEP: case SL_OP_MIX:
        return 3;
    default:
        /* moves (cheaper than a look-up), floor/ceil/round/mod/step (case
         * splits), noise, texture, random, lights, spaces, strings,
         * arrays, control flow, several outputs */
        return 0;
    }
}

void vm_uniform_block_reset(vm_uniform_block *b, const sl_program *p, int variant, int flavour)
{
    if (b->ncode < p->ncode) {
        b->misses = xreallocarray(b->misses, (size_t)p->ncode, sizeof *b->misses);
        b->index = xreallocarray(b->index, (size_t)p->ncode, sizeof *b->index);
        b->arity = xreallocarray(b->arity, (size_t)p->ncode, sizeof *b->arity);
    }
    b->ncode = p->ncode > b->ncode ? p->ncode : b->ncode;
    for (int pc = 0; pc < p->ncode; pc++) {
        int a = vm_uniform_arity(p->code[pc].op);
        if (a == VM_UNIFORM_DERIVS_OF_B && variant != VM_VAR_AFFINE_DERIV)
            a = 0;                     /* no derivative bounds: Du has no meaning */
        b->arity[pc] = (uint8_t)a;
        b->misses[pc] = b->arity[pc] ? 0 : VM_UNIFORM_GIVE_UP;
        b->index[pc] = -1;
    }
    b->nentries = 0;
    b->serial = p->serial;
    b->variant = variant;
    b->flavour = flavour;
}

vm_uniform_entry *vm_uniform_entry_at(vm_uniform_block *b, int pc)
{
    assert(pc >= 0 && pc < b->ncode);
    if (b->index[pc] < 0) {
        if (b->nentries == b->cap) {
            b->cap = b->cap ? 2 * b->cap : 16;
            b->entries = xreallocarray(b->entries, (size_t)b->cap, sizeof *b->entries);
        }
        b->index[pc] = b->nentries++;
    }
    return &b->entries[b->index[pc]];
}

void vm_uniform_free(sl_vm *vm)
{
    for (int i = 0; i < VM_UNIFORM_BLOCKS; i++) {
        free(vm->uniform[i].misses);
        free(vm->uniform[i].index);
        free(vm->uniform[i].arity);
        free(vm->uniform[i].entries);
    }
}

void sl_vm_set_uniform_memo(sl_vm *vm, bool on) { vm->uniform_off = !on; }
long sl_vm_uniform_hits(const sl_vm *vm) { return vm->uniform_hits; }


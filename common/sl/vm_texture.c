/*
 * vm_texture.c: what the VM's texture operations (TEXTURE, TEXINFO;
 * bytecode.h) share across the four arithmetics: the texture cache a VM
 * reads (sl_vm_set_textures), the name -> texture memo that keeps the
 * cache's lock off the hot path, and the texture names a bound instance
 * will look up (sl_instance_texture_names), so that whoever builds the
 * world opens them before rendering (docs/textures.md).
 */
#include "sl/vm_internal.h"
#include "util/err.h"

#include <stdio.h>
#include <string.h>

void sl_vm_set_textures(sl_vm *self, struct tex_cache *textures)
{
    self->textures = textures;
    self->ntex_memo = 0;
}

const tex_texture *sl_vm_texture_find(sl_vm *vm, const char *name, char *err, size_t errsz)
{
    for (int k = 0; k < vm->ntex_memo; k++) {
        if (strcmp(vm->tex_memo[k].name, name) != 0)
            continue;
        if (vm->tex_memo[k].tex || !err)
            return vm->tex_memo[k].tex;  /* NULL: known missing (textureinfo) */
        break;
    }
    char quiet[ERR_LEN];
    bool remember_missing = err == NULL;
    if (!err) {
        err = quiet;
        errsz = sizeof quiet;
    }
    err_set(err, errsz, "no texture cache: the renderer installed none");
    const tex_texture *t = vm->textures ? tex_cache_get(vm->textures, name, err, errsz) : NULL;
    if (strlen(name) < sizeof vm->tex_memo[0].name && (t || remember_missing)) {
        int k = vm->ntex_memo < SL_VM_TEX_MEMO ? vm->ntex_memo++ : (int)(vm->rng % SL_VM_TEX_MEMO);
        snprintf(vm->tex_memo[k].name, sizeof vm->tex_memo[k].name, "%s", name);
        vm->tex_memo[k].tex = t;
    }
    return t;
}

const tex_texture *sl_vm_texture(sl_vm *vm, const char *name, int pc, sl_status *st)
{
    if (!name || strchr(name, '\x01')) {
        char where[256];
        sl_program_pos_string(vm->prog, pc, where, sizeof where);
        *st = sl_vm_fail(vm, SL_ERR_RUNTIME, "the texture name at %s varies over the surface "
                         "(%s mode); texture names must be known where a lookup runs", where,
                         sl_mode_name(vm->mode));
        return NULL;
    }
    char err[600];
    const tex_texture *t = sl_vm_texture_find(vm, name, err, sizeof err);
    if (!t) {
        char where[256];
        sl_program_pos_string(vm->prog, pc, where, sizeof where);
        *st = sl_vm_fail(vm, SL_ERR_RUNTIME, "texture lookup at %s: %s", where, err);
    }
    return t;
}

sl_status sl_vm_texture_channel_error(sl_vm *vm, int pc)
{
    char where[256];
    sl_program_pos_string(vm->prog, pc, where, sizeof where);
    return sl_vm_fail(vm, SL_ERR_RUNTIME, "the texture channel at %s varies over the surface "
                      "(%s mode); channels must be the same for the whole surface", where,
                      sl_mode_name(vm->mode));
}

/* The string a string slot holds when the program starts at an
 * instruction that reads it: a constant, or a parameter's value. */
static const char *known_string(const sl_instance *inst, int slot)
{
    const sl_program *p = inst->program;
    for (int k = 0; k < p->nstrings; k++)
        if (p->string_slots[k] == slot)
            return p->strings[k];
    for (int i = 0; i < p->nparams; i++) {
        if (p->params[i].type != SL_TYPE_STRING || p->params[i].slot != slot)
            continue;
        if (inst->values[i].set)
            return inst->values[i].s;
        for (int pc = 0; pc < p->ncode; pc++)
            if (p->code[pc].op == SL_OP_SPARAM && p->code[pc].b == i && p->code[pc].d)
                return known_string(inst, p->code[pc].d);
    }
    return NULL;
}

int sl_instance_texture_names(const sl_instance *inst, const char **names, int max)
{
    const sl_program *p = inst->program;
    int n = 0;
    for (int pc = 0; pc < p->ncode; pc++) {
        int op = p->code[pc].op;
        if (op != SL_OP_TEXTURE && op != SL_OP_TEXINFO)
            continue;
        const char *name = known_string(inst, p->code[pc].b);
        if (!name || !name[0])
            continue;
        bool seen = false;
        for (int k = 0; k < n && !seen; k++)
            seen = strcmp(names[k], name) == 0;
        if (!seen && n < max)
            names[n++] = name;
    }
    return n;
}

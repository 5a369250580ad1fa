/*
 * shader.c: compiling (sl_compile: lexer -> parser -> checker -> code
 * generator), the program's accessors, and instances (parameter values of
 * one RIB Surface/Displacement call) -- the front half of shader.h; the VM
 * is in vm.c.
 */
#include "sl/ast.h"
#include "sl/check.h"
#include "sl/codegen.h"
#include "sl/lexer.h"
#include "sl/parser.h"
#include "util/xalloc.h"
#include "sl/vm_internal.h"
#include "util/err.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

sl_program *sl_compile(sl_source_set *set, const char *main_file,
                       const char *const *search_path, const atomic_int *cancel,
                       sl_diag *diag)
{
    int errors = sl_diag_error_count(diag);
    sl_lexer *lx = sl_lexer_new(set, main_file, search_path, diag);
    sl_arena *arena = sl_arena_new();
    sl_ast_file *file = sl_parse(lx, arena, cancel, diag);
    sl_program *program = NULL;
    if (sl_diag_error_count(diag) == errors && sl_check(file, arena, cancel, diag))
        program = sl_codegen(file, diag);
    sl_arena_destroy(&arena);
    sl_lexer_destroy(&lx);
    if (sl_diag_error_count(diag) != errors) {
        sl_program_destroy(&program);
        return NULL;
    }
    if (program) {
        program->takes_derivatives = sl_program_derivatives_reach_P(program);
        program->has_outputs = false;
        for (int i = 0; i < program->nparams; i++)
            program->has_outputs = program->has_outputs || program->params[i].output;
        program->global_slots = sl_program_global_slots(program);
        program->box_plan = sl_program_box_plan(program, false, &program->box_values,
                                                &program->box_derivs);
        program->slope_plan = sl_program_box_plan(program, true, NULL, NULL);
        program->split_same = sl_program_split_same(program);
        sl_program_choose_tape_sites(program);
    }
    return program;
}

const char *sl_program_name(const sl_program *self) { return self->name; }
sl_shader_kind sl_program_kind(const sl_program *self) { return self->kind; }
int sl_program_param_count(const sl_program *self) { return self->nparams; }
bool sl_program_has_outputs(const sl_program *self) { return self->has_outputs; }
bool sl_program_takes_derivatives(const sl_program *self) { return self->takes_derivatives; }

bool sl_program_box_reads(const sl_program *self, sl_global g, bool derivs)
{
    uint64_t set = derivs ? self->box_derivs : self->box_values;
    int s = sl_global_slot(g), n = sl_global_size(g);
    for (int k = 0; k < n; k++)
        if (s + k >= 64 || (set >> (s + k)) & 1)
            return true;
    return false;
}

void sl_program_param(const sl_program *self, int index, sl_param_info *info)
{
    if (index < 0 || index >= self->nparams) {
        memset(info, 0, sizeof *info);
        return;
    }
    info->name = self->params[index].name;
    info->type = self->params[index].type;
    info->output = self->params[index].output;
}

int sl_program_find_param(const sl_program *self, const char *name)
{
    for (int i = 0; i < self->nparams; i++)
        if (strcmp(self->params[i].name, name) == 0)
            return i;
    return -1;
}

/* ---------------------------------------------------------------------- */
/* instances                                                               */
/* ---------------------------------------------------------------------- */

sl_instance *sl_instance_new(const sl_program *program)
{
    sl_instance *self = xmalloc(sizeof *self);
    self->program = program;
    size_t n = (size_t)program->nparams + 1;
    self->values = xmalloc(n * sizeof *self->values);
    memset(self->values, 0, n * sizeof *self->values);
    return self;
}

void sl_instance_destroy(sl_instance **self_p)
{
    sl_instance *self = *self_p;
    if (!self)
        return;
    for (int i = 0; i < self->program->nparams; i++)
        free(self->values[i].s);
    free(self->values);
    free(self);
    *self_p = NULL;
}

const sl_program *sl_instance_program(const sl_instance *self) { return self->program; }

static bool types_match(sl_type param, sl_type given)
{
    if (param == given)
        return true;
    bool ps = param == SL_TYPE_POINT || param == SL_TYPE_VECTOR || param == SL_TYPE_NORMAL;
    bool gs = given == SL_TYPE_POINT || given == SL_TYPE_VECTOR || given == SL_TYPE_NORMAL;
    return ps && gs;
}

bool sl_instance_set(sl_instance *self, const char *name, sl_type type,
                     const double *values, int count, char *err, size_t errsz)
{
    const sl_program *p = self->program;
    int i = sl_program_find_param(p, name);
    if (i < 0)
        return err_set(err, errsz, "shader '%s' has no parameter '%s'", p->name, name);
    const sl_param *pp = &p->params[i];
    if (pp->type == SL_TYPE_STRING)
        return err_set(err, errsz, "parameter '%s' of shader '%s' is a string", name,
                        p->name);
    if (!types_match(pp->type, type))
        return err_set(err, errsz, "parameter '%s' of shader '%s' is a %s, not a %s",
                        name, p->name, sl_ty_name(pp->type), sl_ty_name(type));
    if (pp->size > 16)       /* the instance holds 16 values per parameter */
        return err_set(err, errsz, "parameter '%s' of shader '%s' is an array of more "
                        "than 16 values, which cannot be set from the scene yet", name,
                        p->name);
    if (count != pp->size)
        return err_set(err, errsz, "parameter '%s' of shader '%s' takes %d value%s, "
                        "got %d", name, p->name, pp->size, pp->size == 1 ? "" : "s", count);
    for (int k = 0; k < count; k++)
        if (!isfinite(values[k]))
            return err_set(err, errsz, "parameter '%s' of shader '%s': value %d is not "
                            "a finite number", name, p->name, k + 1);
    memcpy(self->values[i].v, values, (size_t)count * sizeof *values);
    self->values[i].set = true;
    return true;
}

bool sl_instance_set_string(sl_instance *self, const char *name, const char *value,
                            char *err, size_t errsz)
{
    const sl_program *p = self->program;
    int i = sl_program_find_param(p, name);
    if (i < 0)
        return err_set(err, errsz, "shader '%s' has no parameter '%s'", p->name, name);
    if (p->params[i].type != SL_TYPE_STRING)
        return err_set(err, errsz, "parameter '%s' of shader '%s' is a %s, not a string",
                        name, p->name, sl_ty_name(p->params[i].type));
    free(self->values[i].s);
    self->values[i].s = xstrndup(value, strlen(value));
    self->values[i].set = true;
    return true;
}

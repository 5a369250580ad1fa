/*
 * class.c: lowering an RSL 2 shader class to an ordinary shader (see
 * class.h): the member variables become the body's first declarations, the
 * methods nested functions that reach the members and the class's
 * parameters through generated 'extern' declarations (RI Spec 3.2 §14.2's
 * scoping, which nested functions already follow), ordered so that every
 * method is defined before the methods that call it, and the public shader
 * method's body comes last, after construct() and begin().
 */
#include "sl/class.h"

#include "sl/builtins.h"

#include <string.h>

static const char *const shader_methods[] = { "surface", "displacement", "light" };

static int shader_method_kind(const char *name)
{
    static const sl_shader_kind kinds[] = { SL_SHADER_SURFACE, SL_SHADER_DISPLACEMENT,
                                            SL_SHADER_LIGHT };
    for (int k = 0; k < 3; k++)
        if (strcmp(name, shader_methods[k]) == 0)
            return (int)kinds[k];
    return -1;
}

/* Does the tree under n call a function called `name`? */
static bool calls(const sl_node *n, const char *name)
{
    for (; n; n = n->a) {       /* a loop along a: chains of operators (ast.h) */
        if (n->kind == SL_N_CALL && n->name && strcmp(n->name, name) == 0)
            return true;
        if (n->kind == SL_N_FUNC && n->func && calls(n->func->body, name))
            return true;
        if (calls(n->b, name) || calls(n->c, name) || calls(n->d, name))
            return true;
        for (int i = 0; i < n->nlist; i++)
            if (calls(n->list[i], name))
                return true;
    }
    return false;
}

typedef struct lowering {
    sl_arena *arena;
    const sl_class *cls;
    const sl_ast_file *file;
    int *state;                 /* per method: 0 new, 1 on the path, 2 placed */
    sl_func **order;
    int norder;
} lowering;

/* Depth first: the methods m calls are placed before m (a cycle is left to
 * the checker's recursion error). */
static void place(lowering *lw, int m)
{
    if (lw->state[m])
        return;
    lw->state[m] = 1;
    const sl_func *f = lw->cls->methods[m];
    for (int j = 0; j < lw->cls->nmethods; j++)
        if (j != m && calls(f->body, lw->cls->methods[j]->name))
            place(lw, j);
    lw->state[m] = 2;
    lw->order[lw->norder++] = lw->cls->methods[m];
}

static bool is_param_of(const sl_func *f, const char *name)
{
    for (int i = 0; i < f->nparams; i++)
        if (strcmp(f->params[i]->name, name) == 0)
            return true;
    return false;
}

static void push(sl_arena *arena, sl_node *block, int *cap, sl_node *item)
{
    sl_list_push(arena, (void ***)&block->list, &block->nlist, cap, item);
}

/* 'extern <type> name;' for a method, at its position */
static void add_extern(lowering *lw, sl_node *decl, int *cap, const sl_sym *of, sl_pos pos)
{
    sl_node *v = sl_node_new(lw->arena, SL_N_VAR, pos);
    sl_sym *s = sl_arena_alloc(lw->arena, sizeof *s);
    s->name = of->name;
    s->pos = pos;
    s->ty = of->ty;
    s->kind = SL_SYM_LOCAL;
    s->writable = true;
    s->slot = -1;
    v->sym = s;
    v->name = of->name;
    v->num = 1;                              /* extern */
    push(lw->arena, decl, cap, v);
}

/* The method's body inside a block that first declares the members and the
 * class's parameters 'extern' (those its own parameters do not hide). */
static void wrap_method(lowering *lw, sl_func *f)
{
    sl_node *decl = sl_node_new(lw->arena, SL_N_DECL, f->pos);
    int dcap = 0;
    for (int i = 0; i < lw->file->nparams; i++) {
        const sl_sym *s = lw->file->params[i]->sym;
        if (!is_param_of(f, s->name))
            add_extern(lw, decl, &dcap, s, f->pos);
    }
    for (int m = 0; m < lw->cls->nmembers; m++) {
        const sl_node *d = lw->cls->members[m];
        for (int i = 0; i < d->nlist; i++)
            if (!is_param_of(f, d->list[i]->sym->name))
                add_extern(lw, decl, &dcap, d->list[i]->sym, f->pos);
    }
    sl_node *body = sl_node_new(lw->arena, SL_N_BLOCK, f->body->pos);
    int bcap = 0;
    if (decl->nlist)
        push(lw->arena, body, &bcap, decl);
    push(lw->arena, body, &bcap, f->body);
    f->body = body;
}

static sl_node *call_stmt(sl_arena *arena, const sl_func *f)
{
    sl_node *call = sl_node_new(arena, SL_N_CALL, f->pos);
    call->name = f->name;
    sl_node *s = sl_node_new(arena, SL_N_EXPR, f->pos);
    s->a = call;
    return s;
}

bool sl_class_lower(sl_arena *arena, sl_diag *diag, sl_ast_file *file, const sl_class *cls)
{
    file->has_shader = true;
    file->name = cls->name;
    file->pos = cls->pos;
    file->kind = SL_SHADER_SURFACE;
    const sl_func *shader = NULL;
    for (int m = 0; m < cls->nmethods; m++) {
        const sl_func *f = cls->methods[m];
        int kind = shader_method_kind(f->name);
        if (kind < 0)
            continue;
        if (shader) {
            sl_diag_error(diag, f->pos, "class '%s' has both a '%s' and a '%s' method; aafarm "
                          "compiles a class as one shader: split it into two classes",
                          cls->name, shader->name, f->name);
            sl_diag_note(diag, shader->pos, "'%s' defined here", shader->name);
            return false;
        }
        shader = f;
        file->kind = (sl_shader_kind)kind;
        for (int i = 0; i < f->nparams; i++) {
            const sl_sym *s = f->params[i];
            if (sl_global_find(s->name) < 0) {
                sl_diag_error(diag, s->pos, "the '%s' method of class '%s' takes the predefined "
                              "variables it sets (as 'output point P; output normal N'), not "
                              "'%s'", f->name, cls->name, s->name);
                return false;
            }
        }
    }
    if (!shader) {
        sl_diag_error(diag, cls->pos, "class '%s' has no public 'surface', 'displacement' or "
                      "'light' method, so it is no shader aafarm can run (co-shaders are "
                      "not supported)", cls->name);
        return false;
    }
    lowering lw = { .arena = arena, .cls = cls, .file = file };
    lw.state = sl_arena_alloc(arena, (size_t)(cls->nmethods + 1) * sizeof *lw.state);
    lw.order = sl_arena_alloc(arena, (size_t)(cls->nmethods + 1) * sizeof *lw.order);
    for (int m = 0; m < cls->nmethods; m++)
        if (cls->methods[m] != shader)
            place(&lw, m);

    sl_node *body = sl_node_new(arena, SL_N_BLOCK, cls->pos);
    int cap = 0;
    for (int m = 0; m < cls->nmembers; m++)
        push(arena, body, &cap, cls->members[m]);
    const sl_func *construct = NULL, *begin = NULL;
    for (int k = 0; k < lw.norder; k++) {
        sl_func *f = lw.order[k];
        wrap_method(&lw, f);
        f->nested = true;
        sl_node *def = sl_node_new(arena, SL_N_FUNC, f->pos);
        def->func = f;
        push(arena, body, &cap, def);
        if (strcmp(f->name, "construct") == 0 && f->nparams == 0)
            construct = f;
        if (strcmp(f->name, "begin") == 0 && f->nparams == 0)
            begin = f;
    }
    if (construct)
        push(arena, body, &cap, call_stmt(arena, construct));
    if (begin)
        push(arena, body, &cap, call_stmt(arena, begin));
    push(arena, body, &cap, shader->body);
    file->body = body;
    return true;
}

/*
 * check_call.c: the checking of calls (see check.h; the checker's state
 * and helpers are in check_internal.h). A call resolves among the user
 * functions in scope (resolve_user: exact, then by conversion cost, then
 * by return type) and then the built-ins (builtins.h); the built-ins with
 * rules of their own are checked here too: space and colour-space names,
 * filterstep's and shadow's parameters, arraylength and the resizable
 * array operations, spline, the string functions with their format
 * strings, and texture lookups with their parameter lists.
 */
#include "sl/check_internal.h"
#include "sl/builtins.h"
#include "sl/format.h"
#include "sl/lexer.h"
#include "sl/strmatch.h"
#include "tex/tex.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A constant string argument naming a space: known? */
static void check_space_arg(checker *c, const sl_node *arg)
{
    if (arg->kind == SL_N_STR && sl_space_find(arg->name) < 0)
        ck_error(c, arg->pos, "unknown space '%s' (known: " SL_SPACE_NAMES ")", arg->name);
}

/* filterstep's optional parameters: "width", a float (the filter width's
 * multiplier), and "filter", a constant filter name (the box filter is
 * used whatever the name). Called for each string argument i. */
static void check_filter_param(checker *c, const sl_node *n, int i)
{
    static const char *const filters[] = { "box", "triangle", "catmull-rom", "gaussian",
                                           "sinc", "disk", "bessel" };
    const sl_node *arg = n->list[i];
    bool value = i > 0 && n->list[i - 1]->ty == SL_TYPE_STRING &&
                 n->list[i - 1]->kind == SL_N_STR && strcmp(n->list[i - 1]->name, "filter") == 0;
    if (arg->kind != SL_N_STR) {
        ck_error(c, arg->pos, "filterstep() parameters must be constant strings");
        return;
    }
    if (value) {
        for (size_t k = 0; k < sizeof filters / sizeof filters[0]; k++)
            if (strcmp(arg->name, filters[k]) == 0)
                return;
        ck_error(c, arg->pos, "unknown filter '%s' (known: \"box\", \"triangle\", "
              "\"catmull-rom\", \"gaussian\", \"sinc\", \"disk\", \"bessel\")", arg->name);
        return;
    }
    bool takes_string = i + 1 < n->nlist && n->list[i + 1]->ty == SL_TYPE_STRING;
    if (strcmp(arg->name, takes_string ? "filter" : "width") != 0)
        ck_error(c, arg->pos, "unknown filterstep() parameter '%s' (known: \"width\" with a "
              "float, \"filter\" with a name)", arg->name);
}

/* The optional "name", value parameters of texture(), environment(),
 * bump() and shadow() (RI Spec 3.2 §15.7, and the ones shader libraries
 * pass to PRMan): type 'f' a float, 's' a constant string, 'w' a wrap
 * mode. Which ones each lookup uses: check_texture, cg_gen_texture. */
static const struct { const char *name; char type; } optional_params[] = {
    { "blur", 'f' }, { "sblur", 'f' }, { "tblur", 'f' }, { "width", 'f' },
    { "swidth", 'f' }, { "twidth", 'f' }, { "fill", 'f' }, { "samples", 'f' },
    { "filter", 's' }, { "wrap", 'w' }, { "swrap", 'w' }, { "twrap", 'w' },
    { "lerp", 'f' }, { "bias", 'f' },
};
enum { NOPTIONAL = sizeof optional_params / sizeof optional_params[0] };
#define TEXTURE_PARAM_NAMES "\"blur\", \"sblur\", \"tblur\", \"width\", \"swidth\", " \
    "\"twidth\", \"fill\", \"samples\", \"filter\", \"wrap\", \"swrap\", \"twrap\", \"lerp\""
#define SHADOW_PARAM_NAMES "\"samples\", \"blur\", \"sblur\", \"tblur\", \"bias\", " \
    "\"width\", \"swidth\", \"twidth\", \"filter\", \"fill\""

/* The index of name in optional_params when it is in the list `allowed`
 * (quoted names), or -1. */
static int optional_find(const char *name, const char *allowed)
{
    char quoted[16];
    for (int k = 0; k < NOPTIONAL; k++) {
        if (strcmp(optional_params[k].name, name) != 0)
            continue;
        snprintf(quoted, sizeof quoted, "\"%s\"", name);
        return strstr(allowed, quoted) ? k : -1;
    }
    return -1;
}

/* An accepted parameter that this lookup has no use for: one warning per
 * name and function in a shader (fn: SL_TEX_* or SL_TEX_INFO for shadow). */
static void warn_ignored(checker *c, const sl_node *pn, const char *fn_name, int fn, int k,
                         const char *why)
{
    _Static_assert(NOPTIONAL * (SL_TEX_INFO + 1) <= 64, "one bit per name and function");
    uint64_t bit = (uint64_t)1 << (fn * NOPTIONAL + k);
    if (c->ignored_warned & bit)
        return;
    c->ignored_warned |= bit;
    sl_diag_warning(c->diag, pn->pos, "%s() parameter '%s' is accepted and ignored: %s (said "
                    "once per shader)", fn_name, pn->name, why);
}

/* One "name", value parameter at list[i] of a texture lookup or shadow()
 * (allowed: its known names): false when reported. *k: its index. */
static bool check_optional(checker *c, sl_node *n, int i, const char *allowed,
                           const char *known, int *k)
{
    sl_node *pn = n->list[i];
    ck_check_expr(c, &n->list[i], SL_TYPE_STRING);
    *k = pn->kind == SL_N_STR ? optional_find(pn->name, allowed) : -1;
    if (*k < 0) {
        ck_error(c, pn->pos, "unknown %s() parameter%s%s%s (known: %s)", n->name,
              pn->kind == SL_N_STR ? " '" : "", pn->kind == SL_N_STR ? pn->name : "",
              pn->kind == SL_N_STR ? "'" : "", known);
        return false;
    }
    if (i + 1 >= n->nlist) {
        ck_error(c, pn->pos, "%s() parameter '%s' has no value", n->name, pn->name);
        return false;
    }
    char type = optional_params[*k].type;
    sl_ty have = ck_check_expr(c, &n->list[i + 1], type == 'f' ? SL_TYPE_FLOAT
                                                               : SL_TYPE_STRING);
    sl_node *v = n->list[i + 1];
    if (have == SL_TY_ERROR)
        return false;
    if (type == 'f' && have != SL_TYPE_FLOAT)
        ck_error(c, v->pos, "%s() parameter '%s' takes a float, not '%s'", n->name, pn->name,
              sl_ty_name(have));
    else if (type != 'f' && v->kind != SL_N_STR)
        ck_error(c, v->pos, "%s() parameter '%s' takes a constant string", n->name, pn->name);
    else if (type == 'w' && tex_wrap_find(v->name) < 0)
        ck_error(c, v->pos, "unknown wrap mode '%s' (known: \"periodic\", \"clamp\", "
                         "\"black\")", v->name);
    else
        return true;
    return false;
}

/* shadow(name, P, "blur", 0.01, ...): the shadow map parameters, accepted
 * with a warning (the traced shadow ray is sharp and has no map); the call
 * keeps its first two arguments. False when reported. */
static bool check_shadow_params(checker *c, sl_node *n)
{
    bool ok = true;
    for (int i = 2; i < n->nlist; i += 2) {
        int k;
        if (!check_optional(c, n, i, SHADOW_PARAM_NAMES, SHADOW_PARAM_NAMES, &k)) {
            ok = false;
            continue;
        }
        warn_ignored(c, n->list[i], "shadow", SL_TEX_INFO, k, "shadows are traced rays, "
                     "sharp, with no map to filter or bias");
    }
    n->nlist = 2;
    return ok;
}

/* A color space argument (ctransform): a constant string naming one. */
static void check_color_space_arg(checker *c, const sl_node *arg)
{
    if (arg->kind != SL_N_STR)
        ck_error(c, arg->pos, "the color space of ctransform() must be a constant string");
    else if (sl_color_space_find(arg->name) < 0)
        ck_error(c, arg->pos, "unknown color space '%s' (known: " SL_COLOR_SPACE_NAMES ")",
              arg->name);
}

static sl_ty check_builtin_call(checker *c, sl_node *n, const sl_ty *args, sl_ty hint)
{
    sl_ty want[SL_MAX_BUILTIN_ARGS], result;
    const sl_builtin *b = sl_builtin_resolve(n->name, args, n->nlist, hint, want, &result);
    if (!b) {
        char list[256] = "";
        for (int i = 0; i < n->nlist; i++) {
            size_t len = strlen(list);
            snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "",
                     sl_ty_name(args[i]));
        }
        ck_error(c, n->pos, "no matching function for call to '%s' with arguments (%s)",
              n->name, list);
        char cands[512];
        sl_builtin_candidates(n->name, cands, sizeof cands);
        sl_diag_note(c->diag, n->pos, "candidates are: %s", cands);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    n->builtin = b;
    if (b->lower == SL_LOWER_EMITTER && c->file->kind != SL_SHADER_LIGHT) {
        ck_error(c, n->pos, "'%s' is only allowed in light shaders", b->op == SL_OP_END &&
              b->k == 0 ? "illuminate" : "solar");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    const char *sig = b->sig + 2;
    for (int i = 0; i < n->nlist; i++) {
        if (sig[i] == 'o' || sig[i] == 'O' || sig[i] == 'M' || sig[i] == 'w' ||
            sig[i] == 'V') {
            sl_node *a = n->list[i];
            if (a->kind != SL_N_IDENT)
                ck_error(c, a->pos, "argument %d of '%s' must be a variable", i + 1, n->name);
            else
                ck_check_assignable(c, a, "modify");
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_FILTERSTEP) {
            check_filter_param(c, n, i);
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_MATCH) {
            int bad = i == 0 && n->list[0]->kind == SL_N_STR ? sl_match_check(n->list[0]->name)
                                                             : 0;
            if (bad)
                ck_error(c, n->list[0]->pos, "malformed regular expression '%s' (at character "
                      "%d)", n->list[0]->name, bad);
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_MESSAGE) {
            ck_wrap_conv(c, &n->list[i], want[i]);
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_RAY) {      /* shadow()'s map name */
            ck_wrap_conv(c, &n->list[i], want[i]);
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_CTRANSFORM)
            check_color_space_arg(c, n->list[i]);
        else if (sig[i] == 's')
            check_space_arg(c, n->list[i]);
        ck_wrap_conv(c, &n->list[i], want[i]);
    }
    return ck_set_ty(n, result);
}

static void add_call_edge(checker *c, sl_func *callee)
{
    if (!c->func)
        return;
    for (int i = 0; i < c->func->ncalls; i++)
        if (c->func->calls[i] == callee)
            return;
    sl_list_push(c->arena, (void ***)&c->func->calls, &c->func->ncalls,
                 &c->func->calls_cap, callee);
}

/* An array argument for an array parameter: the same element type and
 * length; an unsized parameter takes any length (an unsized argument is
 * checked when the call is inlined, where its length is known). */
static bool array_arg_ok(sl_ty param, sl_ty arg)
{
    if (!sl_ty_is_array(param) || !sl_ty_is_array(arg) ||
        sl_ty_elem(param) != sl_ty_elem(arg))
        return false;
    return sl_ty_len(param) == 0 || sl_ty_len(arg) == 0 || sl_ty_len(param) == sl_ty_len(arg);
}

/* A nested overload group (check.c, check_nested_function) still being
 * defined, called from outside it: the later definitions may read
 * variables not declared yet at this call. The first undefined one, or
 * NULL. */
static sl_func *undefined_overload(checker *c, const sl_func *f)
{
    if (!f->nested || (c->func && c->func->nested && c->func->depth == f->depth &&
                       strcmp(c->func->name, f->name) == 0))
        return NULL;
    for (int i = 0; i < c->nvfuncs; i++) {
        sl_func *g = c->vfuncs[i];
        if (g->depth == f->depth && !g->defined && strcmp(g->name, f->name) == 0)
            return g;
    }
    return NULL;
}

static sl_ty check_user_call(checker *c, sl_node *n, sl_func *f, const sl_ty *args)
{
    n->func = f;
    add_call_edge(c, f);
    sl_func *later = undefined_overload(c, f);
    if (later) {
        ck_error(c, n->pos, "'%s' is called before all its overloads in this block are "
              "defined: move the call after the definition at line %d", f->name,
              later->pos.line);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    if (n->nlist != f->nparams) {
        ck_error(c, n->pos, "function '%s' takes %d argument%s, but %d %s given", f->name,
              f->nparams, f->nparams == 1 ? "" : "s", n->nlist, n->nlist == 1 ? "was" : "were");
        sl_diag_note(c->diag, f->pos, "'%s' declared here", f->name);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    bool ok = true;
    for (int i = 0; i < n->nlist; i++) {
        sl_sym *p = f->params[i];
        if (args[i] == SL_TY_ERROR) {
            ok = false;
            continue;
        }
        if (sl_ty_is_array(p->ty) || sl_ty_is_array(args[i])) {
            if (!array_arg_ok(p->ty, args[i])) {
                ck_error(c, n->list[i]->pos, "argument %d of '%s': cannot pass a '%s' to a "
                                          "parameter of type '%s'", i + 1, f->name,
                      sl_ty_name(args[i]), sl_ty_name(p->ty));
                ok = false;
            } else if (p->output) {
                ck_check_assignable(c, n->list[i], "modify");
            }
            continue;
        }
        if (p->output) {
            sl_node *a = n->list[i];
            if (a->kind != SL_N_IDENT) {
                ck_error(c, a->pos, "argument %d of '%s' must be a variable (the parameter "
                                 "is 'output')", i + 1, f->name);
                ok = false;
            } else if (!(args[i] == p->ty ||
                         (sl_ty_is_spatial(args[i]) && sl_ty_is_spatial(p->ty)))) {
                ck_error(c, a->pos, "argument %d of '%s': cannot pass a '%s' variable to an "
                                 "output parameter of type '%s'", i + 1, f->name,
                      sl_ty_name(args[i]), sl_ty_name(p->ty));
                ok = false;
            } else {
                ck_check_assignable(c, a, "modify");
            }
            continue;
        }
        if (!ck_can_convert(args[i], p->ty)) {
            ck_error(c, n->list[i]->pos, "argument %d of '%s': cannot convert '%s' to '%s'",
                  i + 1, f->name, sl_ty_name(args[i]), sl_ty_name(p->ty));
            ok = false;
            continue;
        }
        ck_wrap_conv(c, &n->list[i], p->ty);
    }
    return ck_set_ty(n, ok ? f->ret : SL_TY_ERROR);
}

/* Cost of passing an argument of type `have` to parameter p; -1: not
 * viable. As for the built-ins (builtins.c): exact 0, point/vector/normal
 * as another of the three 1, a float promoted 2; an 'output' parameter
 * takes a variable of its own type (or another spatial type, cost 1). */
static int param_cost(const sl_sym *p, sl_ty have)
{
    if (sl_ty_is_array(p->ty) || sl_ty_is_array(have))
        return array_arg_ok(p->ty, have) ? 0 : -1;
    if (have == p->ty)
        return 0;
    if (sl_ty_is_list(have))
        return !p->output && ck_can_convert(have, p->ty) ? 0 : -1;
    if (sl_ty_is_spatial(have) && sl_ty_is_spatial(p->ty))
        return 1;
    if (p->output)
        return -1;
    if (have == SL_TYPE_FLOAT && (sl_ty_is_triple(p->ty) || p->ty == SL_TYPE_MATRIX))
        return 2;
    return -1;
}

/* Keeps the candidates for which keep() holds, when any does. */
static int narrow(sl_func **f, int n, bool (*keep)(const sl_func *, sl_ty), sl_ty hint)
{
    int k = 0;
    for (int i = 0; i < n; i++)
        if (keep(f[i], hint))
            f[k++] = f[i];
    return k ? k : n;
}
static bool returns_exactly(const sl_func *f, sl_ty hint) { return f->ret == hint; }
static bool returns_convertible(const sl_func *f, sl_ty hint)
{
    return ck_can_convert(f->ret, hint) && f->ret != SL_TYPE_VOID;
}

/* Overload resolution among user functions (see docs/shading-language.md):
 * the viable candidate of least total conversion cost; of equally cheap
 * ones, those returning the type the context asks for (hint), then those
 * returning a type convertible to it, then the innermost definitions. A
 * tie left after that is an error. NULL: none viable (not reported) or
 * ambiguous (reported, *ambiguous set). */
static sl_func *resolve_user(checker *c, sl_node *n, sl_func **cands, int ncands,
                             const sl_ty *args, sl_ty hint, bool *ambiguous)
{
    sl_func *best[MAX_OVERLOADS];
    int nbest = 0, best_cost = 0;
    *ambiguous = false;
    for (int k = 0; k < ncands; k++) {
        sl_func *f = cands[k];
        if (f->nparams != n->nlist)
            continue;
        int cost = 0;
        for (int i = 0; i < n->nlist && cost >= 0; i++) {
            int ci = param_cost(f->params[i], args[i]);
            cost = ci < 0 ? -1 : cost + ci;
        }
        if (cost < 0 || (nbest > 0 && cost > best_cost))
            continue;
        if (nbest == 0 || cost < best_cost)
            nbest = 0;
        best_cost = cost;
        best[nbest++] = f;
    }
    if (nbest > 1 && hint != SL_TYPE_VOID && hint != SL_TY_ERROR) {
        nbest = narrow(best, nbest, returns_exactly, hint);
        nbest = narrow(best, nbest, returns_convertible, hint);
    }
    if (nbest > 1) {
        int deepest = 0, k = 0;
        for (int i = 0; i < nbest; i++)
            deepest = best[i]->depth > deepest ? best[i]->depth : deepest;
        for (int i = 0; i < nbest; i++)
            if (best[i]->depth == deepest)
                best[k++] = best[i];
        nbest = k;
    }
    if (nbest == 1)
        return best[0];
    if (nbest > 1) {
        *ambiguous = true;
        ck_error(c, n->pos, "call to '%s' is ambiguous", n->name);
        for (int i = 0; i < nbest; i++) {
            char sig[256];
            ck_func_signature(best[i], sig, sizeof sig);
            sl_diag_note(c->diag, best[i]->pos, "candidate: %s", sig);
        }
    }
    return NULL;
}

static void no_match(checker *c, sl_node *n, const sl_ty *args, sl_func **cands, int ncands,
                     bool builtin)
{
    char list[256] = "";
    for (int i = 0; i < n->nlist; i++) {
        size_t len = strlen(list);
        snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", sl_ty_name(args[i]));
    }
    ck_error(c, n->pos, "no matching function for call to '%s' with arguments (%s)", n->name,
          list);
    for (int i = 0; i < ncands; i++) {
        char sig[256];
        ck_func_signature(cands[i], sig, sizeof sig);
        sl_diag_note(c->diag, cands[i]->pos, "candidate: %s", sig);
    }
    if (builtin) {
        char names[512];
        sl_builtin_candidates(n->name, names, sizeof names);
        sl_diag_note(c->diag, n->pos, "built-in candidates are: %s", names);
    }
}

/* arraylength(a): the number of elements of an array (a constant where
 * the array's length is; an unsized parameter's is known per call). */
static sl_ty check_arraylength(checker *c, sl_node *n)
{
    for (int i = 0; i < n->nlist; i++)
        ck_check_expr(c, &n->list[i], SL_TYPE_VOID);
    if (n->nlist != 1 || !sl_ty_is_array(n->list[0]->ty) ||
        n->list[0]->kind != SL_N_IDENT) {
        if (n->nlist != 1 || n->list[0]->ty != SL_TY_ERROR)
            ck_error(c, n->pos, "arraylength() takes one array variable");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    return ck_set_ty(n, SL_TYPE_FLOAT);
}

/* RSL 2 resizable arrays: resize(a, n), reserve(a, n), push(a, v), pop(a)
 * on a local declared 'float a[];' or an unsized array parameter (whose
 * argument must then be resizable: checked where the call is inlined).
 * The node's op: SL_RESIZE_*. */
static const char *const resizable_ops[] = { "resize", "reserve", "push", "pop" };

static int resizable_op(const char *name)
{
    for (int k = 0; k < 4; k++)
        if (strcmp(name, resizable_ops[k]) == 0)
            return k;
    return -1;
}

static sl_ty check_resizable(checker *c, sl_node *n, int op)
{
    int want = op == SL_RESIZE_POP ? 1 : 2;
    for (int i = 0; i < n->nlist; i++)
        ck_check_expr(c, &n->list[i], i == 0 ? SL_TYPE_VOID : SL_TYPE_FLOAT);
    const sl_node *a = n->nlist > 0 ? n->list[0] : NULL;
    bool ok = a && a->kind == SL_N_IDENT && a->sym && sl_ty_is_array(a->ty) &&
              (a->sym->resizable || (a->sym->kind == SL_SYM_FPARAM && sl_ty_len(a->sym->ty) == 0));
    if (a && a->ty == SL_TY_ERROR)
        return ck_set_ty(n, SL_TY_ERROR);
    if (!ok || n->nlist != want) {
        ck_error(c, n->pos, "%s() takes a resizable array (a local declared without size or "
              "initializer, as 'float a[];')%s", resizable_ops[op],
              op == SL_RESIZE_POP ? "" : op == SL_RESIZE_PUSH ? " and a value"
                                                              : " and a number of elements");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    n->op = op;
    sl_ty elem = sl_ty_elem(a->ty);
    if (want == 2) {
        sl_ty to = op == SL_RESIZE_PUSH ? elem : SL_TYPE_FLOAT;
        sl_ty t = n->list[1]->ty;
        if (t == SL_TY_ERROR)
            return ck_set_ty(n, SL_TY_ERROR);
        if (!ck_can_convert(t, to)) {
            ck_error(c, n->list[1]->pos, "argument 2 of '%s' must be a '%s', not a '%s'",
                  resizable_ops[op], sl_ty_name(to), sl_ty_name(t));
            return ck_set_ty(n, SL_TY_ERROR);
        }
        ck_wrap_conv(c, &n->list[1], to);
    }
    return ck_set_ty(n, op == SL_RESIZE_POP ? elem : SL_TYPE_VOID);
}

/* spline([basis,] t, k0, k1, ...) and spline([basis,] t, knots[]) (RI
 * Spec 3.2 §15.1): the knots are floats, colors, points or vectors (the
 * first knot's type, or the context's for an untyped first knot); the
 * basis a constant string naming one of sl_spline_basis_find's. At least
 * 4 knots, and 4 + a multiple of the basis' step. The node's op is the
 * basis; an array's length is checked where it is known (an unsized
 * parameter's: when its call is generated). */
static sl_ty check_spline(checker *c, sl_node *n, sl_ty hint)
{
    int first = 0, basis = SL_SPLINE_CATMULL_ROM;
    bool bad = false;
    if (n->nlist > 0 && n->list[0]->kind == SL_N_STR) {
        basis = sl_spline_basis_find(n->list[0]->name);
        if (basis < 0) {
            ck_error(c, n->list[0]->pos, "unknown spline basis '%s' (known: \"catmull-rom\", "
                  "\"bezier\", \"b-spline\", \"hermite\", \"linear\", \"constant\")",
                  n->list[0]->name);
            bad = true;
        }
        ck_check_expr(c, &n->list[0], SL_TYPE_STRING);
        first = 1;
    }
    for (int i = first; i < n->nlist; i++)
        bad |= ck_check_expr(c, &n->list[i], i == first ? SL_TYPE_FLOAT
                          : sl_ty_is_triple(hint) ? hint : SL_TYPE_VOID) == SL_TY_ERROR;
    if (bad)
        return ck_set_ty(n, SL_TY_ERROR);
    if (first == 0 && n->nlist > 0 && n->list[0]->ty == SL_TYPE_STRING) {
        ck_error(c, n->list[0]->pos, "the basis of spline() must be a constant string");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    int nknots = n->nlist - first - 1;
    if (nknots < 1 || n->list[first]->ty != SL_TYPE_FLOAT) {
        ck_error(c, n->pos, "spline() takes [basis,] a float parameter and the knots "
                         "(4 or more values, or an array)");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    const sl_spline_basis *b = sl_spline_basis_get(basis);
    sl_node *k0 = n->list[first + 1];
    sl_ty elem;
    if (nknots == 1 && sl_ty_is_array(k0->ty)) {
        elem = sl_ty_elem(k0->ty);
        nknots = sl_ty_len(k0->ty);
        if (k0->kind != SL_N_IDENT) {
            ck_error(c, k0->pos, "the knots of spline() must be an array variable");
            return ck_set_ty(n, SL_TY_ERROR);
        }
        if (elem == SL_TYPE_MATRIX || elem == SL_TYPE_STRING) {
            ck_error(c, k0->pos, "spline() interpolates floats and triples, not '%s'",
                  sl_ty_name(k0->ty));
            return ck_set_ty(n, SL_TY_ERROR);
        }
    } else {
        elem = k0->ty == SL_TY_LIST3 ? (sl_ty_is_triple(hint) ? hint : SL_TYPE_POINT) : k0->ty;
        if (elem != SL_TYPE_FLOAT && !sl_ty_is_triple(elem)) {
            ck_error(c, k0->pos, "spline() interpolates floats and triples, not '%s'",
                  sl_ty_name(k0->ty));
            return ck_set_ty(n, SL_TY_ERROR);
        }
        for (int i = first + 1; i < n->nlist; i++) {
            sl_ty have = n->list[i]->ty;
            if (!ck_can_convert(have, elem) || sl_ty_is_array(have) ||
                (elem == SL_TYPE_FLOAT && have != SL_TYPE_FLOAT)) {
                ck_error(c, n->list[i]->pos, "knot %d of spline() is a '%s', the first a '%s'",
                      i - first, sl_ty_name(have), sl_ty_name(elem));
                return ck_set_ty(n, SL_TY_ERROR);
            }
            ck_wrap_conv(c, &n->list[i], elem);
        }
    }
    if (nknots && (nknots < 4 || (nknots - 4) % b->step != 0)) {
        ck_error(c, n->pos, "a '%s' spline takes 4%s knots, not %d", b->name,
              b->step == 3 ? ", 7, 10, ..." : b->step == 2 ? ", 6, 8, ..." : " or more",
              nknots);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    int count;
    n->builtin = sl_builtin_find("spline", &count);
    n->op = basis;
    return ck_set_ty(n, elem);
}


typedef struct format_check {
    char convs[64];
    int n;
} format_check;

static void collect_conv(void *arg, const char *spec, size_t len, char conv, const char *lit,
                         size_t litlen)
{
    (void)len;
    (void)lit;
    (void)litlen;
    format_check *f = arg;
    if (spec && f->n < 64)
        f->convs[f->n] = conv;
    if (spec)
        f->n++;
}

/* concat(s, ...), format(fmt, ...), printf(fmt, ...): strings, and a
 * constant format whose conversions match the arguments' types. */
static sl_ty check_strings(checker *c, sl_node *n, const sl_builtin *b)
{
    bool bad = false;
    for (int i = 0; i < n->nlist; i++)
        bad |= ck_check_expr(c, &n->list[i], SL_TYPE_VOID) == SL_TY_ERROR;
    if (bad)
        return ck_set_ty(n, SL_TY_ERROR);
    if (b->op == SL_OP_SCAT) {
        for (int i = 0; i < n->nlist; i++) {
            if (n->list[i]->ty != SL_TYPE_STRING) {
                ck_error(c, n->list[i]->pos, "argument %d of concat() is a '%s', not a string",
                      i + 1, sl_ty_name(n->list[i]->ty));
                return ck_set_ty(n, SL_TY_ERROR);
            }
        }
        if (n->nlist == 0) {
            ck_error(c, n->pos, "concat() takes one or more strings");
            return ck_set_ty(n, SL_TY_ERROR);
        }
    } else {
        if (n->nlist == 0 || n->list[0]->kind != SL_N_STR) {
            ck_error(c, n->pos, "%s() needs a constant format string first", n->name);
            return ck_set_ty(n, SL_TY_ERROR);
        }
        format_check f = { .n = 0 };
        int count = sl_format_walk(n->list[0]->name, collect_conv, &f);
        if (count < 0) {
            ck_error(c, n->list[0]->pos, "malformed conversion in the format string (known: "
                  "%%f %%e %%g %%d %%i %%p %%v %%n %%c %%m %%s %%%%)");
            return ck_set_ty(n, SL_TY_ERROR);
        }
        if (count != n->nlist - 1 || count > 64) {
            ck_error(c, n->pos, "the format string of %s() has %d conversions, but %d values "
                  "follow it", n->name, count, n->nlist - 1);
            return ck_set_ty(n, SL_TY_ERROR);
        }
        for (int i = 0; i < count; i++) {
            sl_ty ty = n->list[i + 1]->ty;
            char k = f.convs[i];
            bool ok = strchr("fegdi", k) ? ty == SL_TYPE_FLOAT
                    : strchr("pvn", k) ? sl_ty_is_spatial(ty)
                    : k == 'c' ? ty == SL_TYPE_COLOR
                    : k == 'm' ? ty == SL_TYPE_MATRIX : ty == SL_TYPE_STRING;
            if (!ok) {
                ck_error(c, n->list[i + 1]->pos, "'%%%c' in the format string of %s() does not "
                      "take a '%s'", k, n->name, sl_ty_name(ty));
                return ck_set_ty(n, SL_TY_ERROR);
            }
        }
    }
    n->builtin = b;
    return ck_set_ty(n, b->op == SL_OP_SPRINT ? SL_TYPE_VOID : SL_TYPE_STRING);
}

/* The texture lookups (RI Spec 3.2 §15.7; docs/textures.md):
 *   texture(name[channel] [, s, t | , s1, t1, s2, t2, s3, t3, s4, t4], params)
 *   environment(name[channel], direction, params)
 *   bump(name[channel], N, dPds, dPdt [, s, t], params)
 *   textureinfo(name, "dataname", variable)
 * name a string expression, [channel] an optional float index (after a
 * string constant or a string variable), params pairs of a constant name
 * and a value. n->op: SL_TEX_* (builtins.h); n->a the name, n->b the
 * channel or NULL; texture and environment are float, or color where the
 * context wants a color. */
static sl_ty check_texture_info(checker *c, sl_node *n)
{
    if (n->nlist != 3) {
        ck_error(c, n->pos, "textureinfo() takes a texture name, the name of the datum and a "
                         "variable for it");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    bool bad = ck_check_expr(c, &n->list[0], SL_TYPE_STRING) != SL_TYPE_STRING;
    sl_node *what = n->list[1], *var = n->list[2];
    ck_check_expr(c, &n->list[1], SL_TYPE_STRING);
    if (what->kind != SL_N_STR) {
        ck_error(c, what->pos, "the datum of textureinfo() must be a constant string "
                            "(\"resolution\", \"channels\", \"levels\" or \"type\")");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    int q = sl_texinfo_find(what->name);
    if (q < 0) {
        ck_error(c, what->pos, "unknown textureinfo() datum '%s' (known: \"resolution\", "
                            "\"channels\", \"levels\", \"type\")", what->name);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    sl_ty want = q == SL_TEXINFO_RESOLUTION ? sl_ty_array(SL_TYPE_FLOAT, 2)
               : q == SL_TEXINFO_TYPE ? SL_TYPE_STRING : SL_TYPE_FLOAT;
    sl_ty have = ck_check_expr(c, &n->list[2], SL_TYPE_VOID);
    if (bad || have == SL_TY_ERROR)
        return ck_set_ty(n, SL_TY_ERROR);
    if (var->kind != SL_N_IDENT || have != want) {
        ck_error(c, var->pos, "textureinfo() writes \"%s\" into a variable of type '%s'",
              what->name, sl_ty_name(want));
        return ck_set_ty(n, SL_TY_ERROR);
    }
    ck_check_assignable(c, var, "modify");
    int count;
    n->builtin = sl_builtin_find("textureinfo", &count);
    n->op = SL_TEX_INFO;
    n->a = n->list[0];
    n->num = q;
    return ck_set_ty(n, SL_TYPE_FLOAT);
}

static sl_ty check_texture(checker *c, sl_node *n, sl_ty hint)
{
    int kind = strcmp(n->name, "texture") == 0 ? SL_TEX_TEXTURE
             : strcmp(n->name, "environment") == 0 ? SL_TEX_ENVIRONMENT
             : strcmp(n->name, "bump") == 0 ? SL_TEX_BUMP : SL_TEX_INFO;
    if (kind == SL_TEX_INFO)
        return check_texture_info(c, n);
    if (n->nlist < 1) {
        ck_error(c, n->pos, "%s() takes a texture name first", n->name);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    bool bad = false;
    sl_node *first = n->list[0];
    n->a = first;
    n->b = NULL;
    sl_ty at = first->kind != SL_N_INDEX ? SL_TY_ERROR
             : first->a->kind == SL_N_STR ? SL_TYPE_STRING : ck_check_ident(c, first->a);
    if (first->kind == SL_N_INDEX && first->a->kind == SL_N_IDENT && at == SL_TY_ERROR)
        return ck_set_ty(n, SL_TY_ERROR);
    if (first->kind == SL_N_INDEX && at == SL_TYPE_STRING) {
        n->a = first->a;                 /* name[channel] */
        ck_set_ty(n->a, SL_TYPE_STRING);
        bad |= ck_check_expr(c, &first->b, SL_TYPE_FLOAT) != SL_TYPE_FLOAT;
        n->b = first->b;
        ck_set_ty(first, SL_TYPE_STRING);
    } else if (ck_check_expr(c, &n->list[0], SL_TYPE_STRING) != SL_TYPE_STRING) {
        if (n->list[0]->ty != SL_TY_ERROR)
            ck_error(c, n->list[0]->pos, "the texture name of %s() must be a string, not '%s'",
                  n->name, sl_ty_name(n->list[0]->ty));
        return ck_set_ty(n, SL_TY_ERROR);
    } else {
        n->a = n->list[0];
    }
    int npos = 0;
    while (1 + npos < n->nlist && n->list[1 + npos]->kind != SL_N_STR)
        npos++;
    bool ok_count = kind == SL_TEX_TEXTURE ? (npos == 0 || npos == 2 || npos == 8)
                  : kind == SL_TEX_ENVIRONMENT ? npos == 1 : (npos == 3 || npos == 5);
    if (!ok_count) {
        ck_error(c, n->pos, "%s() takes %s after the texture name, then \"name\", value "
              "parameters; got %d value%s", n->name,
              kind == SL_TEX_TEXTURE ? "no coordinates (s and t), s and t, or four corners "
                                       "s1, t1, ..., s4, t4"
              : kind == SL_TEX_ENVIRONMENT ? "a direction"
              : "N, dPds and dPdt, optionally then s and t", npos, npos == 1 ? "" : "s");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    for (int i = 1; i <= npos; i++) {
        bool spatial = (kind == SL_TEX_ENVIRONMENT) || (kind == SL_TEX_BUMP && i <= 3);
        sl_ty want = spatial ? SL_TYPE_VECTOR : SL_TYPE_FLOAT;
        sl_ty have = ck_check_expr(c, &n->list[i], want);
        if (have == SL_TY_ERROR) {
            bad = true;
            continue;
        }
        if (spatial ? !sl_ty_is_spatial(have) && !sl_ty_is_list(have) : have != SL_TYPE_FLOAT) {
            ck_error(c, n->list[i]->pos, "argument %d of %s() must be a %s, not '%s'", i + 1,
                  n->name, spatial ? "point, vector or normal" : "float", sl_ty_name(have));
            bad = true;
            continue;
        }
        ck_wrap_conv(c, &n->list[i], want);
    }
    for (int i = 1 + npos; i < n->nlist; i += 2) {
        int k;
        if (!check_optional(c, n, i, TEXTURE_PARAM_NAMES, TEXTURE_PARAM_NAMES, &k)) {
            bad = true;
            continue;
        }
        /* what cg_gen_texture uses: blur, fill, wrap everywhere, width with
         * the four corners' footprint */
        const char *pname = optional_params[k].name;
        if (strcmp(pname, "filter") == 0 || strcmp(pname, "samples") == 0 ||
            strcmp(pname, "lerp") == 0)
            warn_ignored(c, n->list[i], n->name, kind, k, "aafarm filters each lookup one "
                         "way, over the footprint it bounds (docs/textures.md)");
        else if (strstr(pname, "width") && !(kind == SL_TEX_TEXTURE && npos == 8))
            warn_ignored(c, n->list[i], n->name, kind, k, "only the four-corner form of "
                         "texture() has a footprint to widen (use \"blur\")");
    }
    if (bad)
        return ck_set_ty(n, SL_TY_ERROR);
    int count;
    n->builtin = sl_builtin_find(kind == SL_TEX_BUMP ? "bump" : kind == SL_TEX_ENVIRONMENT
                                 ? "environment" : "texture", &count);
    n->op = kind;
    n->num = npos;
    if (kind == SL_TEX_BUMP)
        return ck_set_ty(n, SL_TYPE_VECTOR);
    return ck_set_ty(n, hint == SL_TYPE_COLOR ? SL_TYPE_COLOR : SL_TYPE_FLOAT);
}

sl_ty ck_check_call(checker *c, sl_node *n, sl_ty hint)
{
    sl_func *cands[MAX_OVERLOADS];
    int ncands = ck_find_funcs(c, n->name, cands, MAX_OVERLOADS);
    if (ncands == 0 && strcmp(n->name, "arraylength") == 0)
        return check_arraylength(c, n);
    if (ncands == 0 && resizable_op(n->name) >= 0)
        return check_resizable(c, n, resizable_op(n->name));
    if (ncands == 0 && n->nlist > 2 && n->nlist <= 8 &&
        (strcmp(n->name, "min") == 0 || strcmp(n->name, "max") == 0)) {
        /* RI Spec 3.2 §15.1 min(a, b, ...): min(min(a, b, ...), last) */
        sl_node *inner = sl_node_new(c->arena, SL_N_CALL, n->pos);
        inner->name = n->name;
        inner->list = n->list;
        inner->nlist = n->nlist - 1;
        sl_node **two = sl_arena_alloc(c->arena, 2 * sizeof *two);
        two[0] = inner;
        two[1] = n->list[n->nlist - 1];
        n->list = two;
        n->nlist = 2;
    }
    if (ncands == 0 && strcmp(n->name, "shadow") == 0 && n->nlist > 2 &&
        !check_shadow_params(c, n))
        return ck_set_ty(n, SL_TY_ERROR);
    if (ncands == 0 && strcmp(n->name, "spline") == 0)
        return check_spline(c, n, hint);
    if (ncands == 0 && (strcmp(n->name, "texture") == 0 || strcmp(n->name, "environment") == 0 ||
                        strcmp(n->name, "bump") == 0 || strcmp(n->name, "textureinfo") == 0))
        return check_texture(c, n, hint);
    if (ncands == 0) {
        int count;
        const sl_builtin *b = sl_builtin_find(n->name, &count);
        if (b && b->lower == SL_LOWER_STRINGS)
            return check_strings(c, n, b);
    }
    int count;
    bool builtin = sl_builtin_find(n->name, &count) != NULL;
    if (!ncands && !builtin) {
        for (int i = 0; i < n->nlist; i++)
            ck_check_expr(c, &n->list[i], SL_TYPE_VOID);
        if (strcmp(n->name, "atmosphere") == 0 || strcmp(n->name, "incident") == 0 ||
            strcmp(n->name, "opposite") == 0) {
            ck_error(c, n->pos, "'%s' reads the values of a volume shader, and volume shaders "
                             "are not supported", n->name);
            return ck_set_ty(n, SL_TY_ERROR);
        }
        if (strcmp(n->name, "Dtime") == 0) {
            ck_error(c, n->pos, "'Dtime' is not supported: aafarm renders no motion blur, so "
                             "nothing changes with time (use 0)");
            return ck_set_ty(n, SL_TY_ERROR);
        }
        if (strcmp(n->name, "getshader") == 0 || strcmp(n->name, "getshaders") == 0) {
            ck_error(c, n->pos, "'%s' (RSL 2 co-shaders) is not supported: aafarm compiles "
                             "each shader on its own: put the co-shader's code in a function "
                             "of this shader (or #include it)", n->name);
            return ck_set_ty(n, SL_TY_ERROR);
        }
        if (strcmp(n->name, "gather") == 0) {
            ck_error(c, n->pos, "'gather' is not supported: shaders trace single rays with "
                             "trace(P, R) and shadow(name, P)");
            return ck_set_ty(n, SL_TY_ERROR);
        }
        if (ck_lookup(c, n->name))
            ck_error(c, n->pos, "called object '%s' is not a function", n->name);
        else
            ck_error(c, n->pos, "use of undeclared function '%s'", n->name);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    if (n->nlist > SL_MAX_FUNC_PARAMS || (!ncands && n->nlist > SL_MAX_BUILTIN_ARGS)) {
        ck_error(c, n->pos, "too many arguments in call to '%s' (%d; %s takes at most %d)",
              n->name, n->nlist, ncands ? "a function" : "this built-in",
              ncands ? SL_MAX_FUNC_PARAMS : SL_MAX_BUILTIN_ARGS);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    sl_ty args[SL_MAX_FUNC_PARAMS];
    bool bad = false;
    for (int i = 0; i < n->nlist; i++) {
        /* the parameter type as a hint, when the overloads of this arity agree */
        sl_ty h = SL_TY_ERROR;
        for (int k = 0; k < ncands; k++) {
            if (cands[k]->nparams != n->nlist)
                continue;
            sl_ty pt = cands[k]->params[i]->ty;
            h = h == SL_TY_ERROR || h == pt ? pt : SL_TYPE_VOID;
        }
        args[i] = ck_check_expr(c, &n->list[i], h == SL_TY_ERROR ? SL_TYPE_VOID : h);
        bad |= args[i] == SL_TY_ERROR;
    }
    if (ncands == 1 && !builtin)     /* one function: its own, precise messages */
        return check_user_call(c, n, cands[0], args);
    if (bad)
        return ck_set_ty(n, SL_TY_ERROR);
    if (ncands) {
        bool ambiguous;
        sl_func *f = resolve_user(c, n, cands, ncands, args, hint, &ambiguous);
        if (ambiguous)
            return ck_set_ty(n, SL_TY_ERROR);
        if (f)
            return check_user_call(c, n, f, args);
    }
    sl_ty want[SL_MAX_BUILTIN_ARGS], result;
    if (builtin && n->nlist <= SL_MAX_BUILTIN_ARGS && (!ncands || sl_builtin_resolve(n->name, args, n->nlist, hint, want, &result)))
        return check_builtin_call(c, n, args, hint);
    no_match(c, n, args, cands, ncands, builtin);
    return ck_set_ty(n, SL_TY_ERROR);
}

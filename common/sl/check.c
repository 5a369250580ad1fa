/*
 * check.c: names, types and control-flow facts of a parsed shader (see
 * check.h).
 *
 * Typing follows RI Spec 3.2 §13 ("Language Constructs"): arithmetic on
 * triples is componentwise and a float operand is promoted by duplication;
 * point - point is a vector, point +/- vector a point; a point and a color
 * do not mix; '.' is the dot product of two vectors (or colors), '^' the
 * cross product; comparisons and && || ! give a relation (SL_TY_BOOL).
 * A float used as a condition means "!= 0". Polymorphic noise takes its
 * result type from the context ("hint": a declaration, an assignment, a
 * cast, a parameter, a return), as do untyped lists `(x, y, z)` (typed
 * late: SL_TY_LIST3/LIST16 until a context retypes them) and user
 * functions overloaded by return type.
 *
 * Scopes (RI Spec 3.2 §14.2): one stack of variables; a function's own
 * start at func_base, below it are the enclosing scopes of a nested
 * function, visible only through 'extern'. Nested functions are scoped
 * like variables (vfuncs); calls resolve among the overloads in scope
 * (resolve_user, rules in docs/shading-language.md), then the built-ins.
 * Arrays: fixed-size, indexed by a float; a[i] op= e reads a[i] again.
 *
 * Escapes: every statement records the break/continue/return inside it
 * that leave it (sl_node.escapes). The code generator turns them into flag
 * variables and guards (paper §4.1 needs structured control flow to merge
 * both sides of an undecided branch), so it must know them before it
 * generates the statements that follow.
 *
 * Calls (built-in and user functions, overload resolution, the built-ins
 * with their own rules) are checked in check_call.c; the checker's state
 * and the helpers both files use are declared in check_internal.h.
 */
#include "sl/check.h"
#include "sl/check_internal.h"
#include "sl/builtins.h"
#include "sl/lexer.h"
#include "sl/strmatch.h"
#include "tex/tex.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


static void check_stmt(checker *c, sl_node *n);

void ck_error(checker *c, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(c->diag, SL_DIAG_ERROR, pos, fmt, ap);
    va_end(ap);
}

int sl_space_find(const char *name)
{
    static const char *const names[SL_SPACE__NAMED] = {
        [SL_SPACE_CURRENT] = "current", [SL_SPACE_WORLD] = "world",
        [SL_SPACE_OBJECT] = "object", [SL_SPACE_SHADER] = "shader",
        [SL_SPACE_CAMERA] = "camera", [SL_SPACE_SCREEN] = "screen",
        [SL_SPACE_NDC] = "NDC", [SL_SPACE_RASTER] = "raster",
    };
    for (int i = 0; i < SL_SPACE__NAMED; i++)
        if (strcmp(names[i], name) == 0)
            return i;
    return -1;
}

/* ---------------------------------------------------------------------- */
/* scopes                                                                  */
/* ---------------------------------------------------------------------- */

/* The variable `name` as the current function sees it: its own scopes
 * (down to func_base), then the predefined variables and PI. Variables of
 * an enclosing function are seen only through 'extern' (RI Spec 3.2
 * §14.2), which copies them into the current scope. */
sl_sym *ck_lookup(checker *c, const char *name)
{
    for (int i = c->nsyms - 1; i >= c->func_base; i--)
        if (strcmp(c->syms[i]->name, name) == 0)
            return c->syms[i];
    int g = sl_global_find(name);
    if (g >= 0)
        return c->globals[g];
    if (strcmp(name, "PI") == 0)
        return c->pi;
    if (strcmp(name, "ncomps") == 0)
        return c->ncomps;
    if (strcmp(name, "dtime") == 0)
        return c->dtime;
    return NULL;
}

static void declare(checker *c, sl_sym *sym)
{
    for (int i = c->scope_start; i < c->nsyms; i++) {
        if (strcmp(c->syms[i]->name, sym->name) == 0) {
            ck_error(c, sym->pos, "redefinition of '%s'", sym->name);
            sl_diag_note(c->diag, c->syms[i]->pos, "previous definition is here");
            return;
        }
    }
    sl_list_push(c->arena, (void ***)&c->syms, &c->nsyms, &c->syms_cap, sym);
}

/* A variable of the scopes around the current function (for 'extern' and
 * for the message when one is used without it), innermost first. */
static sl_sym *lookup_enclosing(checker *c, const char *name)
{
    for (int i = c->func_base - 1; i >= 0; i--)
        if (strcmp(c->syms[i]->name, name) == 0)
            return c->syms[i];
    return NULL;
}

typedef struct scope_mark {
    int scope_start, vfuncs_start;
} scope_mark;

static scope_mark push_scope(checker *c)
{
    scope_mark saved = { c->scope_start, c->vfuncs_start };
    c->scope_start = c->nsyms;
    c->vfuncs_start = c->nvfuncs;
    c->depth++;
    return saved;
}

static void pop_scope(checker *c, scope_mark saved)
{
    c->nsyms = c->scope_start;
    c->nvfuncs = c->vfuncs_start;
    c->scope_start = saved.scope_start;
    c->vfuncs_start = saved.vfuncs_start;
    c->depth--;
}

/* The user functions `name` may call here, the overloads: nested ones in
 * scope (innermost first), then those at file level. Returns how many
 * (at most max are stored). */
static unsigned name_hash(const char *name)
{
    unsigned h = 2166136261u;                  /* FNV-1a */
    for (; *name; name++)
        h = (h ^ (unsigned char)*name) * 16777619u;
    return h;
}

/* The file-level functions by name (fhead, fnext), so that a call or a
 * definition finds its namesakes without a scan of every function (a
 * generated source of 100,000 functions took minutes to check) */
static void index_funcs(checker *c)
{
    int n = c->file->nfuncs;
    unsigned size = 16;
    while (size < 2u * (unsigned)n)
        size *= 2;
    c->fmask = size - 1;
    c->fhead = sl_arena_alloc(c->arena, size * sizeof *c->fhead);
    c->fnext = sl_arena_alloc(c->arena, ((size_t)n + 1) * sizeof *c->fnext);
    memset(c->fhead, 0, size * sizeof *c->fhead);
    for (int i = n - 1; i >= 0; i--) {      /* prepended: chains in file order */
        unsigned b = name_hash(c->file->funcs[i]->name) & c->fmask;
        c->fnext[i] = c->fhead[b];
        c->fhead[b] = i + 1;
    }
}

/* Index + 1 of the first file-level function after index `after` (-1:
 * from the start) named `name`; 0: none */
static int next_func(const checker *c, const char *name, int after)
{
    int i = after < 0 ? c->fhead[name_hash(name) & c->fmask] : c->fnext[after];
    while (i && strcmp(c->file->funcs[i - 1]->name, name) != 0)
        i = c->fnext[i - 1];
    return i;
}

int ck_find_funcs(checker *c, const char *name, sl_func **out, int max)
{
    int n = 0;
    for (int i = c->nvfuncs - 1; i >= 0; i--)
        if (strcmp(c->vfuncs[i]->name, name) == 0 && n < max)
            out[n++] = c->vfuncs[i];
    for (int i = next_func(c, name, -1); i && n < max; i = next_func(c, name, i - 1))
        out[n++] = c->file->funcs[i - 1];
    return n;
}

static sl_func *find_func(checker *c, const char *name)
{
    sl_func *f;
    return ck_find_funcs(c, name, &f, 1) ? f : NULL;
}

/* Same parameter types (and 'output'-ness) in the same order. */
static bool same_params(const sl_func *a, const sl_func *b)
{
    if (a->nparams != b->nparams)
        return false;
    for (int i = 0; i < a->nparams; i++)
        if (a->params[i]->ty != b->params[i]->ty ||
            a->params[i]->output != b->params[i]->output)
            return false;
    return true;
}

/* "float f(point, output float)" for a message. */
void ck_func_signature(const sl_func *f, char *buf, size_t size)
{
    size_t o = (size_t)snprintf(buf, size, "%s %s(", sl_ty_name(f->ret), f->name);
    for (int i = 0; i < f->nparams && o < size; i++)
        o += (size_t)snprintf(buf + o, size - o, "%s%s%s", i ? ", " : "",
                              f->params[i]->output ? "output " : "",
                              sl_ty_name(f->params[i]->ty));
    if (o < size)
        snprintf(buf + o, size - o, ")");
}

/* ---------------------------------------------------------------------- */
/* conversions                                                             */
/* ---------------------------------------------------------------------- */

bool ck_can_convert(sl_ty have, sl_ty want)
{
    if (have == want || have == SL_TY_ERROR || want == SL_TY_ERROR)
        return true;
    if (have == SL_TY_LIST3)
        return sl_ty_is_triple(want);
    if (have == SL_TY_LIST16)
        return want == SL_TYPE_MATRIX;
    if (sl_ty_is_spatial(have) && sl_ty_is_spatial(want))
        return true;
    if (have == SL_TYPE_FLOAT &&
        (sl_ty_is_triple(want) || want == SL_TYPE_MATRIX || want == SL_TY_BOOL))
        return true;
    return false;
}

/* Gives an untyped list (and the -, ?: and arithmetic over lists around
 * it) the triple or matrix type `want`. */
static void retype_list(sl_node *e, sl_ty want)
{
    /* a loop along a (a chain of operators: ast.h, sl_spine) and c */
    while (e && sl_ty_is_list(e->ty)) {
        e->ty = want;
        switch (e->kind) {
        case SL_N_CAST: e->cast_ty = want; return;
        case SL_N_UNARY: e = e->a; break;
        case SL_N_BINARY: retype_list(e->b, want); e = e->a; break;
        case SL_N_COND: retype_list(e->b, want); e = e->c; break;
        default: return;
        }
    }
}

/* Wraps *np in a conversion to `want` (the caller checked can_convert). */
void ck_wrap_conv(checker *c, sl_node **np, sl_ty want)
{
    sl_node *e = *np;
    if (e->ty == want || e->ty == SL_TY_ERROR || want == SL_TY_ERROR)
        return;
    if (sl_ty_is_list(e->ty)) {
        retype_list(e, want);
        return;
    }
    if (sl_ty_is_spatial(e->ty) && sl_ty_is_spatial(want)) {
        e->ty = want;          /* same slots, another name */
        return;
    }
    sl_node *conv = sl_node_new(c->arena, SL_N_CONV, e->pos);
    conv->a = e;
    conv->ty = want;
    *np = conv;
}

/* An untyped list where nothing gives it a type: reported. */
static sl_ty settle(checker *c, sl_node *e)
{
    if (!sl_ty_is_list(e->ty))
        return e->ty;
    ck_error(c, e->pos, "cannot tell the type of this list of %d values here; put a type in "
                     "front, as in '%s (...)'", sl_ty_slots(e->ty),
          e->ty == SL_TY_LIST3 ? "point" : "matrix");
    return e->ty = SL_TY_ERROR;
}

/* *np, of type ty (checked), used as a condition. */
static void cond_of(checker *c, sl_node **np, sl_ty ty)
{
    if (ty == SL_TY_BOOL || ty == SL_TY_ERROR)
        return;
    if (ty == SL_TYPE_FLOAT) {
        ck_wrap_conv(c, np, SL_TY_BOOL);
        return;
    }
    ck_error(c, (*np)->pos, "a value of type '%s' cannot be used as a condition",
          sl_ty_name(ty));
    (*np)->ty = SL_TY_ERROR;
}

static void check_cond(checker *c, sl_node **np)
{
    cond_of(c, np, ck_check_expr(c, np, SL_TY_BOOL));
}

/* ---------------------------------------------------------------------- */
/* expressions                                                             */
/* ---------------------------------------------------------------------- */

sl_ty ck_set_ty(sl_node *n, sl_ty ty)
{
    n->ty = ty;
    return ty;
}

sl_ty ck_check_ident(checker *c, sl_node *n)
{
    sl_sym *s = ck_lookup(c, n->name);
    if (!s) {
        sl_sym *outer = lookup_enclosing(c, n->name);
        if (outer)
            ck_error(c, n->pos, "'%s' belongs to an enclosing scope; declare it 'extern %s %s;' "
                             "in function '%s' to use it here", n->name, sl_ty_name(outer->ty),
                  n->name, c->func->name);
        else if (find_func(c, n->name) || sl_builtin_find(n->name, &(int){ 0 }))
            ck_error(c, n->pos, "'%s' is a function; call it with '(...)'", n->name);
        else
            ck_error(c, n->pos, "use of undeclared identifier '%s'", n->name);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    if (s->kind == SL_SYM_GLOBAL || s->kind == SL_SYM_CONST) {
        /* a nested function reading `s` while the enclosing code has its
         * own `s`: the predefined one is meant, as the specification says,
         * but say so (other renderers may differ) */
        sl_sym *outer = lookup_enclosing(c, n->name);
        if (outer && !outer->warned) {
            outer->warned = true;
            sl_diag_warning(c->diag, n->pos, "'%s' in function '%s' is the predefined "
                            "variable, not the enclosing scope's; declare 'extern %s %s;' "
                            "to use that one", n->name, c->func->name, sl_ty_name(outer->ty),
                            n->name);
            sl_diag_note(c->diag, outer->pos, "the enclosing '%s' is declared here", n->name);
        }
    }
    n->sym = s;
    return ck_set_ty(n, s->ty);
}

/* Arithmetic result type of a op b, or SL_TY_ERROR after reporting. */
static sl_ty arith_type(checker *c, const sl_node *n, sl_ty a, sl_ty b)
{
    int op = n->op;
    if (a == SL_TY_ERROR || b == SL_TY_ERROR)
        return SL_TY_ERROR;
    if (a == SL_TYPE_FLOAT && b == SL_TYPE_FLOAT)
        return SL_TYPE_FLOAT;
    if (a == SL_TYPE_MATRIX || b == SL_TYPE_MATRIX) {
        if (op == SL_TOK_STAR && (a == b || a == SL_TYPE_FLOAT || b == SL_TYPE_FLOAT))
            return SL_TYPE_MATRIX;
        if (op == SL_TOK_SLASH && (a == SL_TYPE_MATRIX || a == SL_TYPE_FLOAT))
            return SL_TYPE_MATRIX;      /* m / f; a / b = a * inverse(b) */
        goto bad;
    }
    if (a == SL_TYPE_FLOAT && sl_ty_is_triple(b))
        return b;
    if (b == SL_TYPE_FLOAT && sl_ty_is_triple(a))
        return a;
    if (a == SL_TYPE_COLOR && b == SL_TYPE_COLOR)
        return SL_TYPE_COLOR;
    if (sl_ty_is_spatial(a) && sl_ty_is_spatial(b)) {
        bool additive = op == SL_TOK_PLUS || op == SL_TOK_MINUS;
        if (a == b)
            return additive && op == SL_TOK_MINUS && a == SL_TYPE_POINT ? SL_TYPE_VECTOR : a;
        if (additive && (a == SL_TYPE_POINT || b == SL_TYPE_POINT))
            return op == SL_TOK_MINUS && b == SL_TYPE_POINT ? SL_TYPE_VECTOR : SL_TYPE_POINT;
        return SL_TYPE_VECTOR;
    }
bad:
    ck_error(c, n->pos, "invalid operands to binary '%s' ('%s' and '%s')",
          sl_token_kind_spelling(op), sl_ty_name(a), sl_ty_name(b));
    return SL_TY_ERROR;
}

static sl_ty compare_type(checker *c, const sl_node *n, sl_ty a, sl_ty b)
{
    if (a == SL_TY_ERROR || b == SL_TY_ERROR)
        return SL_TY_ERROR;
    bool eq = n->op == SL_TOK_EQ || n->op == SL_TOK_NE;
    if (a == SL_TYPE_FLOAT && b == SL_TYPE_FLOAT)
        return SL_TY_BOOL;
    if (eq && ((sl_ty_is_spatial(a) && sl_ty_is_spatial(b)) ||
               (a == SL_TYPE_COLOR && b == SL_TYPE_COLOR) ||
               (a == SL_TYPE_STRING && b == SL_TYPE_STRING) ||
               (a == SL_TY_BOOL && b == SL_TY_BOOL) ||
               (a == SL_TYPE_MATRIX && b == SL_TYPE_MATRIX)))
        return SL_TY_BOOL;
    ck_error(c, n->pos, "invalid operands to binary '%s' ('%s' and '%s')",
          sl_token_kind_spelling(n->op), sl_ty_name(a), sl_ty_name(b));
    return SL_TY_ERROR;
}

static bool is_logical(int op) { return op == SL_TOK_AND || op == SL_TOK_OR; }

/* Binary node n after its left operand n->a was checked (type a). */
static sl_ty check_binary_rest(checker *c, sl_node *n, sl_ty a)
{
    int op = n->op;
    if (is_logical(op)) {
        cond_of(c, &n->a, a);
        check_cond(c, &n->b);
        return ck_set_ty(n, SL_TY_BOOL);
    }
    sl_ty b = ck_check_expr(c, &n->b, SL_TYPE_VOID);
    if (a == SL_TY_ERROR || b == SL_TY_ERROR)
        return ck_set_ty(n, SL_TY_ERROR);
    if (sl_ty_is_list(a) || sl_ty_is_list(b)) {
        /* a typed operand types the list: P + (0, 0, 1) */
        if (sl_ty_is_list(a) && ck_can_convert(a, b) && !sl_ty_is_list(b))
            ck_wrap_conv(c, &n->a, a = b);
        else if (sl_ty_is_list(b) && ck_can_convert(b, a) && !sl_ty_is_list(a))
            ck_wrap_conv(c, &n->b, b = a);
        bool arith = op == SL_TOK_PLUS || op == SL_TOK_MINUS || op == SL_TOK_STAR ||
                     op == SL_TOK_SLASH;
        sl_ty list = sl_ty_is_list(a) ? a : b, other = sl_ty_is_list(a) ? b : a;
        /* lists among themselves and with floats stay untyped: (1, 2, 3) * 2 */
        if (list == SL_TY_LIST3 && arith && (other == list || other == SL_TYPE_FLOAT))
            return ck_set_ty(n, list);
        if (sl_ty_is_list(a) && sl_ty_is_list(b) && (op == SL_TOK_EQ || op == SL_TOK_NE) &&
            a == b)
            return ck_set_ty(n, SL_TY_BOOL);
        if (settle(c, n->a) == SL_TY_ERROR || settle(c, n->b) == SL_TY_ERROR)
            return ck_set_ty(n, SL_TY_ERROR);
    }
    switch (op) {
    case SL_TOK_PLUS: case SL_TOK_MINUS: case SL_TOK_STAR: case SL_TOK_SLASH:
        return ck_set_ty(n, arith_type(c, n, a, b));
    case SL_TOK_DOT:
        if ((sl_ty_is_spatial(a) && sl_ty_is_spatial(b)) ||
            (a == SL_TYPE_COLOR && b == SL_TYPE_COLOR))
            return ck_set_ty(n, SL_TYPE_FLOAT);
        break;
    case SL_TOK_CARET:
        if (sl_ty_is_spatial(a) && sl_ty_is_spatial(b))
            return ck_set_ty(n, SL_TYPE_VECTOR);
        break;
    default:
        return ck_set_ty(n, compare_type(c, n, a, b));
    }
    ck_error(c, n->pos, "invalid operands to binary '%s' ('%s' and '%s')",
          sl_token_kind_spelling(op), sl_ty_name(a), sl_ty_name(b));
    return ck_set_ty(n, SL_TY_ERROR);
}

/* A chain of binary operators, left to right as the recursion over `a`
 * would go, with a loop over its spine (ast.h). */
static sl_ty check_binary(checker *c, sl_node *n)
{
    sl_spine spine;
    sl_spine_collect(&spine, n);
    sl_node *deepest = spine.v[spine.n - 1];
    sl_ty ty = ck_check_expr(c, &deepest->a,
                             is_logical(deepest->op) ? SL_TY_BOOL : SL_TYPE_VOID);
    for (int i = spine.n - 1; i >= 0; i--)
        ty = check_binary_rest(c, spine.v[i], ty);
    sl_spine_clear(&spine);
    return ty;
}

static sl_ty check_unary(checker *c, sl_node *n)
{
    if (n->op == SL_TOK_NOT) {
        check_cond(c, &n->a);
        return ck_set_ty(n, SL_TY_BOOL);
    }
    sl_ty a = ck_check_expr(c, &n->a, SL_TYPE_VOID);
    if (a == SL_TY_ERROR || a == SL_TYPE_FLOAT || sl_ty_is_triple(a) || a == SL_TYPE_MATRIX ||
        sl_ty_is_list(a))
        return ck_set_ty(n, a);
    ck_error(c, n->pos, "invalid argument type '%s' to unary '-'", sl_ty_name(a));
    return ck_set_ty(n, SL_TY_ERROR);
}

/* The common type of the two results of ?: */
static sl_ty unify(sl_ty a, sl_ty b)
{
    if (a == b)
        return a;
    if (sl_ty_is_list(a) && !sl_ty_is_list(b) && ck_can_convert(a, b))
        return b;
    if (sl_ty_is_list(b) && !sl_ty_is_list(a) && ck_can_convert(b, a))
        return a;
    if (a == SL_TYPE_FLOAT && (sl_ty_is_triple(b) || b == SL_TYPE_MATRIX))
        return b;
    if (b == SL_TYPE_FLOAT && (sl_ty_is_triple(a) || a == SL_TYPE_MATRIX))
        return a;
    if (sl_ty_is_spatial(a) && sl_ty_is_spatial(b))
        return SL_TYPE_VECTOR;
    return SL_TY_ERROR;
}

static sl_ty check_cond_expr(checker *c, sl_node *n, sl_ty hint)
{
    check_cond(c, &n->a);
    sl_ty a = ck_check_expr(c, &n->b, hint);
    sl_ty b = ck_check_expr(c, &n->c, hint);
    if (a == SL_TY_ERROR || b == SL_TY_ERROR)
        return ck_set_ty(n, SL_TY_ERROR);
    sl_ty ty = unify(a, b);
    if (ty == SL_TY_ERROR || ty == SL_TYPE_VOID) {
        ck_error(c, n->pos, "incompatible operand types ('%s' and '%s') in conditional expression",
              sl_ty_name(a), sl_ty_name(b));
        return ck_set_ty(n, SL_TY_ERROR);
    }
    ck_wrap_conv(c, &n->b, ty);
    ck_wrap_conv(c, &n->c, ty);
    return ck_set_ty(n, ty);
}

bool ck_check_assignable(checker *c, sl_node *lhs, const char *what)
{
    sl_sym *s = lhs->sym;
    if (!s || s->writable)
        return true;
    if (s->kind == SL_SYM_GLOBAL)
        ck_error(c, lhs->pos, "cannot %s '%s': it is a read-only global variable", what, s->name);
    else if (s->kind == SL_SYM_CONST)
        ck_error(c, lhs->pos, "cannot %s '%s': it is a constant", what, s->name);
    else
        ck_error(c, lhs->pos, "cannot %s parameter '%s': it is not declared 'output'", what,
              s->name);
    return false;
}

/* A constant index: its value, true; false when the index varies. */
static bool const_index(const sl_node *x, double *k)
{
    if (x->kind == SL_N_NUM) {
        *k = floor(x->num);
        return true;
    }
    if (x->kind == SL_N_UNARY && x->op == SL_TOK_MINUS && x->a->kind == SL_N_NUM) {
        *k = floor(-x->a->num);
        return true;
    }
    return false;
}

/* a[i]: a an array variable, i a float (rounded down); a constant index
 * must lie inside a sized array. n->num != 0: the index node is shared
 * with the target of `a[i] op= e` and already checked. */
static sl_ty check_index(checker *c, sl_node *n)
{
    if (n->a->kind == SL_N_STR) {
        ck_error(c, n->pos, "a channel index after a string is only allowed on the texture name "
                         "of texture(), environment() or bump()");
        return ck_set_ty(n, SL_TY_ERROR);
    }
    sl_ty at = ck_check_ident(c, n->a);
    sl_ty it = n->num != 0 ? n->b->ty : ck_check_expr(c, &n->b, SL_TYPE_FLOAT);
    if (at == SL_TY_ERROR || it == SL_TY_ERROR)
        return ck_set_ty(n, SL_TY_ERROR);
    if (!sl_ty_is_array(at)) {
        ck_error(c, n->pos, "'%s' is not an array (it is a '%s')", n->a->name, sl_ty_name(at));
        return ck_set_ty(n, SL_TY_ERROR);
    }
    if (it != SL_TYPE_FLOAT) {
        ck_error(c, n->b->pos, "an array index must be a float, not '%s'", sl_ty_name(it));
        return ck_set_ty(n, SL_TY_ERROR);
    }
    double k;
    int len = sl_ty_len(at);
    if (len > 0 && const_index(n->b, &k) && !(k >= 0 && k < len)) {
        ck_error(c, n->b->pos, "array index %g is out of range for '%s' (%s: 0 to %d)", k,
              n->a->name, sl_ty_name(at), len - 1);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    return ck_set_ty(n, sl_ty_elem(at));
}

static sl_ty check_assign(checker *c, sl_node *n)
{
    sl_node *lhs = n->a;
    if (lhs->kind != SL_N_IDENT && lhs->kind != SL_N_INDEX)
        return ck_set_ty(n, SL_TY_ERROR);
    bool element = lhs->kind == SL_N_INDEX;
    sl_node *var = element ? lhs->a : lhs;
    sl_ty lt = element ? check_index(c, lhs) : ck_check_ident(c, lhs);
    if (lt == SL_TY_ERROR) {
        ck_check_expr(c, &n->b, SL_TYPE_VOID);
        return ck_set_ty(n, SL_TY_ERROR);
    }
    ck_check_assignable(c, var, "assign to");
    if (n->op != SL_TOK_ASSIGN) {     /* x op= e  ->  x = x op e */
        sl_node *bin = sl_node_new(c->arena, SL_N_BINARY, n->pos);
        bin->op = n->op == SL_TOK_PLUS_ASSIGN ? SL_TOK_PLUS
                : n->op == SL_TOK_MINUS_ASSIGN ? SL_TOK_MINUS
                : n->op == SL_TOK_STAR_ASSIGN ? SL_TOK_STAR : SL_TOK_SLASH;
        sl_node *read = sl_node_new(c->arena, SL_N_IDENT, var->pos);
        read->name = var->name;
        if (element) {                /* a[i] op= e: the index is evaluated twice */
            sl_node *x = sl_node_new(c->arena, SL_N_INDEX, lhs->pos);
            x->a = read;
            x->b = lhs->b;
            x->num = 1;
            read = x;
        }
        bin->a = read;
        bin->b = n->b;
        n->b = bin;
        n->op = SL_TOK_ASSIGN;
    }
    sl_ty rt = ck_check_expr(c, &n->b, lt);
    if (!ck_can_convert(rt, lt)) {
        ck_error(c, n->b->pos, "cannot assign a value of type '%s' to '%s%s' (%s)",
              sl_ty_name(rt), var->name, element ? "[...]" : "", sl_ty_name(lt));
        return ck_set_ty(n, SL_TY_ERROR);
    }
    ck_wrap_conv(c, &n->b, lt);
    return ck_set_ty(n, lt);
}

/* (x, y, z) or 16 values without a type: a triple or matrix of the type
 * the context asks for (hint), else an untyped list for the context to
 * type later (RI Spec 3.2 §13: "the type of a parenthesised triple is
 * taken from its context"). */
static sl_ty check_untyped_list(checker *c, sl_node *n, sl_ty hint)
{
    bool bad = false;
    for (int i = 0; i < n->nlist; i++)
        bad |= ck_check_expr(c, &n->list[i], SL_TYPE_FLOAT) == SL_TY_ERROR;
    if (bad)
        return SL_TY_ERROR;
    if (n->nlist != 3 && n->nlist != 16) {
        ck_error(c, n->pos, "a list of %d values is neither a triple (3 values) nor a "
                         "matrix (16)", n->nlist);
        return SL_TY_ERROR;
    }
    for (int i = 0; i < n->nlist; i++) {
        if (n->list[i]->ty != SL_TYPE_FLOAT) {
            ck_error(c, n->list[i]->pos, "component %d of a list must be a float, not '%s'",
                  i + 1, sl_ty_name(n->list[i]->ty));
            return SL_TY_ERROR;
        }
    }
    sl_ty list = n->nlist == 3 ? SL_TY_LIST3 : SL_TY_LIST16;
    if (ck_can_convert(list, hint)) {
        n->cast_ty = hint;
        return hint;
    }
    return list;
}

static sl_ty check_cast_values(checker *c, sl_node *n)
{
    sl_ty ty = n->cast_ty;
    int count = n->nlist;
    sl_ty hint = count == 1 ? ty : SL_TYPE_FLOAT;
    bool bad = false;
    for (int i = 0; i < count; i++)
        bad |= ck_check_expr(c, &n->list[i], hint) == SL_TY_ERROR;
    if (bad)
        return SL_TY_ERROR;
    int want = sl_ty_slots(ty);
    if (count == 1) {
        sl_ty a = n->list[0]->ty;
        if (a == ty || ck_can_convert(a, ty)) {
            ck_wrap_conv(c, &n->list[0], ty);
            return ty;
        }
        ck_error(c, n->pos, "cannot convert '%s' to '%s'", sl_ty_name(a), sl_ty_name(ty));
        return SL_TY_ERROR;
    }
    if (count != want || ty == SL_TYPE_FLOAT || ty == SL_TYPE_STRING) {
        ck_error(c, n->pos, "a '%s' is built from %s, not from %d values", sl_ty_name(ty),
              ty == SL_TYPE_MATRIX ? "1 or 16 floats" : want == 3 ? "1 or 3 floats" : "1 value",
              count);
        return SL_TY_ERROR;
    }
    for (int i = 0; i < count; i++) {
        if (n->list[i]->ty != SL_TYPE_FLOAT) {
            ck_error(c, n->list[i]->pos, "component %d of '%s' must be a float, not '%s'", i + 1,
                  sl_ty_name(ty), sl_ty_name(n->list[i]->ty));
            return SL_TY_ERROR;
        }
    }
    return ty;
}

static sl_ty check_cast(checker *c, sl_node *n, sl_ty hint)
{
    if (n->cast_ty == SL_TYPE_VOID || sl_ty_is_list(n->cast_ty))
        return ck_set_ty(n, check_untyped_list(c, n, hint));
    sl_ty ty = check_cast_values(c, n);
    if (ty == SL_TY_ERROR || !n->name)
        return ck_set_ty(n, ty);
    if (sl_ty_is_spatial(ty)) {
        if (sl_space_find(n->name) < 0) {
            ck_error(c, n->pos, "unknown space '%s' (known: " SL_SPACE_NAMES ")", n->name);
            return ck_set_ty(n, SL_TY_ERROR);
        }
    } else if (ty == SL_TYPE_COLOR) {
        if (sl_color_space_find(n->name) < 0) {
            ck_error(c, n->pos, "unknown color space '%s' (known: " SL_COLOR_SPACE_NAMES ")",
                  n->name);
            return ck_set_ty(n, SL_TY_ERROR);
        }
    } else if (ty == SL_TYPE_MATRIX) {
        if (sl_space_find(n->name) < 0) {
            ck_error(c, n->pos, "unknown space '%s' (known: " SL_SPACE_NAMES ")", n->name);
            return ck_set_ty(n, SL_TY_ERROR);
        }
    } else {
        ck_error(c, n->pos, "a space name is not allowed in a cast to '%s'", sl_ty_name(ty));
        return ck_set_ty(n, SL_TY_ERROR);
    }
    return ck_set_ty(n, ty);
}

sl_ty ck_check_expr(checker *c, sl_node **np, sl_ty hint)
{
    sl_node *n = *np;
    switch (n->kind) {
    case SL_N_NUM: return ck_set_ty(n, SL_TYPE_FLOAT);
    case SL_N_STR: return ck_set_ty(n, SL_TYPE_STRING);
    case SL_N_ERROR: return ck_set_ty(n, SL_TY_ERROR);
    case SL_N_IDENT: return ck_check_ident(c, n);
    case SL_N_CALL: return ck_check_call(c, n, hint);
    case SL_N_UNARY: return check_unary(c, n);
    case SL_N_BINARY: return check_binary(c, n);
    case SL_N_COND: return check_cond_expr(c, n, hint);
    case SL_N_ASSIGN: return check_assign(c, n);
    case SL_N_CAST: return check_cast(c, n, hint);
    case SL_N_INDEX: return check_index(c, n);
    case SL_N_CONV: return n->ty;
    default: return ck_set_ty(n, SL_TY_ERROR);
    }
}

/* ---------------------------------------------------------------------- */
/* statements and escapes                                                  */
/* ---------------------------------------------------------------------- */

static bool same_escape(const sl_escape *a, const sl_escape *b)
{
    return a->kind == b->kind && a->loop == b->loop && a->func == b->func;
}

static void add_escape(checker *c, sl_node *n, sl_escape e)
{
    for (int i = 0; i < n->nescapes; i++)
        if (same_escape(&n->escapes[i], &e))
            return;
    sl_escape *grown = sl_arena_alloc(c->arena, (size_t)(n->nescapes + 1) * sizeof *grown);
    if (n->nescapes)
        memcpy(grown, n->escapes, (size_t)n->nescapes * sizeof *grown);
    grown[n->nescapes++] = e;
    n->escapes = grown;
}

/* n inherits the escapes of child, except those that end at `loop`. */
static void inherit(checker *c, sl_node *n, const sl_node *child, const sl_node *loop)
{
    if (!child)
        return;
    for (int i = 0; i < child->nescapes; i++)
        if (!loop || child->escapes[i].loop != loop)
            add_escape(c, n, child->escapes[i]);
}

/* The initializer (or shader parameter default) v->a of variable s: an
 * expression of a convertible type, or for an array '{ values }' (one per
 * element; an array declared without a size takes their number). */
static void check_init(checker *c, sl_node *v, sl_sym *s)
{
    sl_node *init = v->a;
    if (init && init->kind == SL_N_ARRAYINIT) {
        if (!sl_ty_is_array(s->ty)) {
            ck_error(c, init->pos, "cannot initialize '%s' (%s) with a list in braces", s->name,
                  sl_ty_name(s->ty));
            return;
        }
        sl_ty elem = sl_ty_elem(s->ty);
        int len = sl_ty_len(s->ty);
        if (len == 0 && init->nlist > 0 && init->nlist <= SL_MAX_ARRAY_LEN)
            s->ty = sl_ty_array(elem, len = init->nlist);
        init->ty = s->ty;
        for (int i = 0; i < init->nlist; i++) {
            sl_ty t = ck_check_expr(c, &init->list[i], elem);
            if (!ck_can_convert(t, elem)) {
                ck_error(c, init->list[i]->pos, "element %d of '%s' (%s) cannot be a '%s'", i + 1,
                      s->name, sl_ty_name(s->ty), sl_ty_name(t));
                return;
            }
            ck_wrap_conv(c, &init->list[i], elem);
        }
        if (init->nlist != len)
            ck_error(c, init->pos, "'%s' has %d elements, but %d value%s given", s->name, len,
                  init->nlist, init->nlist == 1 ? " is" : "s are");
        return;
    }
    if (init) {
        sl_ty t = ck_check_expr(c, &v->a, s->ty);
        if (!ck_can_convert(t, s->ty))
            ck_error(c, v->a->pos, "cannot initialize '%s' (%s) with a value of type '%s'",
                  s->name, sl_ty_name(s->ty), sl_ty_name(t));
        else
            ck_wrap_conv(c, &v->a, s->ty);
    }
    if (sl_ty_is_array(s->ty) && sl_ty_len(s->ty) == 0 && s->kind == SL_SYM_LOCAL && !init) {
        s->resizable = true;          /* RSL 2: 'float a[];' grows with push/resize */
        s->ty = sl_ty_array(sl_ty_elem(s->ty), SL_RESIZABLE_CAPACITY);
    } else if (sl_ty_is_array(s->ty) && sl_ty_len(s->ty) == 0) {
        ck_error(c, v->pos, "array '%s' needs a size or an initializer", s->name);
    }
}

static void check_decl(checker *c, sl_node *n)
{
    for (int i = 0; i < n->nlist; i++) {
        sl_node *v = n->list[i];
        sl_sym *s = v->sym;
        if (v->num != 0) {            /* extern */
            sl_sym *outer = lookup_enclosing(c, s->name);
            if (!outer) {
                outer = ck_lookup(c, s->name);
                if (outer && outer->kind != SL_SYM_GLOBAL)
                    outer = NULL;         /* a variable of this very function */
            }
            if (!outer) {
                ck_error(c, v->pos, c->func && c->func->nested
                          ? "'extern' names no variable '%s' of an enclosing scope"
                          : "'extern' may only name a predefined variable here "
                            "(pass '%s' as a parameter instead)", s->name);
                s->kind = SL_SYM_LOCAL;     /* declared anyway: no follow-up errors */
                declare(c, s);
                v->num = 0;
                continue;
            } else if (outer->ty != s->ty &&
                       !(sl_ty_is_array(s->ty) && sl_ty_len(s->ty) == 0 &&
                         sl_ty_is_array(outer->ty) &&
                         sl_ty_elem(outer->ty) == sl_ty_elem(s->ty)))
                ck_error(c, v->pos, "'extern' declaration of '%s' as '%s' does not match its "
                                 "type '%s'", s->name, sl_ty_name(s->ty),
                      sl_ty_name(outer->ty));
            v->sym = NULL;
            if (outer->kind != SL_SYM_GLOBAL && outer->kind != SL_SYM_CONST)
                declare(c, outer);        /* the enclosing variable itself */
            continue;
        }
        check_init(c, v, s);
        declare(c, s);
    }
}

static void check_loop_body(checker *c, sl_node *loop, sl_node *body)
{
    sl_list_push(c->arena, (void ***)&c->loops, &c->nloops, &c->loops_cap, loop);
    check_stmt(c, body);
    c->nloops--;
    inherit(c, loop, body, loop);
}

static void check_loop_mod(checker *c, sl_node *n)
{
    const char *kw = n->kind == SL_N_BREAK ? "break" : "continue";
    int levels = (int)n->num;
    if (c->nloops == 0) {
        ck_error(c, n->pos, "'%s' statement not in loop", kw);
        return;
    }
    if (levels > c->nloops) {
        ck_error(c, n->pos, "'%s %d' leaves more loops than the %d around it", kw, levels,
              c->nloops);
        return;
    }
    n->target = c->loops[c->nloops - levels];
    sl_escape e = { n->kind == SL_N_BREAK ? SL_ESC_BREAK : SL_ESC_CONTINUE, n->target, NULL };
    add_escape(c, n, e);
}

static void check_return(checker *c, sl_node *n)
{
    sl_ty want = c->func ? c->func->ret : SL_TYPE_VOID;
    n->func = c->func;
    if (n->a) {
        sl_ty t = ck_check_expr(c, &n->a, want);
        if (want == SL_TYPE_VOID) {
            ck_error(c, n->pos, c->func ? "void function '%s' should not return a value"
                                     : "shader '%s' should not return a value",
                  c->func ? c->func->name : c->file->name);
        } else if (!ck_can_convert(t, want)) {
            ck_error(c, n->a->pos, "cannot return a value of type '%s' from function '%s' "
                                "returning '%s'", sl_ty_name(t), c->func->name,
                  sl_ty_name(want));
        } else {
            ck_wrap_conv(c, &n->a, want);
        }
    } else if (want != SL_TYPE_VOID) {
        ck_error(c, n->pos, "non-void function '%s' should return a value", c->func->name);
    }
    sl_escape e = { SL_ESC_RETURN, NULL, c->func };
    add_escape(c, n, e);
}

static void check_nested_function(checker *c, sl_func *f, const sl_node *block, int index);

static void check_stmt(checker *c, sl_node *n)
{
    if (!n || sl_diag_full(c->diag))
        return;
    switch (n->kind) {
    case SL_N_BLOCK: {
        scope_mark saved = push_scope(c);
        for (int i = 0; i < n->nlist; i++) {
            if (n->list[i]->kind == SL_N_FUNC)
                check_nested_function(c, n->list[i]->func, n, i);
            else
                check_stmt(c, n->list[i]);
            inherit(c, n, n->list[i], NULL);
        }
        pop_scope(c, saved);
        break;
    }
    case SL_N_DECL: check_decl(c, n); break;
    case SL_N_EXPR: ck_check_expr(c, &n->a, SL_TYPE_VOID); break;
    case SL_N_IF:
        check_cond(c, &n->a);
        check_stmt(c, n->b);
        check_stmt(c, n->c);
        inherit(c, n, n->b, NULL);
        inherit(c, n, n->c, NULL);
        break;
    case SL_N_WHILE:
        check_cond(c, &n->a);
        check_loop_body(c, n, n->b);
        break;
    case SL_N_FOR: {
        scope_mark saved = push_scope(c);
        if (n->a)
            check_stmt(c, n->a);
        if (n->b)
            check_cond(c, &n->b);
        if (n->c)
            check_stmt(c, n->c);
        check_loop_body(c, n, n->d);
        pop_scope(c, saved);
        break;
    }
    case SL_N_BREAK: case SL_N_CONTINUE: check_loop_mod(c, n); break;
    case SL_N_RETURN: check_return(c, n); break;
    case SL_N_FUNC: check_nested_function(c, n->func, NULL, 0); break;
    default: break;
    }
}

/* Marks the body's final return as the tail one; true when some other
 * return exists (the code generator then needs a "returned" flag). */
static bool count_returns(const sl_node *n, int *count)
{
    for (; n; n = n->a) {       /* a loop along a: chains of operators (ast.h) */
        if (n->kind == SL_N_RETURN)
            (*count)++;
        count_returns(n->b, count);
        count_returns(n->c, count);
        count_returns(n->d, count);
        if (n->kind == SL_N_BLOCK)
            for (int i = 0; i < n->nlist; i++)
                count_returns(n->list[i], count);
    }
    return *count > 0;
}

static bool needs_ret_flag(sl_node *body)
{
    int count = 0;
    count_returns(body, &count);
    if (count == 0)
        return false;
    if (body->kind == SL_N_BLOCK && body->nlist > 0 &&
        body->list[body->nlist - 1]->kind == SL_N_RETURN) {
        body->list[body->nlist - 1]->tail = true;
        return count > 1;
    }
    return true;
}

/* ---------------------------------------------------------------------- */
/* functions, recursion, the shader                                        */
/* ---------------------------------------------------------------------- */

/* The parameters and body of f, in a scope of their own above the
 * current one (func_base: the variables below it are the enclosing ones). */
static void check_function_body(checker *c, sl_func *f)
{
    sl_list_push(c->arena, (void ***)&c->allfuncs, &c->nallfuncs, &c->allfuncs_cap, f);
    if (f->nparams > SL_MAX_FUNC_PARAMS)
        ck_error(c, f->pos, "function '%s' has %d parameters; at most %d are supported: pass "
              "some of them in arrays", f->name, f->nparams, SL_MAX_FUNC_PARAMS);
    c->func = f;
    c->func_base = c->nsyms;
    scope_mark saved = push_scope(c);
    for (int i = 0; i < f->nparams; i++)
        declare(c, f->params[i]);
    check_stmt(c, f->body);
    pop_scope(c, saved);
    f->needs_ret_flag = needs_ret_flag(f->body);
    if (f->ret != SL_TYPE_VOID) {
        int count = 0;
        if (!count_returns(f->body, &count))
            ck_error(c, f->pos, "non-void function '%s' has no 'return' statement", f->name);
    }
}

static void check_function(checker *c, sl_func *f)
{
    c->nsyms = c->scope_start = 0;
    c->nvfuncs = c->vfuncs_start = 0;
    check_function_body(c, f);
    c->func = NULL;
    c->func_base = 0;
}

/* Puts nested function f in scope (false: a redefinition, reported). */
static bool declare_nested(checker *c, sl_func *f)
{
    f->depth = c->depth;
    for (int i = c->vfuncs_start; i < c->nvfuncs; i++) {
        sl_func *g = c->vfuncs[i];
        if (strcmp(g->name, f->name) == 0 && same_params(f, g) && f->ret == g->ret) {
            ck_error(c, f->pos, "redefinition of function '%s'", f->name);
            sl_diag_note(c->diag, c->vfuncs[i]->pos, "previous definition is here");
            return false;
        }
    }
    sl_list_push(c->arena, (void ***)&c->vfuncs, &c->nvfuncs, &c->vfuncs_cap, f);
    f->declared = true;
    return true;
}

/* A function defined inside a function or the shader body: callable from
 * its definition to the end of the enclosing block (its own body
 * included, so that recursion is reported as such), seeing the enclosing
 * variables through 'extern' only. The overloads of one name defined in
 * one block (block->list from index on) come into scope together, at the
 * first of them, so that each body may call the others (a point-returning
 * helper calling the void one with output parameters, whichever comes
 * first); code outside the group calls them once all are defined
 * (ck_check_call). */
static void check_nested_function(checker *c, sl_func *f, const sl_node *block, int index)
{
    if (!f->declared) {
        if (!declare_nested(c, f))
            return;
        for (int i = index + 1; block && i < block->nlist; i++) {
            sl_func *g = block->list[i]->kind == SL_N_FUNC ? block->list[i]->func : NULL;
            if (g && !g->declared && strcmp(g->name, f->name) == 0 && !declare_nested(c, g))
                g->declared = true;      /* reported; its body is still checked */
        }
    }
    sl_func *saved_func = c->func;
    int saved_base = c->func_base;
    sl_node **saved_loops = c->loops;           /* break cannot leave a function */
    int saved_nloops = c->nloops, saved_cap = c->loops_cap;
    c->loops = NULL;
    c->nloops = c->loops_cap = 0;
    check_function_body(c, f);
    f->defined = true;
    c->loops = saved_loops;
    c->nloops = saved_nloops;
    c->loops_cap = saved_cap;
    c->func = saved_func;
    c->func_base = saved_base;
}

/* Depth-first search for a cycle through f; reports the chain. */
static bool find_cycle(checker *c, sl_func *f, sl_func **path, int depth)
{
    if (f->mark == 2)
        return false;
    path[depth] = f;
    if (f->mark == 1) {
        int start = 0;
        while (path[start] != f)
            start++;
        char chain[512] = "";
        for (int i = start; i <= depth; i++) {
            size_t len = strlen(chain);
            snprintf(chain + len, sizeof chain - len, "%s%s", i > start ? " -> " : "",
                     path[i]->name);
        }
        ck_error(c, f->pos, "recursion is not supported: %s", chain);
        return true;
    }
    f->mark = 1;
    for (int i = 0; i < f->ncalls; i++)
        if (find_cycle(c, f->calls[i], path, depth + 1))
            return true;
    f->mark = 2;
    return false;
}

static void check_recursion(checker *c)
{
    sl_func **path = sl_arena_alloc(c->arena, (size_t)(c->nallfuncs + 2) * sizeof *path);
    for (int i = 0; i < c->nallfuncs; i++) {
        if (find_cycle(c, c->allfuncs[i], path, 0)) {
            for (int j = 0; j < c->nallfuncs; j++)
                c->allfuncs[j]->mark = 2;
            return;
        }
    }
}

/* A function of the file and its place in it, sorted by signature. */
typedef struct func_at {
    const sl_func *f;
    int index;
} func_at;

/* Name, parameters (type, output), return type, then place in the file. */
static int compare_signature(const void *pa, const void *pb)
{
    const func_at *a = pa, *b = pb;
    int d = strcmp(a->f->name, b->f->name);
    if (d) return d;
    if (a->f->nparams != b->f->nparams) return a->f->nparams < b->f->nparams ? -1 : 1;
    for (int i = 0; i < a->f->nparams; i++) {
        const sl_sym *p = a->f->params[i], *q = b->f->params[i];
        if (p->ty != q->ty) return p->ty < q->ty ? -1 : 1;
        if (p->output != q->output) return p->output ? 1 : -1;
    }
    if (a->f->ret != b->f->ret) return a->f->ret < b->f->ret ? -1 : 1;
    return a->index < b->index ? -1 : a->index > b->index;
}

/* first[i]: the earliest function of the file with the name, parameters
 * and return type of function i (i itself when none comes before it).
 * Sorting by signature makes it O(n log n) in the file's functions (a
 * scan of the earlier ones for each took 37 s for 80,000 functions). */
static int *first_definitions(checker *c)
{
    int n = c->file->nfuncs;
    int *first = sl_arena_alloc(c->arena, (size_t)(n ? n : 1) * sizeof *first);
    func_at *by_sig = sl_arena_alloc(c->arena, (size_t)(n ? n : 1) * sizeof *by_sig);
    for (int i = 0; i < n; i++)
        by_sig[i] = (func_at){c->file->funcs[i], i};
    qsort(by_sig, (size_t)n, sizeof *by_sig, compare_signature);
    for (int k = 0, start = 0; k < n; k++) {
        const sl_func *f = by_sig[k].f, *g = by_sig[start].f;
        if (strcmp(f->name, g->name) != 0 || !same_params(f, g) || f->ret != g->ret)
            start = k;
        first[by_sig[k].index] = by_sig[start].index;
    }
    return first;
}

/* Reports function i when an earlier one (first) has its signature. */
static void check_duplicate(checker *c, int i, int first)
{
    if (first == i) return;
    ck_error(c, c->file->funcs[i]->pos, "redefinition of function '%s'", c->file->funcs[i]->name);
    sl_diag_note(c->diag, c->file->funcs[first]->pos, "previous definition is here");
}

/* Does position a come before b (same file, or the main file first)? */
static bool before(sl_pos a, sl_pos b)
{
    if (a.file && b.file && strcmp(a.file, b.file) != 0)
        return false;
    return a.line < b.line || (a.line == b.line && a.col < b.col);
}

static void make_globals(checker *c)
{
    for (int g = 0; g < SL_G__COUNT; g++) {
        sl_sym *s = sl_arena_alloc(c->arena, sizeof *s);
        s->name = sl_global_name((sl_global)g);
        s->ty = sl_global_type((sl_global)g);
        s->kind = SL_SYM_GLOBAL;
        s->global = g;
        s->writable = sl_global_writable((sl_global)g) ||
                      (c->file->kind == SL_SHADER_LIGHT && (g == SL_G_Cl || g == SL_G_L));
        s->slot = sl_global_slot((sl_global)g);
        c->globals[g] = s;
    }
    c->pi = sl_arena_alloc(c->arena, sizeof *c->pi);
    c->pi->name = "PI";
    c->pi->ty = SL_TYPE_FLOAT;
    c->pi->kind = SL_SYM_CONST;
    c->pi->value = M_PI;
    c->pi->slot = -1;
    c->ncomps = sl_arena_alloc(c->arena, sizeof *c->ncomps);
    *c->ncomps = *c->pi;
    c->ncomps->name = "ncomps";
    c->ncomps->value = 3;
    c->dtime = sl_arena_alloc(c->arena, sizeof *c->dtime);
    *c->dtime = *c->pi;
    c->dtime->name = "dtime";
    c->dtime->value = 0;
}

static void check_shader(checker *c)
{
    sl_ast_file *f = c->file;
    c->nsyms = c->scope_start = c->func_base = 0;
    c->nvfuncs = c->vfuncs_start = 0;
    c->func = NULL;
    for (int i = 0; i < f->nparams; i++) {
        sl_node *v = f->params[i];
        check_init(c, v, v->sym);
        declare(c, v->sym);
    }
    if (f->body) {
        check_stmt(c, f->body);
        f->needs_ret_flag = needs_ret_flag(f->body);
    }
}

bool sl_check(sl_ast_file *file, sl_arena *arena, const atomic_int *cancel, sl_diag *diag)
{
    checker c = { .arena = arena, .diag = diag, .file = file };
    int errors = sl_diag_error_count(diag);
    make_globals(&c);
    index_funcs(&c);
    /* definitions in source order, so that messages come in that order */
    bool shader_done = !file->has_shader;
    const int *first = first_definitions(&c);
    for (int i = 0; i < file->nfuncs && !sl_diag_full(diag); i++) {
        if (cancel && atomic_load_explicit(cancel, memory_order_relaxed)) {
            sl_diag_error(diag, file->funcs[i]->pos, "interrupted (SIGINT/SIGTERM) while "
                          "compiling");
            return false;
        }
        if (!shader_done && before(file->pos, file->funcs[i]->pos)) {
            check_shader(&c);
            shader_done = true;
        }
        check_duplicate(&c, i, first[i]);
        check_function(&c, file->funcs[i]);
    }
    if (!shader_done)
        check_shader(&c);
    check_recursion(&c);
    return sl_diag_error_count(diag) == errors;
}

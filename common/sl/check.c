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
 */
#include "sl/check.h"
#include "sl/builtins.h"
#include "sl/lexer.h"
#include "sl/strmatch.h"
#include "tex/tex.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct checker {
    sl_arena *arena;
    sl_diag *diag;
    sl_ast_file *file;
    sl_sym *globals[SL_G__COUNT];
    sl_sym *pi;
    sl_sym *ncomps, *dtime;   /* RI Spec 3.2 §13: 3 color components; no motion blur */
    sl_sym **syms;                 /* scope stack */
    int nsyms, syms_cap;
    int scope_start;               /* first sym of the innermost scope */
    int func_base;                 /* first sym of the current function */
    sl_func **vfuncs;              /* nested functions in scope, innermost last */
    int nvfuncs, vfuncs_cap;
    int vfuncs_start;              /* first of the innermost scope */
    int depth;                     /* block depth */
    sl_func **allfuncs;            /* every function, nested ones too */
    int nallfuncs, allfuncs_cap;
    sl_func *func;                 /* function being checked (NULL: shader) */
    sl_node **loops;
    int nloops, loops_cap;
} checker;

static sl_ty check_expr(checker *c, sl_node **np, sl_ty hint);
static void check_stmt(checker *c, sl_node *n);

static void error(checker *c, sl_pos pos, const char *fmt, ...) SL_PRINTF(3, 4);
static void error(checker *c, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(c->diag, SL_DIAG_ERROR, pos, fmt, ap);
    va_end(ap);
}

int sl_space_find(const char *name)
{
    static const char *const names[SL_SPACE__COUNT] = {
        [SL_SPACE_CURRENT] = "current", [SL_SPACE_WORLD] = "world",
        [SL_SPACE_OBJECT] = "object", [SL_SPACE_SHADER] = "shader",
        [SL_SPACE_CAMERA] = "camera",
    };
    for (int i = 0; i < SL_SPACE__COUNT; i++)
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
static sl_sym *lookup(checker *c, const char *name)
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
            error(c, sym->pos, "redefinition of '%s'", sym->name);
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

enum { MAX_OVERLOADS = 32 };

/* The user functions `name` may call here, the overloads: nested ones in
 * scope (innermost first), then those at file level. Returns how many
 * (at most max are stored). */
static int find_funcs(checker *c, const char *name, sl_func **out, int max)
{
    int n = 0;
    for (int i = c->nvfuncs - 1; i >= 0; i--)
        if (strcmp(c->vfuncs[i]->name, name) == 0 && n < max)
            out[n++] = c->vfuncs[i];
    for (int i = 0; i < c->file->nfuncs; i++)
        if (strcmp(c->file->funcs[i]->name, name) == 0 && n < max)
            out[n++] = c->file->funcs[i];
    return n;
}

static sl_func *find_func(checker *c, const char *name)
{
    sl_func *f;
    return find_funcs(c, name, &f, 1) ? f : NULL;
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
static void func_signature(const sl_func *f, char *buf, size_t size)
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

static bool can_convert(sl_ty have, sl_ty want)
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
    if (!e || !sl_ty_is_list(e->ty))
        return;
    e->ty = want;
    switch (e->kind) {
    case SL_N_CAST: e->cast_ty = want; break;
    case SL_N_UNARY: retype_list(e->a, want); break;
    case SL_N_BINARY: retype_list(e->a, want); retype_list(e->b, want); break;
    case SL_N_COND: retype_list(e->b, want); retype_list(e->c, want); break;
    default: break;
    }
}

/* Wraps *np in a conversion to `want` (the caller checked can_convert). */
static void wrap_conv(checker *c, sl_node **np, sl_ty want)
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
    error(c, e->pos, "cannot tell the type of this list of %d values here; put a type in "
                     "front, as in '%s (...)'", sl_ty_slots(e->ty),
          e->ty == SL_TY_LIST3 ? "point" : "matrix");
    return e->ty = SL_TY_ERROR;
}

static void check_cond(checker *c, sl_node **np)
{
    sl_ty ty = check_expr(c, np, SL_TY_BOOL);
    if (ty == SL_TY_BOOL || ty == SL_TY_ERROR)
        return;
    if (ty == SL_TYPE_FLOAT) {
        wrap_conv(c, np, SL_TY_BOOL);
        return;
    }
    error(c, (*np)->pos, "a value of type '%s' cannot be used as a condition",
          sl_ty_name(ty));
    (*np)->ty = SL_TY_ERROR;
}

/* ---------------------------------------------------------------------- */
/* expressions                                                             */
/* ---------------------------------------------------------------------- */

static sl_ty set_ty(sl_node *n, sl_ty ty)
{
    n->ty = ty;
    return ty;
}

static sl_ty check_ident(checker *c, sl_node *n)
{
    sl_sym *s = lookup(c, n->name);
    if (!s) {
        sl_sym *outer = lookup_enclosing(c, n->name);
        if (outer)
            error(c, n->pos, "'%s' belongs to an enclosing scope; declare it 'extern %s %s;' "
                             "in function '%s' to use it here", n->name, sl_ty_name(outer->ty),
                  n->name, c->func->name);
        else if (find_func(c, n->name) || sl_builtin_find(n->name, &(int){ 0 }))
            error(c, n->pos, "'%s' is a function; call it with '(...)'", n->name);
        else
            error(c, n->pos, "use of undeclared identifier '%s'", n->name);
        return set_ty(n, SL_TY_ERROR);
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
    return set_ty(n, s->ty);
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
    error(c, n->pos, "invalid operands to binary '%s' ('%s' and '%s')",
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
    error(c, n->pos, "invalid operands to binary '%s' ('%s' and '%s')",
          sl_token_kind_spelling(n->op), sl_ty_name(a), sl_ty_name(b));
    return SL_TY_ERROR;
}

static sl_ty check_binary(checker *c, sl_node *n)
{
    int op = n->op;
    if (op == SL_TOK_AND || op == SL_TOK_OR) {
        check_cond(c, &n->a);
        check_cond(c, &n->b);
        return set_ty(n, SL_TY_BOOL);
    }
    sl_ty a = check_expr(c, &n->a, SL_TYPE_VOID);
    sl_ty b = check_expr(c, &n->b, SL_TYPE_VOID);
    if (a == SL_TY_ERROR || b == SL_TY_ERROR)
        return set_ty(n, SL_TY_ERROR);
    if (sl_ty_is_list(a) || sl_ty_is_list(b)) {
        /* a typed operand types the list: P + (0, 0, 1) */
        if (sl_ty_is_list(a) && can_convert(a, b) && !sl_ty_is_list(b))
            wrap_conv(c, &n->a, a = b);
        else if (sl_ty_is_list(b) && can_convert(b, a) && !sl_ty_is_list(a))
            wrap_conv(c, &n->b, b = a);
        bool arith = op == SL_TOK_PLUS || op == SL_TOK_MINUS || op == SL_TOK_STAR ||
                     op == SL_TOK_SLASH;
        sl_ty list = sl_ty_is_list(a) ? a : b, other = sl_ty_is_list(a) ? b : a;
        /* lists among themselves and with floats stay untyped: (1, 2, 3) * 2 */
        if (list == SL_TY_LIST3 && arith && (other == list || other == SL_TYPE_FLOAT))
            return set_ty(n, list);
        if (sl_ty_is_list(a) && sl_ty_is_list(b) && (op == SL_TOK_EQ || op == SL_TOK_NE) &&
            a == b)
            return set_ty(n, SL_TY_BOOL);
        if (settle(c, n->a) == SL_TY_ERROR || settle(c, n->b) == SL_TY_ERROR)
            return set_ty(n, SL_TY_ERROR);
    }
    switch (op) {
    case SL_TOK_PLUS: case SL_TOK_MINUS: case SL_TOK_STAR: case SL_TOK_SLASH:
        return set_ty(n, arith_type(c, n, a, b));
    case SL_TOK_DOT:
        if ((sl_ty_is_spatial(a) && sl_ty_is_spatial(b)) ||
            (a == SL_TYPE_COLOR && b == SL_TYPE_COLOR))
            return set_ty(n, SL_TYPE_FLOAT);
        break;
    case SL_TOK_CARET:
        if (sl_ty_is_spatial(a) && sl_ty_is_spatial(b))
            return set_ty(n, SL_TYPE_VECTOR);
        break;
    default:
        return set_ty(n, compare_type(c, n, a, b));
    }
    error(c, n->pos, "invalid operands to binary '%s' ('%s' and '%s')",
          sl_token_kind_spelling(op), sl_ty_name(a), sl_ty_name(b));
    return set_ty(n, SL_TY_ERROR);
}

static sl_ty check_unary(checker *c, sl_node *n)
{
    if (n->op == SL_TOK_NOT) {
        check_cond(c, &n->a);
        return set_ty(n, SL_TY_BOOL);
    }
    sl_ty a = check_expr(c, &n->a, SL_TYPE_VOID);
    if (a == SL_TY_ERROR || a == SL_TYPE_FLOAT || sl_ty_is_triple(a) || a == SL_TYPE_MATRIX ||
        sl_ty_is_list(a))
        return set_ty(n, a);
    error(c, n->pos, "invalid argument type '%s' to unary '-'", sl_ty_name(a));
    return set_ty(n, SL_TY_ERROR);
}

/* The common type of the two results of ?: */
static sl_ty unify(sl_ty a, sl_ty b)
{
    if (a == b)
        return a;
    if (sl_ty_is_list(a) && !sl_ty_is_list(b) && can_convert(a, b))
        return b;
    if (sl_ty_is_list(b) && !sl_ty_is_list(a) && can_convert(b, a))
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
    sl_ty a = check_expr(c, &n->b, hint);
    sl_ty b = check_expr(c, &n->c, hint);
    if (a == SL_TY_ERROR || b == SL_TY_ERROR)
        return set_ty(n, SL_TY_ERROR);
    sl_ty ty = unify(a, b);
    if (ty == SL_TY_ERROR || ty == SL_TYPE_VOID) {
        error(c, n->pos, "incompatible operand types ('%s' and '%s') in conditional expression",
              sl_ty_name(a), sl_ty_name(b));
        return set_ty(n, SL_TY_ERROR);
    }
    wrap_conv(c, &n->b, ty);
    wrap_conv(c, &n->c, ty);
    return set_ty(n, ty);
}

static bool check_assignable(checker *c, sl_node *lhs, const char *what)
{
    sl_sym *s = lhs->sym;
    if (!s || s->writable)
        return true;
    if (s->kind == SL_SYM_GLOBAL)
        error(c, lhs->pos, "cannot %s '%s': it is a read-only global variable", what, s->name);
    else if (s->kind == SL_SYM_CONST)
        error(c, lhs->pos, "cannot %s '%s': it is a constant", what, s->name);
    else
        error(c, lhs->pos, "cannot %s parameter '%s': it is not declared 'output'", what,
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
        error(c, n->pos, "a channel index after a string is only allowed on the texture name "
                         "of texture(), environment() or bump()");
        return set_ty(n, SL_TY_ERROR);
    }
    sl_ty at = check_ident(c, n->a);
    sl_ty it = n->num != 0 ? n->b->ty : check_expr(c, &n->b, SL_TYPE_FLOAT);
    if (at == SL_TY_ERROR || it == SL_TY_ERROR)
        return set_ty(n, SL_TY_ERROR);
    if (!sl_ty_is_array(at)) {
        error(c, n->pos, "'%s' is not an array (it is a '%s')", n->a->name, sl_ty_name(at));
        return set_ty(n, SL_TY_ERROR);
    }
    if (it != SL_TYPE_FLOAT) {
        error(c, n->b->pos, "an array index must be a float, not '%s'", sl_ty_name(it));
        return set_ty(n, SL_TY_ERROR);
    }
    double k;
    int len = sl_ty_len(at);
    if (len > 0 && const_index(n->b, &k) && !(k >= 0 && k < len)) {
        error(c, n->b->pos, "array index %g is out of range for '%s' (%s: 0 to %d)", k,
              n->a->name, sl_ty_name(at), len - 1);
        return set_ty(n, SL_TY_ERROR);
    }
    return set_ty(n, sl_ty_elem(at));
}

static sl_ty check_assign(checker *c, sl_node *n)
{
    sl_node *lhs = n->a;
    if (lhs->kind != SL_N_IDENT && lhs->kind != SL_N_INDEX)
        return set_ty(n, SL_TY_ERROR);
    bool element = lhs->kind == SL_N_INDEX;
    sl_node *var = element ? lhs->a : lhs;
    sl_ty lt = element ? check_index(c, lhs) : check_ident(c, lhs);
    if (lt == SL_TY_ERROR) {
        check_expr(c, &n->b, SL_TYPE_VOID);
        return set_ty(n, SL_TY_ERROR);
    }
    check_assignable(c, var, "assign to");
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
    sl_ty rt = check_expr(c, &n->b, lt);
    if (!can_convert(rt, lt)) {
        error(c, n->b->pos, "cannot assign a value of type '%s' to '%s%s' (%s)",
              sl_ty_name(rt), var->name, element ? "[...]" : "", sl_ty_name(lt));
        return set_ty(n, SL_TY_ERROR);
    }
    wrap_conv(c, &n->b, lt);
    return set_ty(n, lt);
}

/* A constant string argument naming a space: known? */
static void check_space_arg(checker *c, const sl_node *arg)
{
    if (arg->kind == SL_N_STR && sl_space_find(arg->name) < 0)
        error(c, arg->pos, "unknown space '%s' (known: \"current\", \"world\", "
                           "\"object\", \"shader\", \"camera\")", arg->name);
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
        error(c, arg->pos, "filterstep() parameters must be constant strings");
        return;
    }
    if (value) {
        for (size_t k = 0; k < sizeof filters / sizeof filters[0]; k++)
            if (strcmp(arg->name, filters[k]) == 0)
                return;
        error(c, arg->pos, "unknown filter '%s' (known: \"box\", \"triangle\", "
              "\"catmull-rom\", \"gaussian\", \"sinc\", \"disk\", \"bessel\")", arg->name);
        return;
    }
    bool takes_string = i + 1 < n->nlist && n->list[i + 1]->ty == SL_TYPE_STRING;
    if (strcmp(arg->name, takes_string ? "filter" : "width") != 0)
        error(c, arg->pos, "unknown filterstep() parameter '%s' (known: \"width\" with a "
              "float, \"filter\" with a name)", arg->name);
}

/* shadow(name, P, "blur", 0.01, ...): the shadow map parameters of RI Spec
 * 3.2 §15.7, accepted and ignored (the traced shadow ray is sharp). */
static void check_shadow_param(checker *c, const sl_node *arg)
{
    static const char *const names[] = { "samples", "blur", "bias", "width", "swidth",
                                         "twidth" };
    if (arg->kind == SL_N_STR)
        for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
            if (strcmp(arg->name, names[k]) == 0)
                return;
    error(c, arg->pos, "unknown shadow() parameter%s%s%s (known: \"samples\", \"blur\", "
          "\"bias\", \"width\", \"swidth\", \"twidth\", each with a float; they are "
          "accepted and ignored)", arg->kind == SL_N_STR ? " '" : "",
          arg->kind == SL_N_STR ? arg->name : "", arg->kind == SL_N_STR ? "'" : "");
}

/* A color space argument (ctransform): a constant string naming one. */
static void check_color_space_arg(checker *c, const sl_node *arg)
{
    if (arg->kind != SL_N_STR)
        error(c, arg->pos, "the color space of ctransform() must be a constant string");
    else if (sl_color_space_find(arg->name) < 0)
        error(c, arg->pos, "unknown color space '%s' (known: " SL_COLOR_SPACE_NAMES ")",
              arg->name);
}

static sl_ty check_builtin_call(checker *c, sl_node *n, const sl_ty *args, sl_ty hint)
{
    sl_ty want[8], result;
    const sl_builtin *b = sl_builtin_resolve(n->name, args, n->nlist, hint, want, &result);
    if (!b) {
        char list[256] = "";
        for (int i = 0; i < n->nlist; i++) {
            size_t len = strlen(list);
            snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "",
                     sl_ty_name(args[i]));
        }
        error(c, n->pos, "no matching function for call to '%s' with arguments (%s)",
              n->name, list);
        char cands[512];
        sl_builtin_candidates(n->name, cands, sizeof cands);
        sl_diag_note(c->diag, n->pos, "candidates are: %s", cands);
        return set_ty(n, SL_TY_ERROR);
    }
    n->builtin = b;
    if (b->lower == SL_LOWER_EMITTER && c->file->kind != SL_SHADER_LIGHT) {
        error(c, n->pos, "'%s' is only allowed in light shaders", b->op == SL_OP_END &&
              b->k == 0 ? "illuminate" : "solar");
        return set_ty(n, SL_TY_ERROR);
    }
    const char *sig = b->sig + 2;
    for (int i = 0; i < n->nlist; i++) {
        if (sig[i] == 'o' || sig[i] == 'O' || sig[i] == 'M' || sig[i] == 'w' ||
            sig[i] == 'V') {
            sl_node *a = n->list[i];
            if (a->kind != SL_N_IDENT)
                error(c, a->pos, "argument %d of '%s' must be a variable", i + 1, n->name);
            else
                check_assignable(c, a, "modify");
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
                error(c, n->list[0]->pos, "malformed regular expression '%s' (at character "
                      "%d)", n->list[0]->name, bad);
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_RAY) {
            if (i > 0)
                check_shadow_param(c, n->list[i]);
            else
                wrap_conv(c, &n->list[i], want[i]);
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_MESSAGE) {
            wrap_conv(c, &n->list[i], want[i]);
            continue;
        }
        if (sig[i] == 's' && b->lower == SL_LOWER_CTRANSFORM)
            check_color_space_arg(c, n->list[i]);
        else if (sig[i] == 's')
            check_space_arg(c, n->list[i]);
        wrap_conv(c, &n->list[i], want[i]);
    }
    return set_ty(n, result);
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

static sl_ty check_user_call(checker *c, sl_node *n, sl_func *f, const sl_ty *args)
{
    n->func = f;
    add_call_edge(c, f);
    if (n->nlist != f->nparams) {
        error(c, n->pos, "function '%s' takes %d argument%s, but %d %s given", f->name,
              f->nparams, f->nparams == 1 ? "" : "s", n->nlist, n->nlist == 1 ? "was" : "were");
        sl_diag_note(c->diag, f->pos, "'%s' declared here", f->name);
        return set_ty(n, SL_TY_ERROR);
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
                error(c, n->list[i]->pos, "argument %d of '%s': cannot pass a '%s' to a "
                                          "parameter of type '%s'", i + 1, f->name,
                      sl_ty_name(args[i]), sl_ty_name(p->ty));
                ok = false;
            } else if (p->output) {
                check_assignable(c, n->list[i], "modify");
            }
            continue;
        }
        if (p->output) {
            sl_node *a = n->list[i];
            if (a->kind != SL_N_IDENT) {
                error(c, a->pos, "argument %d of '%s' must be a variable (the parameter "
                                 "is 'output')", i + 1, f->name);
                ok = false;
            } else if (!(args[i] == p->ty ||
                         (sl_ty_is_spatial(args[i]) && sl_ty_is_spatial(p->ty)))) {
                error(c, a->pos, "argument %d of '%s': cannot pass a '%s' variable to an "
                                 "output parameter of type '%s'", i + 1, f->name,
                      sl_ty_name(args[i]), sl_ty_name(p->ty));
                ok = false;
            } else {
                check_assignable(c, a, "modify");
            }
            continue;
        }
        if (!can_convert(args[i], p->ty)) {
            error(c, n->list[i]->pos, "argument %d of '%s': cannot convert '%s' to '%s'",
                  i + 1, f->name, sl_ty_name(args[i]), sl_ty_name(p->ty));
            ok = false;
            continue;
        }
        wrap_conv(c, &n->list[i], p->ty);
    }
    return set_ty(n, ok ? f->ret : SL_TY_ERROR);
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
        return !p->output && can_convert(have, p->ty) ? 0 : -1;
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
    return can_convert(f->ret, hint) && f->ret != SL_TYPE_VOID;
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
        error(c, n->pos, "call to '%s' is ambiguous", n->name);
        for (int i = 0; i < nbest; i++) {
            char sig[256];
            func_signature(best[i], sig, sizeof sig);
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
    error(c, n->pos, "no matching function for call to '%s' with arguments (%s)", n->name,
          list);
    for (int i = 0; i < ncands; i++) {
        char sig[256];
        func_signature(cands[i], sig, sizeof sig);
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
        check_expr(c, &n->list[i], SL_TYPE_VOID);
    if (n->nlist != 1 || !sl_ty_is_array(n->list[0]->ty) ||
        n->list[0]->kind != SL_N_IDENT) {
        if (n->nlist != 1 || n->list[0]->ty != SL_TY_ERROR)
            error(c, n->pos, "arraylength() takes one array variable");
        return set_ty(n, SL_TY_ERROR);
    }
    return set_ty(n, SL_TYPE_FLOAT);
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
        check_expr(c, &n->list[i], i == 0 ? SL_TYPE_VOID : SL_TYPE_FLOAT);
    const sl_node *a = n->nlist > 0 ? n->list[0] : NULL;
    bool ok = a && a->kind == SL_N_IDENT && a->sym && sl_ty_is_array(a->ty) &&
              (a->sym->resizable || (a->sym->kind == SL_SYM_FPARAM && sl_ty_len(a->sym->ty) == 0));
    if (a && a->ty == SL_TY_ERROR)
        return set_ty(n, SL_TY_ERROR);
    if (!ok || n->nlist != want) {
        error(c, n->pos, "%s() takes a resizable array (a local declared without size or "
              "initializer, as 'float a[];')%s", resizable_ops[op],
              op == SL_RESIZE_POP ? "" : op == SL_RESIZE_PUSH ? " and a value"
                                                              : " and a number of elements");
        return set_ty(n, SL_TY_ERROR);
    }
    n->op = op;
    sl_ty elem = sl_ty_elem(a->ty);
    if (want == 2) {
        sl_ty to = op == SL_RESIZE_PUSH ? elem : SL_TYPE_FLOAT;
        sl_ty t = n->list[1]->ty;
        if (t == SL_TY_ERROR)
            return set_ty(n, SL_TY_ERROR);
        if (!can_convert(t, to)) {
            error(c, n->list[1]->pos, "argument 2 of '%s' must be a '%s', not a '%s'",
                  resizable_ops[op], sl_ty_name(to), sl_ty_name(t));
            return set_ty(n, SL_TY_ERROR);
        }
        wrap_conv(c, &n->list[1], to);
    }
    return set_ty(n, op == SL_RESIZE_POP ? elem : SL_TYPE_VOID);
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
            error(c, n->list[0]->pos, "unknown spline basis '%s' (known: \"catmull-rom\", "
                  "\"bezier\", \"b-spline\", \"hermite\", \"linear\", \"constant\")",
                  n->list[0]->name);
            bad = true;
        }
        check_expr(c, &n->list[0], SL_TYPE_STRING);
        first = 1;
    }
    for (int i = first; i < n->nlist; i++)
        bad |= check_expr(c, &n->list[i], i == first ? SL_TYPE_FLOAT
                          : sl_ty_is_triple(hint) ? hint : SL_TYPE_VOID) == SL_TY_ERROR;
    if (bad)
        return set_ty(n, SL_TY_ERROR);
    if (first == 0 && n->nlist > 0 && n->list[0]->ty == SL_TYPE_STRING) {
        error(c, n->list[0]->pos, "the basis of spline() must be a constant string");
        return set_ty(n, SL_TY_ERROR);
    }
    int nknots = n->nlist - first - 1;
    if (nknots < 1 || n->list[first]->ty != SL_TYPE_FLOAT) {
        error(c, n->pos, "spline() takes [basis,] a float parameter and the knots "
                         "(4 or more values, or an array)");
        return set_ty(n, SL_TY_ERROR);
    }
    const sl_spline_basis *b = sl_spline_basis_get(basis);
    sl_node *k0 = n->list[first + 1];
    sl_ty elem;
    if (nknots == 1 && sl_ty_is_array(k0->ty)) {
        elem = sl_ty_elem(k0->ty);
        nknots = sl_ty_len(k0->ty);
        if (k0->kind != SL_N_IDENT) {
            error(c, k0->pos, "the knots of spline() must be an array variable");
            return set_ty(n, SL_TY_ERROR);
        }
        if (elem == SL_TYPE_MATRIX || elem == SL_TYPE_STRING) {
            error(c, k0->pos, "spline() interpolates floats and triples, not '%s'",
                  sl_ty_name(k0->ty));
            return set_ty(n, SL_TY_ERROR);
        }
    } else {
        elem = k0->ty == SL_TY_LIST3 ? (sl_ty_is_triple(hint) ? hint : SL_TYPE_POINT) : k0->ty;
        if (elem != SL_TYPE_FLOAT && !sl_ty_is_triple(elem)) {
            error(c, k0->pos, "spline() interpolates floats and triples, not '%s'",
                  sl_ty_name(k0->ty));
            return set_ty(n, SL_TY_ERROR);
        }
        for (int i = first + 1; i < n->nlist; i++) {
            sl_ty have = n->list[i]->ty;
            if (!can_convert(have, elem) || sl_ty_is_array(have) ||
                (elem == SL_TYPE_FLOAT && have != SL_TYPE_FLOAT)) {
                error(c, n->list[i]->pos, "knot %d of spline() is a '%s', the first a '%s'",
                      i - first, sl_ty_name(have), sl_ty_name(elem));
                return set_ty(n, SL_TY_ERROR);
            }
            wrap_conv(c, &n->list[i], elem);
        }
    }
    if (nknots && (nknots < 4 || (nknots - 4) % b->step != 0)) {
        error(c, n->pos, "a '%s' spline takes 4%s knots, not %d", b->name,
              b->step == 3 ? ", 7, 10, ..." : b->step == 2 ? ", 6, 8, ..." : " or more",
              nknots);
        return set_ty(n, SL_TY_ERROR);
    }
    int count;
    n->builtin = sl_builtin_find("spline", &count);
    n->op = basis;
    return set_ty(n, elem);
}

/* The conversions of a format string (RI Spec 3.2 §15.6): "%%", or "%"
 * flags [-+ 0], width, .precision and one of f e g d i (a float), p v n
 * (a point, vector or normal), c (a color), m (a matrix), s (a string).
 * Calls fn for each; returns the number of conversions, or -1 (reported)
 * for a malformed one. Shared with the code generator. */
int sl_format_walk(const char *fmt, void (*fn)(void *, const char *spec, size_t len, char conv,
                                              const char *lit, size_t litlen), void *arg)
{
    int count = 0;
    const char *lit = fmt;
    for (const char *p = fmt; *p; p++) {
        if (*p != '%')
            continue;
        if (p[1] == '%') {              /* the literal up to and with one '%' */
            if (fn)
                fn(arg, NULL, 0, '%', lit, (size_t)(p + 1 - lit));
            lit = ++p + 1;
            continue;
        }
        const char *q = p + 1;
        while (*q && strchr("-+ 0", *q))
            q++;
        while (*q >= '0' && *q <= '9')
            q++;
        if (*q == '.')
            for (q++; *q >= '0' && *q <= '9'; q++)
                ;
        if (!*q || !strchr("fegdipvncms", *q) || q - p > 20)
            return -1;
        if (fn)
            fn(arg, p, (size_t)(q - p), *q, lit, (size_t)(p - lit));
        count++;
        p = q;
        lit = q + 1;
    }
    if (fn && *lit)
        fn(arg, NULL, 0, 0, lit, strlen(lit));
    return count;
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
        bad |= check_expr(c, &n->list[i], SL_TYPE_VOID) == SL_TY_ERROR;
    if (bad)
        return set_ty(n, SL_TY_ERROR);
    if (b->op == SL_OP_SCAT) {
        for (int i = 0; i < n->nlist; i++) {
            if (n->list[i]->ty != SL_TYPE_STRING) {
                error(c, n->list[i]->pos, "argument %d of concat() is a '%s', not a string",
                      i + 1, sl_ty_name(n->list[i]->ty));
                return set_ty(n, SL_TY_ERROR);
            }
        }
        if (n->nlist == 0) {
            error(c, n->pos, "concat() takes one or more strings");
            return set_ty(n, SL_TY_ERROR);
        }
    } else {
        if (n->nlist == 0 || n->list[0]->kind != SL_N_STR) {
            error(c, n->pos, "%s() needs a constant format string first", n->name);
            return set_ty(n, SL_TY_ERROR);
        }
        format_check f = { .n = 0 };
        int count = sl_format_walk(n->list[0]->name, collect_conv, &f);
        if (count < 0) {
            error(c, n->list[0]->pos, "malformed conversion in the format string (known: "
                  "%%f %%e %%g %%d %%i %%p %%v %%n %%c %%m %%s %%%%)");
            return set_ty(n, SL_TY_ERROR);
        }
        if (count != n->nlist - 1 || count > 64) {
            error(c, n->pos, "the format string of %s() has %d conversions, but %d values "
                  "follow it", n->name, count, n->nlist - 1);
            return set_ty(n, SL_TY_ERROR);
        }
        for (int i = 0; i < count; i++) {
            sl_ty ty = n->list[i + 1]->ty;
            char k = f.convs[i];
            bool ok = strchr("fegdi", k) ? ty == SL_TYPE_FLOAT
                    : strchr("pvn", k) ? sl_ty_is_spatial(ty)
                    : k == 'c' ? ty == SL_TYPE_COLOR
                    : k == 'm' ? ty == SL_TYPE_MATRIX : ty == SL_TYPE_STRING;
            if (!ok) {
                error(c, n->list[i + 1]->pos, "'%%%c' in the format string of %s() does not "
                      "take a '%s'", k, n->name, sl_ty_name(ty));
                return set_ty(n, SL_TY_ERROR);
            }
        }
    }
    n->builtin = b;
    return set_ty(n, b->op == SL_OP_SPRINT ? SL_TYPE_VOID : SL_TYPE_STRING);
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
static const struct { const char *name; char type; } texture_params[] = {
    { "blur", 'f' }, { "sblur", 'f' }, { "tblur", 'f' }, { "width", 'f' },
    { "swidth", 'f' }, { "twidth", 'f' }, { "fill", 'f' }, { "samples", 'f' },
    { "filter", 's' }, { "wrap", 'w' }, { "swrap", 'w' }, { "twrap", 'w' },
};
#define TEXTURE_PARAM_NAMES "\"blur\", \"sblur\", \"tblur\", \"width\", \"swidth\", " \
    "\"twidth\", \"fill\", \"samples\", \"filter\", \"wrap\", \"swrap\", \"twrap\""

static sl_ty check_texture_info(checker *c, sl_node *n)
{
    if (n->nlist != 3) {
        error(c, n->pos, "textureinfo() takes a texture name, the name of the datum and a "
                         "variable for it");
        return set_ty(n, SL_TY_ERROR);
    }
    bool bad = check_expr(c, &n->list[0], SL_TYPE_STRING) != SL_TYPE_STRING;
    sl_node *what = n->list[1], *var = n->list[2];
    check_expr(c, &n->list[1], SL_TYPE_STRING);
    if (what->kind != SL_N_STR) {
        error(c, what->pos, "the datum of textureinfo() must be a constant string "
                            "(\"resolution\", \"channels\", \"levels\" or \"type\")");
        return set_ty(n, SL_TY_ERROR);
    }
    int q = sl_texinfo_find(what->name);
    if (q < 0) {
        error(c, what->pos, "unknown textureinfo() datum '%s' (known: \"resolution\", "
                            "\"channels\", \"levels\", \"type\")", what->name);
        return set_ty(n, SL_TY_ERROR);
    }
    sl_ty want = q == SL_TEXINFO_RESOLUTION ? sl_ty_array(SL_TYPE_FLOAT, 2)
               : q == SL_TEXINFO_TYPE ? SL_TYPE_STRING : SL_TYPE_FLOAT;
    sl_ty have = check_expr(c, &n->list[2], SL_TYPE_VOID);
    if (bad || have == SL_TY_ERROR)
        return set_ty(n, SL_TY_ERROR);
    if (var->kind != SL_N_IDENT || have != want) {
        error(c, var->pos, "textureinfo() writes \"%s\" into a variable of type '%s'",
              what->name, sl_ty_name(want));
        return set_ty(n, SL_TY_ERROR);
    }
    check_assignable(c, var, "modify");
    int count;
    n->builtin = sl_builtin_find("textureinfo", &count);
    n->op = SL_TEX_INFO;
    n->a = n->list[0];
    n->num = q;
    return set_ty(n, SL_TYPE_FLOAT);
}

static sl_ty check_texture(checker *c, sl_node *n, sl_ty hint)
{
    int kind = strcmp(n->name, "texture") == 0 ? SL_TEX_TEXTURE
             : strcmp(n->name, "environment") == 0 ? SL_TEX_ENVIRONMENT
             : strcmp(n->name, "bump") == 0 ? SL_TEX_BUMP : SL_TEX_INFO;
    if (kind == SL_TEX_INFO)
        return check_texture_info(c, n);
    if (n->nlist < 1) {
        error(c, n->pos, "%s() takes a texture name first", n->name);
        return set_ty(n, SL_TY_ERROR);
    }
    bool bad = false;
    sl_node *first = n->list[0];
    n->a = first;
    n->b = NULL;
    sl_ty at = first->kind != SL_N_INDEX ? SL_TY_ERROR
             : first->a->kind == SL_N_STR ? SL_TYPE_STRING : check_ident(c, first->a);
    if (first->kind == SL_N_INDEX && first->a->kind == SL_N_IDENT && at == SL_TY_ERROR)
        return set_ty(n, SL_TY_ERROR);
    if (first->kind == SL_N_INDEX && at == SL_TYPE_STRING) {
        n->a = first->a;                 /* name[channel] */
        set_ty(n->a, SL_TYPE_STRING);
        bad |= check_expr(c, &first->b, SL_TYPE_FLOAT) != SL_TYPE_FLOAT;
        n->b = first->b;
        set_ty(first, SL_TYPE_STRING);
    } else if (check_expr(c, &n->list[0], SL_TYPE_STRING) != SL_TYPE_STRING) {
        if (n->list[0]->ty != SL_TY_ERROR)
            error(c, n->list[0]->pos, "the texture name of %s() must be a string, not '%s'",
                  n->name, sl_ty_name(n->list[0]->ty));
        return set_ty(n, SL_TY_ERROR);
    } else {
        n->a = n->list[0];
    }
    int npos = 0;
    while (1 + npos < n->nlist && n->list[1 + npos]->kind != SL_N_STR)
        npos++;
    bool ok_count = kind == SL_TEX_TEXTURE ? (npos == 0 || npos == 2 || npos == 8)
                  : kind == SL_TEX_ENVIRONMENT ? npos == 1 : (npos == 3 || npos == 5);
    if (!ok_count) {
        error(c, n->pos, "%s() takes %s after the texture name, then \"name\", value "
              "parameters; got %d value%s", n->name,
              kind == SL_TEX_TEXTURE ? "no coordinates (s and t), s and t, or four corners "
                                       "s1, t1, ..., s4, t4"
              : kind == SL_TEX_ENVIRONMENT ? "a direction"
              : "N, dPds and dPdt, optionally then s and t", npos, npos == 1 ? "" : "s");
        return set_ty(n, SL_TY_ERROR);
    }
    for (int i = 1; i <= npos; i++) {
        bool spatial = (kind == SL_TEX_ENVIRONMENT) || (kind == SL_TEX_BUMP && i <= 3);
        sl_ty want = spatial ? SL_TYPE_VECTOR : SL_TYPE_FLOAT;
        sl_ty have = check_expr(c, &n->list[i], want);
        if (have == SL_TY_ERROR) {
            bad = true;
            continue;
        }
        if (spatial ? !sl_ty_is_spatial(have) && !sl_ty_is_list(have) : have != SL_TYPE_FLOAT) {
            error(c, n->list[i]->pos, "argument %d of %s() must be a %s, not '%s'", i + 1,
                  n->name, spatial ? "point, vector or normal" : "float", sl_ty_name(have));
            bad = true;
            continue;
        }
        wrap_conv(c, &n->list[i], want);
    }
    for (int i = 1 + npos; i < n->nlist; i += 2) {
        sl_node *pn = n->list[i];
        check_expr(c, &n->list[i], SL_TYPE_STRING);
        size_t k = 0, nk = sizeof texture_params / sizeof texture_params[0];
        while (k < nk && strcmp(texture_params[k].name, pn->name) != 0)
            k++;
        if (pn->kind != SL_N_STR || k == nk) {
            error(c, pn->pos, "unknown %s() parameter '%s' (known: " TEXTURE_PARAM_NAMES ")",
                  n->name, pn->kind == SL_N_STR ? pn->name : "?");
            bad = true;
            continue;
        }
        if (i + 1 >= n->nlist) {
            error(c, pn->pos, "%s() parameter '%s' has no value", n->name, pn->name);
            bad = true;
            break;
        }
        char type = texture_params[k].type;
        sl_ty have = check_expr(c, &n->list[i + 1], type == 'f' ? SL_TYPE_FLOAT
                                                                : SL_TYPE_STRING);
        sl_node *v = n->list[i + 1];
        if (have == SL_TY_ERROR) {
            bad = true;
        } else if (type == 'f' && have != SL_TYPE_FLOAT) {
            error(c, v->pos, "%s() parameter '%s' takes a float, not '%s'", n->name, pn->name,
                  sl_ty_name(have));
            bad = true;
        } else if (type != 'f' && v->kind != SL_N_STR) {
            error(c, v->pos, "%s() parameter '%s' takes a constant string", n->name, pn->name);
            bad = true;
        } else if (type == 'w' && tex_wrap_find(v->name) < 0) {
            error(c, v->pos, "unknown wrap mode '%s' (known: \"periodic\", \"clamp\", "
                             "\"black\")", v->name);
            bad = true;
        }
    }
    if (bad)
        return set_ty(n, SL_TY_ERROR);
    int count;
    n->builtin = sl_builtin_find(kind == SL_TEX_BUMP ? "bump" : kind == SL_TEX_ENVIRONMENT
                                 ? "environment" : "texture", &count);
    n->op = kind;
    n->num = npos;
    if (kind == SL_TEX_BUMP)
        return set_ty(n, SL_TYPE_VECTOR);
    return set_ty(n, hint == SL_TYPE_COLOR ? SL_TYPE_COLOR : SL_TYPE_FLOAT);
}

static sl_ty check_call(checker *c, sl_node *n, sl_ty hint)
{
    sl_func *cands[MAX_OVERLOADS];
    int ncands = find_funcs(c, n->name, cands, MAX_OVERLOADS);
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
            check_expr(c, &n->list[i], SL_TYPE_VOID);
        if (strcmp(n->name, "atmosphere") == 0 || strcmp(n->name, "incident") == 0 ||
            strcmp(n->name, "opposite") == 0) {
            error(c, n->pos, "'%s' reads the values of a volume shader, and volume shaders "
                             "are not supported", n->name);
            return set_ty(n, SL_TY_ERROR);
        }
        if (strcmp(n->name, "Dtime") == 0) {
            error(c, n->pos, "'Dtime' is not supported: aafarm renders no motion blur, so "
                             "nothing changes with time (use 0)");
            return set_ty(n, SL_TY_ERROR);
        }
        if (strcmp(n->name, "getshader") == 0 || strcmp(n->name, "getshaders") == 0) {
            error(c, n->pos, "'%s' (RSL 2 co-shaders) is not supported: aafarm compiles "
                             "each shader on its own: put the co-shader's code in a function "
                             "of this shader (or #include it)", n->name);
            return set_ty(n, SL_TY_ERROR);
        }
        if (strcmp(n->name, "gather") == 0) {
            error(c, n->pos, "'gather' is not supported: shaders trace single rays with "
                             "trace(P, R) and shadow(name, P)");
            return set_ty(n, SL_TY_ERROR);
        }
        if (lookup(c, n->name))
            error(c, n->pos, "called object '%s' is not a function", n->name);
        else
            error(c, n->pos, "use of undeclared function '%s'", n->name);
        return set_ty(n, SL_TY_ERROR);
    }
    if (n->nlist > 8) {
        error(c, n->pos, "too many arguments in call to '%s'", n->name);
        return set_ty(n, SL_TY_ERROR);
    }
    sl_ty args[8];
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
        args[i] = check_expr(c, &n->list[i], h == SL_TY_ERROR ? SL_TYPE_VOID : h);
        bad |= args[i] == SL_TY_ERROR;
    }
    if (ncands == 1 && !builtin)     /* one function: its own, precise messages */
        return check_user_call(c, n, cands[0], args);
    if (bad)
        return set_ty(n, SL_TY_ERROR);
    if (ncands) {
        bool ambiguous;
        sl_func *f = resolve_user(c, n, cands, ncands, args, hint, &ambiguous);
        if (ambiguous)
            return set_ty(n, SL_TY_ERROR);
        if (f)
            return check_user_call(c, n, f, args);
    }
    sl_ty want[8], result;
    if (builtin && (!ncands || sl_builtin_resolve(n->name, args, n->nlist, hint, want, &result)))
        return check_builtin_call(c, n, args, hint);
    no_match(c, n, args, cands, ncands, builtin);
    return set_ty(n, SL_TY_ERROR);
}

/* (x, y, z) or 16 values without a type: a triple or matrix of the type
 * the context asks for (hint), else an untyped list for the context to
 * type later (RI Spec 3.2 §13: "the type of a parenthesised triple is
 * taken from its context"). */
static sl_ty check_untyped_list(checker *c, sl_node *n, sl_ty hint)
{
    bool bad = false;
    for (int i = 0; i < n->nlist; i++)
        bad |= check_expr(c, &n->list[i], SL_TYPE_FLOAT) == SL_TY_ERROR;
    if (bad)
        return SL_TY_ERROR;
    if (n->nlist != 3 && n->nlist != 16) {
        error(c, n->pos, "a list of %d values is neither a triple (3 values) nor a "
                         "matrix (16)", n->nlist);
        return SL_TY_ERROR;
    }
    for (int i = 0; i < n->nlist; i++) {
        if (n->list[i]->ty != SL_TYPE_FLOAT) {
            error(c, n->list[i]->pos, "component %d of a list must be a float, not '%s'",
                  i + 1, sl_ty_name(n->list[i]->ty));
            return SL_TY_ERROR;
        }
    }
    sl_ty list = n->nlist == 3 ? SL_TY_LIST3 : SL_TY_LIST16;
    if (can_convert(list, hint)) {
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
        bad |= check_expr(c, &n->list[i], hint) == SL_TY_ERROR;
    if (bad)
        return SL_TY_ERROR;
    int want = sl_ty_slots(ty);
    if (count == 1) {
        sl_ty a = n->list[0]->ty;
        if (a == ty || can_convert(a, ty)) {
            wrap_conv(c, &n->list[0], ty);
            return ty;
        }
        error(c, n->pos, "cannot convert '%s' to '%s'", sl_ty_name(a), sl_ty_name(ty));
        return SL_TY_ERROR;
    }
    if (count != want || ty == SL_TYPE_FLOAT || ty == SL_TYPE_STRING) {
        error(c, n->pos, "a '%s' is built from %s, not from %d values", sl_ty_name(ty),
              ty == SL_TYPE_MATRIX ? "1 or 16 floats" : want == 3 ? "1 or 3 floats" : "1 value",
              count);
        return SL_TY_ERROR;
    }
    for (int i = 0; i < count; i++) {
        if (n->list[i]->ty != SL_TYPE_FLOAT) {
            error(c, n->list[i]->pos, "component %d of '%s' must be a float, not '%s'", i + 1,
                  sl_ty_name(ty), sl_ty_name(n->list[i]->ty));
            return SL_TY_ERROR;
        }
    }
    return ty;
}

static sl_ty check_cast(checker *c, sl_node *n, sl_ty hint)
{
    if (n->cast_ty == SL_TYPE_VOID || sl_ty_is_list(n->cast_ty))
        return set_ty(n, check_untyped_list(c, n, hint));
    sl_ty ty = check_cast_values(c, n);
    if (ty == SL_TY_ERROR || !n->name)
        return set_ty(n, ty);
    if (sl_ty_is_spatial(ty)) {
        if (sl_space_find(n->name) < 0) {
            error(c, n->pos, "unknown space '%s' (known: \"current\", \"world\", "
                             "\"object\", \"shader\", \"camera\")", n->name);
            return set_ty(n, SL_TY_ERROR);
        }
    } else if (ty == SL_TYPE_COLOR) {
        if (sl_color_space_find(n->name) < 0) {
            error(c, n->pos, "unknown color space '%s' (known: " SL_COLOR_SPACE_NAMES ")",
                  n->name);
            return set_ty(n, SL_TY_ERROR);
        }
    } else if (ty == SL_TYPE_MATRIX) {
        if (sl_space_find(n->name) < 0) {
            error(c, n->pos, "unknown space '%s' (known: \"current\", \"world\", "
                             "\"object\", \"shader\", \"camera\")", n->name);
            return set_ty(n, SL_TY_ERROR);
        }
    } else {
        error(c, n->pos, "a space name is not allowed in a cast to '%s'", sl_ty_name(ty));
        return set_ty(n, SL_TY_ERROR);
    }
    return set_ty(n, ty);
}

static sl_ty check_expr(checker *c, sl_node **np, sl_ty hint)
{
    sl_node *n = *np;
    switch (n->kind) {
    case SL_N_NUM: return set_ty(n, SL_TYPE_FLOAT);
    case SL_N_STR: return set_ty(n, SL_TYPE_STRING);
    case SL_N_ERROR: return set_ty(n, SL_TY_ERROR);
    case SL_N_IDENT: return check_ident(c, n);
    case SL_N_CALL: return check_call(c, n, hint);
    case SL_N_UNARY: return check_unary(c, n);
    case SL_N_BINARY: return check_binary(c, n);
    case SL_N_COND: return check_cond_expr(c, n, hint);
    case SL_N_ASSIGN: return check_assign(c, n);
    case SL_N_CAST: return check_cast(c, n, hint);
    case SL_N_INDEX: return check_index(c, n);
    case SL_N_CONV: return n->ty;
    default: return set_ty(n, SL_TY_ERROR);
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
            error(c, init->pos, "cannot initialize '%s' (%s) with a list in braces", s->name,
                  sl_ty_name(s->ty));
            return;
        }
        sl_ty elem = sl_ty_elem(s->ty);
        int len = sl_ty_len(s->ty);
        if (len == 0 && init->nlist > 0 && init->nlist <= SL_MAX_ARRAY_LEN)
            s->ty = sl_ty_array(elem, len = init->nlist);
        init->ty = s->ty;
        for (int i = 0; i < init->nlist; i++) {
            sl_ty t = check_expr(c, &init->list[i], elem);
            if (!can_convert(t, elem)) {
                error(c, init->list[i]->pos, "element %d of '%s' (%s) cannot be a '%s'", i + 1,
                      s->name, sl_ty_name(s->ty), sl_ty_name(t));
                return;
            }
            wrap_conv(c, &init->list[i], elem);
        }
        if (init->nlist != len)
            error(c, init->pos, "'%s' has %d elements, but %d value%s given", s->name, len,
                  init->nlist, init->nlist == 1 ? " is" : "s are");
        return;
    }
    if (init) {
        sl_ty t = check_expr(c, &v->a, s->ty);
        if (!can_convert(t, s->ty))
            error(c, v->a->pos, "cannot initialize '%s' (%s) with a value of type '%s'",
                  s->name, sl_ty_name(s->ty), sl_ty_name(t));
        else
            wrap_conv(c, &v->a, s->ty);
    }
    if (sl_ty_is_array(s->ty) && sl_ty_len(s->ty) == 0 && s->kind == SL_SYM_LOCAL && !init) {
        s->resizable = true;          /* RSL 2: 'float a[];' grows with push/resize */
        s->ty = sl_ty_array(sl_ty_elem(s->ty), SL_RESIZABLE_CAPACITY);
    } else if (sl_ty_is_array(s->ty) && sl_ty_len(s->ty) == 0) {
        error(c, v->pos, "array '%s' needs a size or an initializer", s->name);
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
                outer = lookup(c, s->name);
                if (outer && outer->kind != SL_SYM_GLOBAL)
                    outer = NULL;         /* a variable of this very function */
            }
            if (!outer) {
                error(c, v->pos, c->func && c->func->nested
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
                error(c, v->pos, "'extern' declaration of '%s' as '%s' does not match its "
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
        error(c, n->pos, "'%s' statement not in loop", kw);
        return;
    }
    if (levels > c->nloops) {
        error(c, n->pos, "'%s %d' leaves more loops than the %d around it", kw, levels,
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
        sl_ty t = check_expr(c, &n->a, want);
        if (want == SL_TYPE_VOID) {
            error(c, n->pos, c->func ? "void function '%s' should not return a value"
                                     : "shader '%s' should not return a value",
                  c->func ? c->func->name : c->file->name);
        } else if (!can_convert(t, want)) {
            error(c, n->a->pos, "cannot return a value of type '%s' from function '%s' "
                                "returning '%s'", sl_ty_name(t), c->func->name,
                  sl_ty_name(want));
        } else {
            wrap_conv(c, &n->a, want);
        }
    } else if (want != SL_TYPE_VOID) {
        error(c, n->pos, "non-void function '%s' should return a value", c->func->name);
    }
    sl_escape e = { SL_ESC_RETURN, NULL, c->func };
    add_escape(c, n, e);
}

static void check_nested_function(checker *c, sl_func *f);

static void check_stmt(checker *c, sl_node *n)
{
    if (!n || sl_diag_full(c->diag))
        return;
    switch (n->kind) {
    case SL_N_BLOCK: {
        scope_mark saved = push_scope(c);
        for (int i = 0; i < n->nlist; i++) {
            check_stmt(c, n->list[i]);
            inherit(c, n, n->list[i], NULL);
        }
        pop_scope(c, saved);
        break;
    }
    case SL_N_DECL: check_decl(c, n); break;
    case SL_N_EXPR: check_expr(c, &n->a, SL_TYPE_VOID); break;
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
    case SL_N_FUNC: check_nested_function(c, n->func); break;
    default: break;
    }
}

/* Marks the body's final return as the tail one; true when some other
 * return exists (the code generator then needs a "returned" flag). */
static bool count_returns(const sl_node *n, int *count)
{
    if (!n)
        return false;
    if (n->kind == SL_N_RETURN)
        (*count)++;
    count_returns(n->a, count);
    count_returns(n->b, count);
    count_returns(n->c, count);
    count_returns(n->d, count);
    if (n->kind == SL_N_BLOCK)
        for (int i = 0; i < n->nlist; i++)
            count_returns(n->list[i], count);
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
            error(c, f->pos, "non-void function '%s' has no 'return' statement", f->name);
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

/* A function defined inside a function or the shader body: callable from
 * its definition to the end of the enclosing block (its own body
 * included, so that recursion is reported as such), seeing the enclosing
 * variables through 'extern' only. */
static void check_nested_function(checker *c, sl_func *f)
{
    f->depth = c->depth;
    for (int i = c->vfuncs_start; i < c->nvfuncs; i++) {
        sl_func *g = c->vfuncs[i];
        if (strcmp(g->name, f->name) == 0 && same_params(f, g) && f->ret == g->ret) {
            error(c, f->pos, "redefinition of function '%s'", f->name);
            sl_diag_note(c->diag, c->vfuncs[i]->pos, "previous definition is here");
            return;
        }
    }
    sl_list_push(c->arena, (void ***)&c->vfuncs, &c->nvfuncs, &c->vfuncs_cap, f);
    sl_func *saved_func = c->func;
    int saved_base = c->func_base;
    sl_node **saved_loops = c->loops;           /* break cannot leave a function */
    int saved_nloops = c->nloops, saved_cap = c->loops_cap;
    c->loops = NULL;
    c->nloops = c->loops_cap = 0;
    check_function_body(c, f);
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
        error(c, f->pos, "recursion is not supported: %s", chain);
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

/* Reports f when an earlier function has its name. */
static void check_duplicate(checker *c, int i)
{
    sl_func *f = c->file->funcs[i];
    for (int j = 0; j < i; j++) {
        sl_func *g = c->file->funcs[j];
        if (strcmp(f->name, g->name) == 0 && same_params(f, g) && f->ret == g->ret) {
            error(c, f->pos, "redefinition of function '%s'", f->name);
            sl_diag_note(c->diag, c->file->funcs[j]->pos, "previous definition is here");
            return;
        }
    }
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

bool sl_check(sl_ast_file *file, sl_arena *arena, sl_diag *diag)
{
    checker c = { .arena = arena, .diag = diag, .file = file };
    int errors = sl_diag_error_count(diag);
    make_globals(&c);
    /* definitions in source order, so that messages come in that order */
    bool shader_done = !file->has_shader;
    for (int i = 0; i < file->nfuncs && !sl_diag_full(diag); i++) {
        if (!shader_done && before(file->pos, file->funcs[i]->pos)) {
            check_shader(&c);
            shader_done = true;
        }
        check_duplicate(&c, i);
        check_function(&c, file->funcs[i]);
    }
    if (!shader_done)
        check_shader(&c);
    check_recursion(&c);
    return sl_diag_error_count(diag) == errors;
}

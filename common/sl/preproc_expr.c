/*
 * preproc_expr.c: the #if / #elif expression of the preprocessor (see
 * preproc.h; the state it reads is in preproc_internal.h): `defined X` and
 * `defined(X)` are replaced first, the line is then macro-expanded and
 * evaluated as a C integer constant expression on long long (wrapping
 * instead of overflowing, C precedence, ?: and short-circuit operators
 * that evaluate only the side taken).
 */
#include "sl/preproc_internal.h"

#include <limits.h>
#include <stdarg.h>
#include <string.h>

typedef struct pp_expr {
    sl_preproc *pp;
    const sl_pptoken *t;      /* the expanded line, ending in an EOF token */
    size_t i;
    int depth;
    bool failed;              /* an error was reported: stop reporting */
} pp_expr;

static void ex_error(pp_expr *e, sl_pos pos, const char *fmt, ...) SL_PRINTF(3, 4);
static void ex_error(pp_expr *e, sl_pos pos, const char *fmt, ...)
{
    if (e->failed)
        return;
    e->failed = true;
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(e->pp->diag, SL_DIAG_ERROR, pos, fmt, ap);
    va_end(ap);
}

static const sl_pptoken *ex_peek(const pp_expr *e) { return &e->t[e->i]; }

static const sl_pptoken *ex_take(pp_expr *e)
{
    const sl_pptoken *t = &e->t[e->i];
    if (t->kind != SL_TOK_EOF)
        e->i++;
    return t;
}

static long long ex_cond(pp_expr *e, bool eval);

static long long ex_number(pp_expr *e, const sl_pptoken *t)
{
    char buf[4 * 64 + 8];
    sl_token_kind kind = sl_number_kind(t->text, t->len);
    if (kind == SL_TOK_FLOAT) {
        ex_error(e, t->pos, "floating constant in preprocessor expression");
        return 0;
    }
    if (kind != SL_TOK_INT) {
        ex_error(e, t->pos, "malformed number '%s'", pp_spell_for_message(t, buf));
        return 0;
    }
    unsigned long long v = 0;
    for (size_t i = 0; i < t->len; i++) {
        unsigned d = (unsigned)(t->text[i] - '0');
        if (v > ((unsigned long long)LLONG_MAX - d) / 10) {
            ex_error(e, t->pos, "integer constant is too large");
            return 0;
        }
        v = v * 10 + d;
    }
    return (long long)v;
}

static long long ex_unary(pp_expr *e, bool eval)
{
    char buf[4 * 64 + 8];
    if (++e->depth > SL_PP_MAX_EXPR_DEPTH) {
        ex_error(e, ex_peek(e)->pos, "#if expression nested too deeply (more than %d levels): "
                 "simplify it", SL_PP_MAX_EXPR_DEPTH);
        e->depth--;
        return 0;
    }
    const sl_pptoken *t = ex_take(e);
    long long v = 0;
    switch (t->kind) {
    case SL_TOK_LPAREN:
        v = ex_cond(e, eval);
        if (ex_peek(e)->kind == SL_TOK_RPAREN)
            ex_take(e);
        else
            ex_error(e, ex_peek(e)->pos, "missing ')' in expression");
        break;
    case SL_TOK_PLUS:  v = ex_unary(e, eval); break;
    case SL_TOK_MINUS: v = (long long)(0ull - (unsigned long long)ex_unary(e, eval)); break;
    case SL_TOK_NOT:   v = !ex_unary(e, eval); break;
    case SL_TOK_TILDE: v = ~ex_unary(e, eval); break;
    case SL_TOK_PPNUMBER: v = ex_number(e, t); break;
    case SL_TOK_IDENT: v = 0; break;       /* not a macro: 0 */
    case SL_TOK_EOF:
        ex_error(e, t->pos, "expected value in expression");
        break;
    case SL_TOK_STRING:
    case SL_TOK_OTHER:
    case SL_TOK_HASH:
    case SL_TOK_HASHHASH:
        ex_error(e, t->pos, "token '%s' is not valid in preprocessor expressions",
                 pp_spell_for_message(t, buf));
        break;
    default:
        ex_error(e, t->pos, "expected value in expression before '%s'",
                 pp_spell_for_message(t, buf));
        break;
    }
    e->depth--;
    return v;
}

static int ex_precedence(sl_token_kind kind)
{
    switch (kind) {
    case SL_TOK_OR:      return 1;
    case SL_TOK_AND:     return 2;
    case SL_TOK_PIPE:    return 3;
    case SL_TOK_CARET:   return 4;
    case SL_TOK_AMP:     return 5;
    case SL_TOK_EQ: case SL_TOK_NE: return 6;
    case SL_TOK_LT: case SL_TOK_GT: case SL_TOK_LE: case SL_TOK_GE: return 7;
    case SL_TOK_SHL: case SL_TOK_SHR: return 8;
    case SL_TOK_PLUS: case SL_TOK_MINUS: return 9;
    case SL_TOK_STAR: case SL_TOK_SLASH: case SL_TOK_PERCENT: return 10;
    default:             return 0;
    }
}

/* a op b with C semantics on long long, wrapping instead of overflowing. */
static long long ex_apply(pp_expr *e, const sl_pptoken *op, long long a, long long b, bool eval)
{
    typedef unsigned long long ull;
    switch (op->kind) {
    case SL_TOK_OR:    return a || b;
    case SL_TOK_AND:   return a && b;
    case SL_TOK_PIPE:  return a | b;
    case SL_TOK_CARET: return a ^ b;
    case SL_TOK_AMP:   return a & b;
    case SL_TOK_EQ:    return a == b;
    case SL_TOK_NE:    return a != b;
    case SL_TOK_LT:    return a < b;
    case SL_TOK_GT:    return a > b;
    case SL_TOK_LE:    return a <= b;
    case SL_TOK_GE:    return a >= b;
    case SL_TOK_SHL:   return b < 0 || b > 63 ? 0 : (long long)((ull)a << b);
    case SL_TOK_SHR:
        if (b < 0 || b > 63)
            return a < 0 ? -1 : 0;
        return a < 0 ? ~(~a >> b) : a >> b;
    case SL_TOK_PLUS:  return (long long)((ull)a + (ull)b);
    case SL_TOK_MINUS: return (long long)((ull)a - (ull)b);
    case SL_TOK_STAR:  return (long long)((ull)a * (ull)b);
    case SL_TOK_SLASH:
    case SL_TOK_PERCENT:
        if (b == 0) {
            if (eval)
                ex_error(e, op->pos, "division by zero in #if");
            return 0;
        }
        if (a == LLONG_MIN && b == -1)
            return op->kind == SL_TOK_SLASH ? LLONG_MIN : 0;
        return op->kind == SL_TOK_SLASH ? a / b : a % b;
    default:
        return 0;
    }
}

static long long ex_binary(pp_expr *e, int min_prec, bool eval)
{
    long long lhs = ex_unary(e, eval);
    for (;;) {
        const sl_pptoken *op = ex_peek(e);
        int prec = ex_precedence(op->kind);
        if (prec == 0 || prec < min_prec || e->failed)
            return lhs;
        ex_take(e);
        bool eval_rhs = eval;
        if (op->kind == SL_TOK_AND)
            eval_rhs = eval && lhs != 0;
        else if (op->kind == SL_TOK_OR)
            eval_rhs = eval && lhs == 0;
        long long rhs = ex_binary(e, prec + 1, eval_rhs);
        lhs = ex_apply(e, op, lhs, rhs, eval);
    }
}

static long long ex_cond(pp_expr *e, bool eval)
{
    if (++e->depth > SL_PP_MAX_EXPR_DEPTH) {
        ex_error(e, ex_peek(e)->pos, "#if expression nested too deeply (more than %d levels): "
                 "simplify it", SL_PP_MAX_EXPR_DEPTH);
        e->depth--;
        return 0;
    }
    long long c = ex_binary(e, 1, eval);
    if (ex_peek(e)->kind == SL_TOK_QUESTION && !e->failed) {
        ex_take(e);
        long long a = ex_cond(e, eval && c);
        if (ex_peek(e)->kind != SL_TOK_COLON) {
            ex_error(e, ex_peek(e)->pos, "'?' without following ':'");
            e->depth--;
            return 0;
        }
        ex_take(e);
        long long b = ex_cond(e, eval && !c);
        c = c ? a : b;
    }
    e->depth--;
    return c;
}

/* Evaluates the #if / #elif line in pp->line. */
bool pp_eval_if(sl_preproc *pp, const sl_pptoken *name)
{
    const sl_pptoken *v = pp->line.v;
    size_t n = pp->line.n;
    if (n == 0) {
        sl_diag_error(pp->diag, name->pos, "'#%.*s' with no expression",
                      (int)name->len, name->text);
        return false;
    }
    /* defined X, defined(X) -> 1 or 0, before any expansion */
    tokvec pre = { 0 };
    bool ok = true;
    for (size_t i = 0; i < n && ok; i++) {
        if (!pp_is_word(&v[i], "defined")) {
            pp_tv_push(&pre, &v[i]);
            continue;
        }
        size_t j = i + 1;
        bool paren = j < n && v[j].kind == SL_TOK_LPAREN;
        if (paren)
            j++;
        if (j >= n || v[j].kind != SL_TOK_IDENT) {
            sl_diag_error(pp->diag, j < n ? v[j].pos : pp->eol,
                          "operator 'defined' requires an identifier");
            ok = false;
            break;
        }
        bool defined = pp_find_macro(pp, v[j].text, v[j].len) != NULL;
        j++;
        if (paren) {
            if (j >= n || v[j].kind != SL_TOK_RPAREN) {
                sl_diag_error(pp->diag, j < n ? v[j].pos : pp->eol,
                              "missing ')' after 'defined'");
                ok = false;
                break;
            }
            j++;
        }
        sl_pptoken num = v[i];
        num.kind = SL_TOK_PPNUMBER;
        num.text = defined ? "1" : "0";
        num.len = 1;
        pp_tv_push(&pre, &num);
        i = j - 1;
    }
    long long value = 0;
    if (ok) {
        tokvec expanded = { 0 };
        pp_expand_list(pp, pre.v, pre.n, pp->eol, &expanded);
        sl_pptoken end;
        pp_eof_token(pp, &end);
        end.pos = pp->eol;
        pp_tv_push(&expanded, &end);

        pp_expr e = { pp, expanded.v, 0, 0, false };
        if (expanded.n == 1) {
            ex_error(&e, name->pos, "'#%.*s' with no expression", (int)name->len, name->text);
        } else {
            value = ex_cond(&e, true);
            const sl_pptoken *rest = ex_peek(&e);
            char buf[4 * 64 + 8];
            if (rest->kind == SL_TOK_RPAREN)
                ex_error(&e, rest->pos, "missing '(' in expression");
            else if (rest->kind != SL_TOK_EOF)
                ex_error(&e, rest->pos, "missing binary operator before token '%s'",
                         pp_spell_for_message(rest, buf));
        }
        ok = !e.failed;
        pp_tv_clear(&expanded);
    }
    pp_tv_clear(&pre);
    return ok && value != 0;
}

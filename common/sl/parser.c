/*
 * parser.c: recursive descent over the grammar of RenderMan's Shading
 * Language (RI Spec 3.2 Appendix B), one function per rule.
 *
 *   file        := { shader | function | class }
 *   class       := 'class' IDENT '(' [formals] ')' '{' { member } '}'   (RSL 2)
 *   member      := ['public'] type IDENT '(' [formals] ')' block
 *                | ['public'] type def {',' def} ';'
 *   shader      := ('surface' | 'displacement') IDENT '(' [formals] ')' block
 *   function    := [type] IDENT '(' [formals] ')' block
 *   formals     := formal { (';' | ',') formal } [';']
 *   formal      := ['output'] ['uniform'|'varying'] type def {',' def}
 *   def         := IDENT ['[' [INT] ']'] ['=' (expr | '{' expr {',' expr} '}')]
 *   statement   := block | declaration | function | if | while | for | break
 *                | continue | return | expr ';' | ';'
 *   expr        := assignment, then ?: || && (== !=) (< > <= >=) (+ -)
 *                  (^) (* /) (.) unary, lowest to highest precedence (the
 *                  spec's order: "." binds tighter than "*", "^" between
 *                  "*" and "+")
 *   unary       := ('-' | '+' | '!') unary | type [STRING] unary | primary
 *   primary     := NUMBER | STRING | IDENT | IDENT '[' expr ']'
 *                | IDENT '(' args ')' | '(' expr ')'
 *
 * A type keyword followed by '(' or a string is a cast (`point "object"
 * (x, y, z)`, `color (0.5)`), followed by an identifier a declaration.
 * A parenthesised list of values without a type (`(x, y, z)`) is an
 * SL_N_CAST of type void, which the checker types from the context.
 *
 * Error handling: the first error of a statement is reported, the parser
 * enters panic mode (no more reports) and skips to the next ';' or '}' at
 * the same brace depth.
 */
#include "sl/parser.h"

#include "sl/class.h"

#include <stdio.h>
#include <string.h>

typedef struct parser {
    sl_lexer *lx;
    sl_arena *arena;
    sl_diag *diag;
    sl_token cur;        /* the next token, not yet consumed */
    sl_token prev;       /* the last consumed token */
    bool panic;
    int depth;
    int stmts;           /* statements among the open levels */
    int else_ifs;        /* links of `else if` chains among the open levels */
    long consumed;       /* tokens consumed so far: progress of the loops */
    const atomic_int *cancel;   /* the program's stop flag, or NULL */
    bool cancelled;      /* it was found set, or the nesting limit was met:
                            the text "ends" here (no cascade of errors) */
    bool coshader_said;  /* co-shaders reported once per source (coshader_error) */
} parser;

/* ---------------------------------------------------------------------- */
/* tokens                                                                  */
/* ---------------------------------------------------------------------- */

static void advance(parser *p)
{
    p->consumed++;
    p->prev = p->cur;
    if (p->cancel && !p->cancelled && p->consumed % SL_PARSE_CANCEL_EVERY == 0 &&
        atomic_load_explicit(p->cancel, memory_order_relaxed)) {
        sl_diag_error(p->diag, p->cur.pos, "interrupted (SIGINT/SIGTERM) while compiling");
        p->cancelled = true;
    }
    if (p->cancelled) {   /* no more tokens: every loop and rule unwinds */
        p->cur.kind = SL_TOK_EOF;
        return;
    }
    sl_lexer_next(p->lx, &p->cur);
}

static bool check(const parser *p, sl_token_kind kind) { return p->cur.kind == kind; }

static bool match(parser *p, sl_token_kind kind)
{
    if (!check(p, kind))
        return false;
    advance(p);
    return true;
}

static sl_token_kind peek_kind(parser *p, int k) { return sl_lexer_peek(p->lx, k)->kind; }

static void error_at(parser *p, sl_pos pos, const sl_token *tok, const char *fmt, ...)
    SL_PRINTF(4, 5);
static void error_at(parser *p, sl_pos pos, const sl_token *tok, const char *fmt, ...)
{
    if (p->panic || p->cancelled)
        return;
    p->panic = true;
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(p->diag, SL_DIAG_ERROR, pos, fmt, ap);
    va_end(ap);
    if (tok)
        sl_token_note_macro(tok, p->diag);
}

/* The position just after the previous token: where a missing ';' goes. */
static sl_pos after_prev(const parser *p)
{
    sl_pos pos = p->prev.pos;
    if (!pos.file)
        return p->cur.pos;
    size_t len = p->prev.len;
    if (p->prev.kind == SL_TOK_STRING)
        len += 2;
    if (p->prev.macro)            /* a macro's tokens sit at the invocation */
        return pos;
    pos.col += (int)len;
    return pos;
}

/* "expected ';' after expression": reported after the previous token. */
static bool expect_after(parser *p, sl_token_kind kind, const char *what)
{
    if (match(p, kind))
        return true;
    error_at(p, after_prev(p), &p->prev, "expected %s after %s",
             sl_token_kind_name(kind), what);
    return false;
}

/* "expected ')'": reported at the current token, with a note at the
 * opening bracket when there is one. */
static bool expect_closing(parser *p, sl_token_kind kind, const sl_token *open)
{
    if (match(p, kind))
        return true;
    if (p->panic || p->cancelled)
        return false;
    error_at(p, p->cur.pos, &p->cur, "expected %s", sl_token_kind_name(kind));
    if (open)
        sl_diag_note(p->diag, open->pos, "to match this %s", sl_token_kind_name(open->kind));
    return false;
}

static bool expect(parser *p, sl_token_kind kind, const char *context)
{
    if (match(p, kind))
        return true;
    error_at(p, p->cur.pos, &p->cur, "expected %s %s", sl_token_kind_name(kind), context);
    return false;
}

/* Skips to the end of the current statement: past a ';' or up to a '}'
 * at brace depth 0. */
static void synchronize(parser *p)
{
    int depth = 0;
    while (!check(p, SL_TOK_EOF)) {
        if (depth == 0 && check(p, SL_TOK_SEMICOLON)) {
            advance(p);
            break;
        }
        if (check(p, SL_TOK_LBRACE))
            depth++;
        if (check(p, SL_TOK_RBRACE)) {
            if (depth == 0)
                break;
            depth--;
            advance(p);
            if (depth == 0 && !check(p, SL_KW_ELSE))
                break;
            continue;
        }
        advance(p);
    }
    p->panic = false;
}

/* ---------------------------------------------------------------------- */
/* types                                                                   */
/* ---------------------------------------------------------------------- */

static bool is_type_kw(sl_token_kind k)
{
    return k == SL_KW_FLOAT || k == SL_KW_POINT || k == SL_KW_VECTOR ||
           k == SL_KW_NORMAL || k == SL_KW_COLOR || k == SL_KW_STRING ||
           k == SL_KW_MATRIX || k == SL_KW_VOID;
}

static bool is_qualifier(sl_token_kind k)
{
    return k == SL_KW_UNIFORM || k == SL_KW_VARYING || k == SL_KW_OUTPUT ||
           k == SL_KW_EXTERN;
}

static sl_ty type_of_kw(sl_token_kind k)
{
    switch (k) {
    case SL_KW_FLOAT: return SL_TYPE_FLOAT;
    case SL_KW_POINT: return SL_TYPE_POINT;
    case SL_KW_VECTOR: return SL_TYPE_VECTOR;
    case SL_KW_NORMAL: return SL_TYPE_NORMAL;
    case SL_KW_COLOR: return SL_TYPE_COLOR;
    case SL_KW_STRING: return SL_TYPE_STRING;
    case SL_KW_MATRIX: return SL_TYPE_MATRIX;
    default: return SL_TYPE_VOID;
    }
}

/* ---------------------------------------------------------------------- */
/* expressions                                                             */
/* ---------------------------------------------------------------------- */

static sl_node *expression(parser *p);
static sl_node *unary(parser *p);

static sl_node *error_node(parser *p, sl_pos pos)
{
    return sl_node_new(p->arena, SL_N_ERROR, pos);
}

/* One more level of nesting (SL_PARSE_MAX_DEPTH): `what` is "expression"
 * or "statements". Chains of binary operators do not nest (a loop). */
static bool enter(parser *p, const char *what)
{
    if (p->depth >= SL_PARSE_MAX_DEPTH) {
        /* named by what makes up most of the depth: the conditions of a
         * thousand nested ifs are not the expressions to split */
        bool expr = strcmp(what, "expression") == 0 && 2 * p->stmts <= p->depth;
        if (2 * p->else_ifs > p->depth)     /* mostly a chain of else-ifs */
            error_at(p, p->cur.pos, &p->cur, "'else if' chain too long (more than %d levels of "
                     "nesting, each 'else if' one): split it into several if statements",
                     SL_PARSE_MAX_DEPTH);
        else
            error_at(p, p->cur.pos, &p->cur, "%s nested too deeply (more than %d levels): %s",
                     expr ? "expression" : "statements", SL_PARSE_MAX_DEPTH,
                     expr ? "split it into statements with temporary variables"
                          : "move the inner blocks into functions");
        /* a resource limit, not a syntax error: nothing after it is worth
         * a message (the recovery saw each remaining link of a chain as a
         * broken statement) */
        p->cancelled = true;
        p->cur.kind = SL_TOK_EOF;
        return false;
    }
    p->depth++;
    return true;
}

static void push_node(parser *p, sl_node *n, int *cap, sl_node *item)
{
    sl_list_push(p->arena, (void ***)&n->list, &n->nlist, cap, item);
}

/* '(' args ')' after a function name; the '(' is the current token. */
static sl_node *call(parser *p, sl_token name)
{
    sl_node *n = sl_node_new(p->arena, SL_N_CALL, name.pos);
    n->name = name.text;
    sl_token open = p->cur;
    advance(p);
    int cap = 0;
    if (!check(p, SL_TOK_RPAREN)) {
        do {
            push_node(p, n, &cap, expression(p));
        } while (match(p, SL_TOK_COMMA));
    }
    expect_closing(p, SL_TOK_RPAREN, &open);
    return n;
}

static sl_node *primary_inner(parser *p)
{
    sl_token t = p->cur;
    switch (t.kind) {
    case SL_TOK_INT:
    case SL_TOK_FLOAT: {
        advance(p);
        sl_node *n = sl_node_new(p->arena, SL_N_NUM, t.pos);
        n->num = t.number;
        return n;
    }
    case SL_TOK_STRING: {
        advance(p);
        sl_node *n = sl_node_new(p->arena, SL_N_STR, t.pos);
        n->name = t.text;
        n->len = t.len;
        if (check(p, SL_TOK_LBRACKET)) {         /* "map.tx"[channel] (texture) */
            sl_token open = p->cur;
            advance(p);
            sl_node *x = sl_node_new(p->arena, SL_N_INDEX, open.pos);
            x->a = n;
            x->b = expression(p);
            expect_closing(p, SL_TOK_RBRACKET, &open);
            return x;
        }
        return n;
    }
    case SL_TOK_IDENT: {
        advance(p);
        if (check(p, SL_TOK_LPAREN))
            return call(p, t);
        sl_node *n = sl_node_new(p->arena, SL_N_IDENT, t.pos);
        n->name = t.text;
        if (check(p, SL_TOK_LBRACKET)) {         /* a[i] */
            sl_token open = p->cur;
            advance(p);
            sl_node *x = sl_node_new(p->arena, SL_N_INDEX, open.pos);
            x->a = n;
            x->b = expression(p);
            expect_closing(p, SL_TOK_RBRACKET, &open);
            return x;
        }
        return n;
    }
    case SL_KW_DISPLACEMENT: case SL_KW_SURFACE:
        if (peek_kind(p, 0) == SL_TOK_LPAREN) {   /* message passing: a call */
            advance(p);
            return call(p, t);
        }
        break;
    case SL_TOK_LPAREN: {
        advance(p);
        sl_node *e = expression(p);
        if (check(p, SL_TOK_COMMA)) {    /* (x, y, z): typed by the checker */
            sl_node *n = sl_node_new(p->arena, SL_N_CAST, t.pos);
            n->cast_ty = SL_TYPE_VOID;
            int cap = 0;
            push_node(p, n, &cap, e);
            while (match(p, SL_TOK_COMMA))
                push_node(p, n, &cap, expression(p));
            e = n;
        }
        expect_closing(p, SL_TOK_RPAREN, &t);
        return e;
    }
    default:
        break;
    }
    error_at(p, t.pos, &t, "expected expression");
    return error_node(p, t.pos);
}

#define SL_COSHADER_HELP \
    "aafarm compiles each shader on its own: put the co-shader's code in a function of " \
    "this shader (or #include it)"

/* An RSL 2 co-shader construct (what: "'shader' variables", ...) at the
 * current token: said once per source, the first one; the others have
 * the same cause and fix. */
static void coshader_error(parser *p, const char *what)
{
    if (p->coshader_said) {
        p->panic = true;
        return;
    }
    p->coshader_said = true;
    error_at(p, p->cur.pos, &p->cur, "%s (RSL 2 co-shaders) are not supported: "
             SL_COSHADER_HELP, what);
}

/* A primary, and the RSL 2 method call 'x->method(...)' after it (the
 * lexer gives '-' '>'): co-shaders are not supported, said here. */
static sl_node *primary(parser *p)
{
    sl_node *n = primary_inner(p);
    if (check(p, SL_TOK_MINUS) && peek_kind(p, 0) == SL_TOK_GT) {
        coshader_error(p, "method calls with '->'");
        return error_node(p, p->cur.pos);
    }
    return n;
}

/* type [STRING] ( '(' list ')' | unary ): a cast or a constructor. */
static sl_node *typecast(parser *p)
{
    sl_token t = p->cur;
    advance(p);
    sl_node *n = sl_node_new(p->arena, SL_N_CAST, t.pos);
    n->cast_ty = type_of_kw(t.kind);
    if (t.kind == SL_KW_VOID) {
        error_at(p, t.pos, &t, "cannot cast to 'void'");
        return error_node(p, t.pos);
    }
    if (check(p, SL_TOK_STRING)) {
        n->name = p->cur.text;
        n->len = p->cur.len;
        n->pos = p->cur.pos;
        advance(p);
    }
    int cap = 0;
    if (check(p, SL_TOK_LPAREN)) {
        sl_token open = p->cur;
        advance(p);
        do {
            push_node(p, n, &cap, expression(p));
        } while (match(p, SL_TOK_COMMA));
        expect_closing(p, SL_TOK_RPAREN, &open);
    } else {
        push_node(p, n, &cap, unary(p));
    }
    n->pos = t.pos;
    return n;
}

static sl_node *unary(parser *p)
{
    if (!enter(p, "expression"))
        return error_node(p, p->cur.pos);
    sl_node *result;
    sl_token t = p->cur;
    if (t.kind == SL_TOK_MINUS || t.kind == SL_TOK_NOT || t.kind == SL_TOK_PLUS) {
        advance(p);
        sl_node *a = unary(p);
        if (t.kind == SL_TOK_PLUS) {
            result = a;
        } else {
            result = sl_node_new(p->arena, SL_N_UNARY, t.pos);
            result->op = t.kind;
            result->a = a;
        }
    } else if (is_type_kw(t.kind)) {
        result = typecast(p);
    } else {
        result = primary(p);
    }
    p->depth--;
    return result;
}

static sl_node *binary(parser *p, sl_token op, sl_node *a, sl_node *b)
{
    sl_node *n = sl_node_new(p->arena, SL_N_BINARY, op.pos);
    n->op = op.kind;
    n->a = a;
    n->b = b;
    return n;
}

/* One level of left-associative binary operators. */
typedef sl_node *(*level_fn)(parser *p);

static sl_node *left_assoc(parser *p, level_fn next, const sl_token_kind *ops, int nops)
{
    sl_node *a = next(p);
    for (;;) {
        int i = 0;
        while (i < nops && !check(p, ops[i]))
            i++;
        if (i == nops)
            return a;
        sl_token op = p->cur;
        advance(p);
        a = binary(p, op, a, next(p));
    }
}

static sl_node *dot_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_DOT };
    return left_assoc(p, unary, ops, 1);
}
static sl_node *mul_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_STAR, SL_TOK_SLASH };
    return left_assoc(p, dot_level, ops, 2);
}
static sl_node *cross_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_CARET };
    return left_assoc(p, mul_level, ops, 1);
}
static sl_node *add_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_PLUS, SL_TOK_MINUS };
    return left_assoc(p, cross_level, ops, 2);
}
static sl_node *rel_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_LT, SL_TOK_GT, SL_TOK_LE, SL_TOK_GE };
    return left_assoc(p, add_level, ops, 4);
}
static sl_node *eq_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_EQ, SL_TOK_NE };
    return left_assoc(p, rel_level, ops, 2);
}
static sl_node *and_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_AND };
    return left_assoc(p, eq_level, ops, 1);
}
static sl_node *or_level(parser *p)
{
    static const sl_token_kind ops[] = { SL_TOK_OR };
    return left_assoc(p, and_level, ops, 1);
}

static sl_node *conditional(parser *p)
{
    sl_node *c = or_level(p);
    if (!check(p, SL_TOK_QUESTION))
        return c;
    sl_token q = p->cur;
    advance(p);
    if (!enter(p, "expression"))
        return error_node(p, q.pos);
    sl_node *n = sl_node_new(p->arena, SL_N_COND, q.pos);
    n->a = c;
    n->b = expression(p);
    if (expect(p, SL_TOK_COLON, "in conditional expression"))
        n->c = conditional(p);
    else
        n->c = error_node(p, p->cur.pos);
    p->depth--;
    return n;
}

static bool is_assign_op(sl_token_kind k)
{
    return k == SL_TOK_ASSIGN || k == SL_TOK_PLUS_ASSIGN || k == SL_TOK_MINUS_ASSIGN ||
           k == SL_TOK_STAR_ASSIGN || k == SL_TOK_SLASH_ASSIGN;
}

static sl_node *expression(parser *p)
{
    if (!enter(p, "expression"))
        return error_node(p, p->cur.pos);
    sl_node *lhs = conditional(p);
    if (is_assign_op(p->cur.kind)) {
        sl_token op = p->cur;
        advance(p);
        sl_node *n = sl_node_new(p->arena, SL_N_ASSIGN, op.pos);
        n->op = op.kind;
        n->a = lhs;
        n->b = expression(p);
        if (lhs->kind != SL_N_IDENT && lhs->kind != SL_N_INDEX && lhs->kind != SL_N_ERROR)
            error_at(p, lhs->pos, NULL, "expression is not assignable");
        lhs = n;
    }
    p->depth--;
    return lhs;
}

/* ---------------------------------------------------------------------- */
/* declarations                                                            */
/* ---------------------------------------------------------------------- */

typedef struct declspec {
    sl_ty ty;
    bool output, external;
    sl_token type_tok;
} declspec;

/* [output|extern|uniform|varying]* type; false (reported) without a type */
static bool decl_spec(parser *p, declspec *spec, const char *context)
{
    memset(spec, 0, sizeof *spec);
    while (is_qualifier(p->cur.kind)) {
        if (p->cur.kind == SL_KW_OUTPUT)
            spec->output = true;
        if (p->cur.kind == SL_KW_EXTERN)
            spec->external = true;
        advance(p);
    }
    if (check(p, SL_TOK_IDENT) && strcmp(p->cur.text, "shader") == 0) {
        coshader_error(p, strstr(context, "parameter") ? "'shader' parameters"
                                                       : "'shader' variables");
        return false;
    }
    if (!is_type_kw(p->cur.kind)) {
        error_at(p, p->cur.pos, &p->cur, "expected type name %s", context);
        return false;
    }
    spec->type_tok = p->cur;
    spec->ty = type_of_kw(p->cur.kind);
    advance(p);
    if (check(p, SL_TOK_STRING)) {    /* 'point "object"' in a declaration */
        error_at(p, p->cur.pos, &p->cur,
                 "a space name is not allowed in a declaration; cast the value instead");
        return false;
    }
    return true;
}

static sl_sym *new_sym(parser *p, const sl_token *name, const declspec *spec, sl_sym_kind kind)
{
    sl_sym *s = sl_arena_alloc(p->arena, sizeof *s);
    s->name = name->text;
    s->pos = name->pos;
    s->ty = spec->ty;
    s->kind = kind;
    s->output = spec->output;
    s->writable = true;
    s->slot = -1;
    return s;
}

/* '[' [N] ']' after a declared name: v's type becomes an array of N
 * (N: an integer literal; none: the length comes from the initializer or,
 * for a function parameter, from each argument). */
static bool array_size(parser *p, sl_node *v, const declspec *spec)
{
    sl_token open = p->cur;
    advance(p);
    int len = 0;
    if (!check(p, SL_TOK_RBRACKET)) {
        if (!check(p, SL_TOK_INT) || p->cur.number < 1 || p->cur.number > SL_MAX_ARRAY_LEN) {
            error_at(p, p->cur.pos, &p->cur, "array size must be an integer from 1 to %d",
                     SL_MAX_ARRAY_LEN);
            return false;
        }
        len = (int)p->cur.number;
        advance(p);
    }
    if (!expect_closing(p, SL_TOK_RBRACKET, &open))
        return false;
    if (spec->ty == SL_TYPE_STRING) {
        error_at(p, open.pos, &open, "arrays of strings are not supported");
        return false;
    }
    v->sym->ty = sl_ty_array(spec->ty, len);
    return true;
}

/* '{' expr {, expr} '}': the values of an array. */
static sl_node *array_init(parser *p)
{
    sl_token open = p->cur;
    advance(p);
    sl_node *n = sl_node_new(p->arena, SL_N_ARRAYINIT, open.pos);
    int cap = 0;
    if (!check(p, SL_TOK_RBRACE)) {
        do {
            push_node(p, n, &cap, expression(p));
        } while (match(p, SL_TOK_COMMA));
    }
    expect_closing(p, SL_TOK_RBRACE, &open);
    return n;
}

/* name ['[' [N] ']'] [= expr | = '{' exprs '}']; returns an SL_N_VAR node
 * or NULL after an error */
static sl_node *declarator(parser *p, const declspec *spec, sl_sym_kind kind, bool allow_init)
{
    if (!check(p, SL_TOK_IDENT)) {
        error_at(p, p->cur.pos, &p->cur, "expected identifier");
        return NULL;
    }
    sl_token name = p->cur;
    advance(p);
    sl_node *v = sl_node_new(p->arena, SL_N_VAR, name.pos);
    v->sym = new_sym(p, &name, spec, kind);
    v->name = name.text;
    if (spec->ty == SL_TYPE_VOID) {
        error_at(p, spec->type_tok.pos, &spec->type_tok,
                 "variable '%s' declared 'void'", name.text);
        return NULL;
    }
    if (check(p, SL_TOK_LBRACKET) && !array_size(p, v, spec))
        return NULL;
    if (check(p, SL_TOK_ASSIGN)) {
        if (!allow_init) {
            error_at(p, p->cur.pos, &p->cur,
                     "default values are only allowed for shader parameters");
            return NULL;
        }
        advance(p);
        v->a = check(p, SL_TOK_LBRACE) ? array_init(p) : expression(p);
    }
    return v;
}

/* A group of formals: spec name [= e] {, name [= e]}; appended to *list. */
static bool formal_group(parser *p, sl_node ***list, int *n, int *cap, sl_sym_kind kind)
{
    declspec spec;
    if (!decl_spec(p, &spec, "in parameter list"))
        return false;
    do {
        sl_node *v = declarator(p, &spec, kind, kind == SL_SYM_PARAM);
        if (!v)
            return false;
        sl_list_push(p->arena, (void ***)list, n, cap, v);
        /* ', type ...' starts a new group (C style) */
        if (check(p, SL_TOK_COMMA) &&
            (is_type_kw(peek_kind(p, 0)) || is_qualifier(peek_kind(p, 0))))
            return true;
    } while (match(p, SL_TOK_COMMA));
    return true;
}

/* '(' formals ')', the '(' already consumed. */
static void formals(parser *p, const sl_token *open, sl_node ***list, int *n, sl_sym_kind kind)
{
    int cap = 0;
    while (!check(p, SL_TOK_RPAREN) && !check(p, SL_TOK_EOF)) {
        if (!formal_group(p, list, n, &cap, kind)) {
            /* skip to ')', over an array default '= { ... }' (a co-shader
             * list 'shader layers[] = {}' says one thing, not two) */
            while (!check(p, SL_TOK_RPAREN) && !check(p, SL_TOK_EOF) &&
                   !check(p, SL_TOK_LBRACE)) {
                bool braces = check(p, SL_TOK_ASSIGN) && peek_kind(p, 0) == SL_TOK_LBRACE;
                advance(p);
                for (int depth = 0; braces && !check(p, SL_TOK_EOF); advance(p)) {
                    depth += check(p, SL_TOK_LBRACE) - check(p, SL_TOK_RBRACE);
                    if (depth == 0) {
                        advance(p);
                        break;
                    }
                }
            }
            break;
        }
        if (!match(p, SL_TOK_SEMICOLON) && !match(p, SL_TOK_COMMA))
            break;
    }
    expect_closing(p, SL_TOK_RPAREN, open);
    p->panic = false;
}

/* ---------------------------------------------------------------------- */
/* statements                                                              */
/* ---------------------------------------------------------------------- */

static sl_node *statement(parser *p);

static sl_node *block(parser *p)
{
    sl_token open = p->cur;
    sl_node *b = sl_node_new(p->arena, SL_N_BLOCK, open.pos);
    if (!expect(p, SL_TOK_LBRACE, "to start a block"))
        return b;
    int cap = 0;
    while (!check(p, SL_TOK_RBRACE) && !check(p, SL_TOK_EOF)) {
        long start = p->consumed;
        sl_node *s = statement(p);
        if (s)
            push_node(p, b, &cap, s);
        if (p->panic) {
            /* a statement that failed but reached its ';' (or '}') ends
             * there; otherwise skip to the end of the statement (always
             * moving on: '}' and the end of file end the loop) */
            if (p->consumed > start &&
                (p->prev.kind == SL_TOK_SEMICOLON || p->prev.kind == SL_TOK_RBRACE))
                p->panic = false;
            else
                synchronize(p);
        }
    }
    expect_closing(p, SL_TOK_RBRACE, &open);
    return b;
}

/* name '(' formals ')' block, the name being the current token: the rest
 * of a function definition, at file level or nested (RI Spec 3.2 §14.2:
 * "Functions may be declared anyplace that it is legal to declare a
 * variable"). NULL after an error. */
static sl_func *function_rest(parser *p, sl_ty ret)
{
    sl_token name = p->cur;
    advance(p);
    sl_token open = p->cur;
    if (!expect(p, SL_TOK_LPAREN, "after function name"))
        return NULL;
    sl_func *f = sl_arena_alloc(p->arena, sizeof *f);
    f->name = name.text;
    f->pos = name.pos;
    f->ret = ret;
    sl_node **params = NULL;
    formals(p, &open, &params, &f->nparams, SL_SYM_FPARAM);
    f->params = sl_arena_alloc(p->arena, (size_t)(f->nparams + 1) * sizeof *f->params);
    for (int i = 0; i < f->nparams; i++) {
        f->params[i] = params[i]->sym;
        f->params[i]->writable = f->params[i]->output;
    }
    f->body = block(p);
    return f;
}

/* A declaration statement: spec declarator {, declarator} ';' */
static sl_node *declaration(parser *p, bool need_semicolon)
{
    sl_node *d = sl_node_new(p->arena, SL_N_DECL, p->cur.pos);
    declspec spec;
    if (!decl_spec(p, &spec, "in declaration"))
        return d;
    if (spec.output)
        error_at(p, spec.type_tok.pos, &spec.type_tok,
                 "'output' is only allowed on parameters");
    if (check(p, SL_TOK_IDENT) && peek_kind(p, 0) == SL_TOK_LPAREN) {
        if (spec.external) {
            error_at(p, spec.type_tok.pos, &spec.type_tok,
                     "'extern' is only allowed on variables");
            return d;
        }
        sl_node *n = sl_node_new(p->arena, SL_N_FUNC, p->cur.pos);
        n->func = function_rest(p, spec.ty);
        if (n->func)
            n->func->nested = true;
        return n->func ? n : d;
    }
    int cap = 0;
    do {
        sl_node *v = declarator(p, &spec, SL_SYM_LOCAL, true);
        if (!v)
            return d;
        v->sym->output = false;
        v->num = spec.external;    /* extern: refers to an existing variable */
        push_node(p, d, &cap, v);
    } while (match(p, SL_TOK_COMMA));
    if (need_semicolon)
        expect_after(p, SL_TOK_SEMICOLON, "declaration");
    return d;
}

static sl_node *paren_condition(parser *p, const char *keyword)
{
    sl_token open = p->cur;
    char context[48];
    snprintf(context, sizeof context, "after '%s'", keyword);
    if (!expect(p, SL_TOK_LPAREN, context))
        return error_node(p, p->cur.pos);
    sl_node *c = expression(p);
    expect_closing(p, SL_TOK_RPAREN, &open);
    return c;
}

static sl_node *if_statement(parser *p)
{
    sl_node *n = sl_node_new(p->arena, SL_N_IF, p->cur.pos);
    advance(p);
    n->a = paren_condition(p, "if");
    if (p->panic)
        return n;
    n->b = statement(p);
    if (!p->panic && match(p, SL_KW_ELSE)) {
        /* `else if` nests (every pass recurses along the chain): one level
         * a link, named in the message when the chain meets the limit */
        int link = check(p, SL_KW_IF);
        p->else_ifs += link;
        n->c = statement(p);
        p->else_ifs -= link;
    }
    return n;
}

static sl_node *while_statement(parser *p)
{
    sl_node *n = sl_node_new(p->arena, SL_N_WHILE, p->cur.pos);
    advance(p);
    n->a = paren_condition(p, "while");
    if (p->panic)
        return n;
    n->b = statement(p);
    return n;
}

static sl_node *for_statement(parser *p)
{
    sl_node *n = sl_node_new(p->arena, SL_N_FOR, p->cur.pos);
    advance(p);
    sl_token open = p->cur;
    if (!expect(p, SL_TOK_LPAREN, "after 'for'"))
        return n;
    if (!check(p, SL_TOK_SEMICOLON)) {
        if (is_qualifier(p->cur.kind) ||
            (is_type_kw(p->cur.kind) && peek_kind(p, 0) == SL_TOK_IDENT)) {
            n->a = declaration(p, false);
        } else {
            n->a = sl_node_new(p->arena, SL_N_EXPR, p->cur.pos);
            n->a->a = expression(p);
        }
    }
    if (!expect_after(p, SL_TOK_SEMICOLON, "'for' initialization"))
        return n;
    if (!check(p, SL_TOK_SEMICOLON))
        n->b = expression(p);
    if (!expect_after(p, SL_TOK_SEMICOLON, "'for' condition"))
        return n;
    if (!check(p, SL_TOK_RPAREN)) {
        n->c = sl_node_new(p->arena, SL_N_EXPR, p->cur.pos);
        n->c->a = expression(p);
    }
    if (!expect_closing(p, SL_TOK_RPAREN, &open))
        return n;
    n->d = statement(p);
    return n;
}

/* break [n] ';' / continue [n] ';' */
static sl_node *loop_mod(parser *p, sl_node_kind kind)
{
    sl_token kw = p->cur;
    sl_node *n = sl_node_new(p->arena, kind, kw.pos);
    advance(p);
    n->num = 1;
    if (check(p, SL_TOK_INT)) {
        n->num = p->cur.number;
        if (n->num < 1) {
            error_at(p, p->cur.pos, &p->cur, "'%s' level must be at least 1", kw.text);
            return n;
        }
        advance(p);
    }
    expect_after(p, SL_TOK_SEMICOLON, kind == SL_N_BREAK ? "'break'" : "'continue'");
    return n;
}

static sl_node *return_statement(parser *p)
{
    sl_node *n = sl_node_new(p->arena, SL_N_RETURN, p->cur.pos);
    advance(p);
    if (!check(p, SL_TOK_SEMICOLON))
        n->a = expression(p);
    expect_after(p, SL_TOK_SEMICOLON, "return statement");
    return n;
}

/* The parenthesized arguments of illuminance, illuminate or solar (the
 * keyword kw just read), as the list of a call node; an empty list only
 * where may_be_empty. NULL after an error. */
static sl_node *light_args(parser *p, const sl_token *kw, const char *after, bool may_be_empty)
{
    sl_token open = p->cur;
    sl_node *args = sl_node_new(p->arena, SL_N_CALL, kw->pos);
    int cap = 0;
    if (!expect(p, SL_TOK_LPAREN, after))
        return NULL;
    if (!may_be_empty || !check(p, SL_TOK_RPAREN)) {
        do {
            push_node(p, args, &cap, expression(p));
        } while (!p->panic && match(p, SL_TOK_COMMA));
    }
    if (!expect_closing(p, SL_TOK_RPAREN, &open))
        return NULL;
    return args;
}

/* A call of the internal function `name` with the nargs nodes of args. */
static sl_node *internal_call(parser *p, sl_pos pos, const char *name, sl_node *const *args,
                              int nargs)
{
    sl_node *n = sl_node_new(p->arena, SL_N_CALL, pos);
    n->name = name;
    int cap = 0;
    for (int i = 0; i < nargs; i++)
        push_node(p, n, &cap, args[i]);
    return n;
}

/* if ("illuminance cone"(axis, angle)) body */
static sl_node *cone_test(parser *p, sl_pos pos, sl_node *const axis_angle[2], sl_node *body)
{
    sl_node *cone = internal_call(p, pos, "illuminance cone", axis_angle, 2);
    sl_node *test = sl_node_new(p->arena, SL_N_IF, pos);
    test->a = cone;
    test->b = body;
    return test;
}

/* The statement `call;` and the block { first second } */
static sl_node *call_statement(parser *p, sl_pos pos, sl_node *call)
{
    sl_node *n = sl_node_new(p->arena, SL_N_EXPR, pos);
    n->a = call;
    return n;
}

static sl_node *block_of_two(parser *p, sl_pos pos, sl_node *first, sl_node *second)
{
    sl_node *b = sl_node_new(p->arena, SL_N_BLOCK, pos);
    int cap = 0;
    push_node(p, b, &cap, first);
    push_node(p, b, &cap, second);
    return b;
}

/* illuminance ([category,] position [, axis, angle]) statement (RI Spec 3.2
 * §15.4) becomes
 *   { "illuminance start"(position);
 *     while ("illuminance next"())          (loads L and Cl, 0 at the end)
 *         if ("illuminance cone"(axis, angle)) statement }
 * (no `if` without a cone), so break, continue and the range modes' loop
 * handling work as for any loop. The category (a string) is accepted and
 * matches every light. */
static sl_node *illuminance_statement(parser *p)
{
    sl_token kw = p->cur;
    advance(p);
    sl_node *args = light_args(p, &kw, "after 'illuminance'", false);
    if (!args)
        return NULL;
    int first = args->nlist > 0 && args->list[0]->kind == SL_N_STR ? 1 : 0;
    int n = args->nlist - first;
    if (n != 1 && n != 3) {
        error_at(p, kw.pos, &kw, "illuminance takes [category,] position [, axis, angle], "
                                 "not %d values", args->nlist);
        return NULL;
    }
    sl_node *body = statement(p);
    if (!body)
        return NULL;
    sl_node *start = internal_call(p, kw.pos, "illuminance start", &args->list[first], 1);
    sl_node *start_stmt = call_statement(p, kw.pos, start);
    sl_node *next = internal_call(p, kw.pos, "illuminance next", NULL, 0);
    sl_node *loop = sl_node_new(p->arena, SL_N_WHILE, kw.pos);
    loop->a = next;
    loop->b = n == 3 ? cone_test(p, kw.pos, &args->list[first + 1], body) : body;
    return block_of_two(p, kw.pos, start_stmt, loop);
}

/* illuminate (position [, axis, angle]) statement and solar ([axis,
 * angle]) statement, in light shaders (RI Spec 3.2 §15.4) become
 *   { "illuminate begin"(position);   (L = Ps - position)
 *     if ("illuminance cone"(axis, angle)) statement }
 *   { "solar begin"(axis); statement } (L = axis: the light's direction)
 * (no `if` without a cone). */
static sl_node *emitter_statement(parser *p)
{
    sl_token kw = p->cur;
    bool solar = kw.kind == SL_KW_SOLAR;
    advance(p);
    sl_node *args = light_args(p, &kw, solar ? "after 'solar'" : "after 'illuminate'", true);
    if (!args)
        return NULL;
    int n = args->nlist;
    if (solar ? (n != 0 && n != 2) : (n != 1 && n != 3)) {
        error_at(p, kw.pos, &kw, solar ? "solar takes [axis, angle], not %d values"
                                       : "illuminate takes position [, axis, angle], not %d "
                                         "values", n);
        return NULL;
    }
    sl_node *body = statement(p);
    if (!body)
        return NULL;
    sl_node *begin = internal_call(p, kw.pos, solar ? "solar begin" : "illuminate begin",
                                   args->list, n > 0 ? 1 : 0);
    sl_node *begin_stmt = call_statement(p, kw.pos, begin);
    if (n == 3)
        body = cone_test(p, kw.pos, &args->list[1], body);
    return block_of_two(p, kw.pos, begin_stmt, body);
}


static sl_node *statement_inner(parser *p)
{
    switch (p->cur.kind) {
    case SL_TOK_LBRACE: return block(p);
    case SL_KW_IF: return if_statement(p);
    case SL_KW_WHILE: return while_statement(p);
    case SL_KW_FOR: return for_statement(p);
    case SL_KW_BREAK: return loop_mod(p, SL_N_BREAK);
    case SL_KW_CONTINUE: return loop_mod(p, SL_N_CONTINUE);
    case SL_KW_RETURN: return return_statement(p);
    case SL_TOK_SEMICOLON: {
        sl_node *n = sl_node_new(p->arena, SL_N_EMPTY, p->cur.pos);
        advance(p);
        return n;
    }
    case SL_KW_ILLUMINANCE: return illuminance_statement(p);
    case SL_KW_ILLUMINATE: case SL_KW_SOLAR: return emitter_statement(p);
    default: break;
    }
    if (is_qualifier(p->cur.kind) ||
        ((is_type_kw(p->cur.kind) ||
          (check(p, SL_TOK_IDENT) && strcmp(p->cur.text, "shader") == 0)) &&
         peek_kind(p, 0) == SL_TOK_IDENT))
        return declaration(p, true);
    sl_node *n = sl_node_new(p->arena, SL_N_EXPR, p->cur.pos);
    n->a = expression(p);
    expect_after(p, SL_TOK_SEMICOLON, "expression");
    return n;
}

static sl_node *statement(parser *p)
{
    if (!enter(p, "statements"))
        return NULL;
    p->stmts++;
    sl_node *s = statement_inner(p);
    p->stmts--;
    p->depth--;
    return s;
}

/* ---------------------------------------------------------------------- */
/* definitions                                                             */
/* ---------------------------------------------------------------------- */

/* The source's one shader (or class) is `name`: false, with the error,
 * when it already has one. */
static bool claim_shader(parser *p, sl_ast_file *file, const sl_token *name)
{
    if (file->has_shader) {
        error_at(p, name->pos, name, "more than one shader in one source ('%s' and '%s')",
                 file->name, name->text);
        sl_diag_note(p->diag, file->pos, "'%s' defined here", file->name);
        return false;
    }
    file->has_shader = true;
    file->name = name->text;
    file->pos = name->pos;
    return true;
}

static void shader_definition(parser *p, sl_ast_file *file)
{
    sl_token kw = p->cur;
    advance(p);
    if (kw.kind != SL_KW_SURFACE && kw.kind != SL_KW_DISPLACEMENT && kw.kind != SL_KW_LIGHT) {
        error_at(p, kw.pos, &kw,
                 "'%s' shaders are not supported (only 'surface', 'displacement' and "
                 "'light')", kw.text);
        return;
    }
    if (!check(p, SL_TOK_IDENT)) {
        error_at(p, p->cur.pos, &p->cur, "expected shader name after '%s'", kw.text);
        return;
    }
    sl_token name = p->cur;
    advance(p);
    if (!claim_shader(p, file, &name))
        return;
    file->kind = kw.kind == SL_KW_SURFACE ? SL_SHADER_SURFACE
               : kw.kind == SL_KW_LIGHT ? SL_SHADER_LIGHT : SL_SHADER_DISPLACEMENT;
    sl_token open = p->cur;
    if (!expect(p, SL_TOK_LPAREN, "after shader name"))
        return;
    formals(p, &open, &file->params, &file->nparams, SL_SYM_PARAM);
    for (int i = 0; i < file->nparams; i++)
        file->params[i]->sym->param_index = i;
    file->body = block(p);
}

/* One member of a class body: a method (the shader methods are named
 * 'surface', 'displacement', 'light': keywords) or member variables. */
static void class_member(parser *p, sl_class *cls)
{
    if (check(p, SL_TOK_IDENT) && strcmp(p->cur.text, "public") == 0)
        advance(p);
    declspec spec;
    if (!decl_spec(p, &spec, "in class body"))
        return;
    sl_token_kind k = p->cur.kind;
    if ((k == SL_TOK_IDENT || k == SL_KW_SURFACE || k == SL_KW_DISPLACEMENT ||
         k == SL_KW_LIGHT) && peek_kind(p, 0) == SL_TOK_LPAREN) {
        sl_func *f = function_rest(p, spec.ty);
        if (f)
            sl_list_push(p->arena, (void ***)&cls->methods, &cls->nmethods,
                         &cls->methods_cap, f);
        return;
    }
    if (spec.output || spec.external) {
        error_at(p, spec.type_tok.pos, &spec.type_tok, "'%s' is not allowed on member "
                 "variables", spec.output ? "output" : "extern");
        return;
    }
    sl_node *d = sl_node_new(p->arena, SL_N_DECL, spec.type_tok.pos);
    int cap = 0;
    do {
        sl_node *v = declarator(p, &spec, SL_SYM_LOCAL, true);
        if (!v)
            return;
        push_node(p, d, &cap, v);
    } while (match(p, SL_TOK_COMMA));
    if (expect_after(p, SL_TOK_SEMICOLON, "member declaration"))
        sl_list_push(p->arena, (void ***)&cls->members, &cls->nmembers, &cls->members_cap, d);
}

/* RSL 2: 'class' name '(' params ')' '{' members '}', lowered to a shader
 * by class.c. */
static void class_definition(parser *p, sl_ast_file *file)
{
    advance(p);                                  /* 'class' */
    sl_token name = p->cur;
    advance(p);
    if (!claim_shader(p, file, &name))
        return;
    sl_class cls = { .name = name.text, .pos = name.pos };
    sl_token open = p->cur;
    if (!expect(p, SL_TOK_LPAREN, "after class name"))
        return;
    formals(p, &open, &file->params, &file->nparams, SL_SYM_PARAM);
    for (int i = 0; i < file->nparams; i++)
        file->params[i]->sym->param_index = i;
    sl_token brace = p->cur;
    if (!expect(p, SL_TOK_LBRACE, "to start the class body"))
        return;
    int errors = sl_diag_error_count(p->diag);
    while (!check(p, SL_TOK_RBRACE) && !check(p, SL_TOK_EOF)) {
        long start = p->consumed;
        class_member(p, &cls);
        if (p->panic) {
            if (p->consumed > start &&
                (p->prev.kind == SL_TOK_SEMICOLON || p->prev.kind == SL_TOK_RBRACE))
                p->panic = false;
            else
                synchronize(p);
        }
    }
    expect_closing(p, SL_TOK_RBRACE, &brace);
    if (sl_diag_error_count(p->diag) == errors)
        sl_class_lower(p->arena, p->diag, file, &cls);
}

static void function_definition(parser *p, sl_ast_file *file, int *funcs_cap)
{
    sl_ty ret = SL_TYPE_VOID;
    if (is_type_kw(p->cur.kind)) {
        ret = type_of_kw(p->cur.kind);
        advance(p);
    }
    if (!check(p, SL_TOK_IDENT)) {
        error_at(p, p->cur.pos, &p->cur, "expected function name");
        return;
    }
    sl_func *f = function_rest(p, ret);
    if (f)
        sl_list_push(p->arena, (void ***)&file->funcs, &file->nfuncs, funcs_cap, f);
}

static void skip_definition(parser *p)
{
    while (!check(p, SL_TOK_EOF)) {
        if (check(p, SL_TOK_LBRACE)) {
            int depth = 0;
            do {
                if (check(p, SL_TOK_LBRACE))
                    depth++;
                if (check(p, SL_TOK_RBRACE))
                    depth--;
                advance(p);
            } while (depth > 0 && !check(p, SL_TOK_EOF));
            break;
        }
        advance(p);
        if (p->cur.kind == SL_KW_SURFACE || p->cur.kind == SL_KW_DISPLACEMENT)
            break;
    }
    p->panic = false;
}

sl_ast_file *sl_parse(sl_lexer *lx, sl_arena *arena, const atomic_int *cancel, sl_diag *diag)
{
    parser p = { .lx = lx, .arena = arena, .diag = diag, .cancel = cancel };
    sl_ast_file *file = sl_arena_alloc(arena, sizeof *file);
    sl_lexer_next(lx, &p.cur);
    int funcs_cap = 0;
    while (!check(&p, SL_TOK_EOF)) {
        sl_token_kind k = p.cur.kind;
        if (k == SL_KW_SURFACE || k == SL_KW_DISPLACEMENT || k == SL_KW_LIGHT ||
            k == SL_KW_VOLUME || k == SL_KW_IMAGER) {
            shader_definition(&p, file);
        } else if (k == SL_TOK_IDENT && strcmp(p.cur.text, "class") == 0 &&
                   peek_kind(&p, 0) == SL_TOK_IDENT) {
            class_definition(&p, file);
        } else if (is_type_kw(k) || (k == SL_TOK_IDENT && peek_kind(&p, 0) == SL_TOK_LPAREN)) {
            function_definition(&p, file, &funcs_cap);
        } else {
            error_at(&p, p.cur.pos, &p.cur,
                     "expected a shader ('surface' or 'displacement') or a function definition");
        }
        if (p.panic)
            skip_definition(&p);
        if (sl_diag_full(diag))
            break;
    }
    if (!file->has_shader && sl_diag_error_count(diag) == 0) {
        sl_pos whole = { p.cur.pos.file, 0, 0 };       /* the whole file */
        sl_diag_error(diag, whole, "no shader definition (expected 'surface' or "
                                   "'displacement')");
    }
    return file;
}

/*
 * preproc.c: the preprocessor of the shading language (see preproc.h).
 *
 * What lives here, top to bottom:
 *
 *   memory        an sl_arena (everything token texts point into lives until
 *                 sl_preproc_destroy), a string-keyed hash map (macros,
 *                 interned strings, cleaned source texts), token vectors;
 *   hide sets     Prosser's algorithm: each token carries the set of macros
 *                 whose expansion produced it; a macro in a token's hide set
 *                 does not expand that token (no recursive self-expansion);
 *   raw input     the stack of open sources (one scanner each), the
 *                 conditional stack, and read_raw(), which scans tokens,
 *                 runs directives and drops tokens of skipped groups;
 *   directives    #define #undef #if #ifdef #ifndef #elif #else #endif
 *                 #include #error #warning #pragma;
 *   #if           `defined`, macro expansion, then an integer expression
 *                 evaluator (long long, wrapping, C precedence): in
 *                 preproc_expr.c;
 *   expansion     expand_next() pulls a token from an input (the raw input
 *                 with a push-back stack, or a token list for macro
 *                 arguments and #if lines); a macro invocation is replaced
 *                 by its substituted body, pushed back and rescanned.
 *
 * Positions: a token from a macro body takes the position of the
 * invocation (the outermost one, since a nested invocation token itself
 * carries it) and records the macro in `from`; argument tokens keep their
 * own positions.
 *
 * The state and the helpers preproc.c and preproc_expr.c share are
 * declared in preproc_internal.h.
 */
#include "sl/preproc.h"
#include "sl/preproc_internal.h"
#include "sl/strbuf.h"
#include "util/xalloc.h"

#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------- */
/* memory                                                                  */
/* ---------------------------------------------------------------------- */

void pp_tv_push(tokvec *tv, const sl_pptoken *t)
{
    if (tv->n == tv->cap) {
        tv->cap = tv->cap ? 2 * tv->cap : 16;
        tv->v = xrealloc(tv->v, tv->cap * sizeof *tv->v);
    }
    tv->v[tv->n++] = *t;
}

void pp_tv_clear(tokvec *tv)
{
    free(tv->v);
    tv->v = NULL;
    tv->n = tv->cap = 0;
}

void *sl_preproc_alloc(sl_preproc *self, size_t size)
{
    return sl_arena_alloc(self->arena, size);
}

static char *arena_strndup(sl_preproc *pp, const char *s, size_t len)
{
    char *copy = sl_arena_alloc(pp->arena, len + 1);
    if (len)
        memcpy(copy, s, len);
    copy[len] = '\0';
    return copy;
}

/* ---- the hash map ---- */

static uint32_t hash_bytes(const char *s, size_t n)
{
    uint32_t h = 2166136261u;              /* FNV-1a */
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)s[i];
        h *= 16777619u;
    }
    return h;
}

static map_entry *map_slot(pp_map *m, const char *key, size_t len, uint32_t h)
{
    size_t mask = m->cap - 1;
    for (size_t i = h & mask;; i = (i + 1) & mask) {
        map_entry *e = &m->slots[i];
        if (!e->key || (e->hash == h && e->len == len && memcmp(e->key, key, len) == 0))
            return e;
    }
}

static map_entry *map_get(pp_map *m, const char *key, size_t len)
{
    if (m->cap == 0)
        return NULL;
    map_entry *e = map_slot(m, key, len, hash_bytes(key, len));
    return e->key ? e : NULL;
}

/* The entry for key, created (value NULL) if absent; `key` must then stay
 * valid as long as the map. */
static map_entry *map_put(pp_map *m, const char *key, size_t len)
{
    if (2 * (m->count + 1) > m->cap) {
        pp_map bigger = { 0 };
        bigger.cap = m->cap ? 2 * m->cap : 64;
        bigger.slots = xmalloc(bigger.cap * sizeof *bigger.slots);
        memset(bigger.slots, 0, bigger.cap * sizeof *bigger.slots);
        for (size_t i = 0; i < m->cap; i++) {
            map_entry *e = &m->slots[i];
            if (e->key)
                *map_slot(&bigger, e->key, e->len, e->hash) = *e;
        }
        bigger.count = m->count;
        free(m->slots);
        *m = bigger;
    }
    uint32_t h = hash_bytes(key, len);
    map_entry *e = map_slot(m, key, len, h);
    if (!e->key) {
        e->key = key;
        e->len = len;
        e->hash = h;
        e->value = NULL;
        m->count++;
    }
    return e;
}

const char *sl_preproc_intern(sl_preproc *self, const char *text, size_t len)
{
    map_entry *e = map_get(&self->interned, text, len);
    if (e)
        return e->key;
    char *copy = arena_strndup(self, text, len);
    e = map_put(&self->interned, copy, len);
    e->value = copy;
    return copy;
}

/* ---------------------------------------------------------------------- */
/* small helpers                                                           */
/* ---------------------------------------------------------------------- */

static sl_pos no_pos(void)
{
    sl_pos pos = { NULL, 0, 0 };
    return pos;
}

bool pp_is_word(const sl_pptoken *t, const char *word)
{
    size_t n = strlen(word);
    return t->kind == SL_TOK_IDENT && t->len == n && memcmp(t->text, word, n) == 0;
}

/* The spelling of a token for a message, at most 64 bytes of it; the
 * buffer holds 4 * 64 + 8 bytes. */
const char *pp_spell_for_message(const sl_pptoken *t, char *buf)
{
    if (t->kind == SL_TOK_EOF || t->kind == SL_TOK_NEWLINE)
        return "end of line";
    size_t n = t->len > 64 ? 64 : t->len, o = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)t->text[i];
        if (c >= 0x20 && c < 0x7f)
            buf[o++] = (char)c;
        else
            o += (size_t)sprintf(buf + o, "\\x%02x", c);
    }
    strcpy(buf + o, t->len > 64 ? "..." : "");
    return buf;
}

/* Counts n tokens against SL_PP_MAX_TOKENS and checks the storage taken so
 * far against SL_PP_MAX_BYTES; false (reported once, at pos, and the stream
 * ends) when a limit is passed. */
static bool spend(sl_preproc *pp, size_t n, sl_pos pos)
{
    if (pp->dead)
        return false;
    pp->spent += n;
    if (pp->spent <= SL_PP_MAX_TOKENS && sl_arena_bytes(pp->arena) <= SL_PP_MAX_BYTES)
        return true;
    if (pp->spent > SL_PP_MAX_TOKENS)
        sl_diag_error(pp->diag, pos,
                      "too many tokens (more than %d scanned or produced by macro "
                      "expansion): simplify the macros expanded here",
                      SL_PP_MAX_TOKENS);
    else
        sl_diag_error(pp->diag, pos,
                      "macro expansion too large (more than %d bytes of preprocessor "
                      "storage): simplify the macros expanded here",
                      SL_PP_MAX_BYTES);
    pp->dead = true;
    if (pos.file)
        pp->eof_pos = pos;
    return false;
}

void pp_eof_token(const sl_preproc *pp, sl_pptoken *tok)
{
    memset(tok, 0, sizeof *tok);
    tok->kind = SL_TOK_EOF;
    tok->text = "";
    tok->pos = pp->eof_pos;
}

static bool skipping(const sl_preproc *pp)
{
    return pp->nconds > 0 && !pp->conds[pp->nconds - 1].active;
}

static const char *plural(long n) { return n == 1 ? "" : "s"; }

/* ---------------------------------------------------------------------- */
/* hide sets                                                               */
/* ---------------------------------------------------------------------- */

static bool hs_has(const sl_hideset *hs, const sl_macro *m)
{
    for (; hs; hs = hs->next)
        if (hs->macro == m)
            return true;
    return false;
}

/* Every node counts against the token limit (pos: the expansion that
 * needs it), which bounds the memory hide sets take. */
static const sl_hideset *hs_add(sl_preproc *pp, const sl_hideset *hs, const sl_macro *m,
                                sl_pos pos)
{
    if (hs_has(hs, m))
        return hs;
    sl_hideset *node = sl_arena_alloc(pp->arena, sizeof *node);
    node->macro = m;
    node->next = hs;
    spend(pp, 1, pos);
    return node;
}

static const sl_hideset *hs_union(sl_preproc *pp, const sl_hideset *a, const sl_hideset *b,
                                  sl_pos pos)
{
    if (!a || a == b)
        return b;
    for (; a; a = a->next)
        b = hs_add(pp, b, a->macro, pos);
    return b;
}

static const sl_hideset *hs_intersect(sl_preproc *pp, const sl_hideset *a,
                                      const sl_hideset *b, sl_pos pos)
{
    const sl_hideset *r = NULL;
    for (; a; a = a->next)
        if (hs_has(b, a->macro))
            r = hs_add(pp, r, a->macro, pos);
    return r;
}

/* ---------------------------------------------------------------------- */
/* macros                                                                  */
/* ---------------------------------------------------------------------- */

const char *sl_macro_name(const sl_macro *macro) { return macro->name; }
sl_pos sl_macro_pos(const sl_macro *macro) { return macro->pos; }

sl_macro *pp_find_macro(sl_preproc *pp, const char *name, size_t len)
{
    map_entry *e = map_get(&pp->macros, name, len);
    return e ? e->value : NULL;
}

/* Same definition (C: same parameters, same body tokens, same spacing). */
static bool same_macro(const sl_macro *a, const sl_macro *b)
{
    if (a->funclike != b->funclike || a->nparams != b->nparams || a->nbody != b->nbody)
        return false;
    for (int i = 0; i < a->nparams; i++)
        if (a->params[i] != b->params[i])
            return false;
    for (size_t i = 0; i < a->nbody; i++) {
        const sl_pptoken *x = &a->body[i], *y = &b->body[i];
        if (x->kind != y->kind || x->len != y->len || memcmp(x->text, y->text, x->len) != 0)
            return false;
        if (i > 0 && (x->flags & SL_PPF_SPACE) != (y->flags & SL_PPF_SPACE))
            return false;
    }
    return true;
}

/* Parses the tokens of a #define line (after "define") into a macro;
 * NULL after reporting an error. eol: where the line ends. */
static sl_macro *parse_define(sl_preproc *pp, const sl_pptoken *v, size_t n,
                              sl_pos directive_pos, sl_pos eol)
{
    if (n == 0) {
        sl_diag_error(pp->diag, directive_pos, "no macro name given in '#define' directive");
        return NULL;
    }
    if (v[0].kind != SL_TOK_IDENT) {
        sl_diag_error(pp->diag, v[0].pos, "macro names must be identifiers");
        return NULL;
    }
    if (pp_is_word(&v[0], "defined")) {
        sl_diag_error(pp->diag, v[0].pos, "'defined' cannot be used as a macro name");
        return NULL;
    }
    sl_macro *m = sl_arena_alloc(pp->arena, sizeof *m);
    memset(m, 0, sizeof *m);
    m->name = sl_preproc_intern(pp, v[0].text, v[0].len);
    m->pos = v[0].pos;

    size_t i = 1;
    if (i < n && v[i].kind == SL_TOK_LPAREN && !(v[i].flags & SL_PPF_SPACE)) {
        m->funclike = true;
        i++;
        m->params = sl_arena_alloc(pp->arena, n * sizeof *m->params);
        if (i < n && v[i].kind == SL_TOK_RPAREN) {
            i++;
        } else {
            for (;;) {
                sl_pos at = i < n ? v[i].pos : eol;
                if (i < n && v[i].kind == SL_TOK_DOT) {
                    sl_diag_error(pp->diag, at, "variadic macros are not supported");
                    return NULL;
                }
                if (i >= n || v[i].kind != SL_TOK_IDENT) {
                    sl_diag_error(pp->diag, at, "expected parameter name in macro parameter list");
                    return NULL;
                }
                const char *name = sl_preproc_intern(pp, v[i].text, v[i].len);
                for (int p = 0; p < m->nparams; p++) {
                    if (m->params[p] == name) {
                        sl_diag_error(pp->diag, at, "duplicate macro parameter '%s'", name);
                        return NULL;
                    }
                }
                m->params[m->nparams++] = name;
                i++;
                if (i < n && v[i].kind == SL_TOK_COMMA) {
                    i++;
                    continue;
                }
                if (i < n && v[i].kind == SL_TOK_RPAREN) {
                    i++;
                    break;
                }
                sl_diag_error(pp->diag, i < n ? v[i].pos : eol,
                              "expected ',' or ')' in macro parameter list");
                return NULL;
            }
        }
    }

    m->nbody = n - i;
    m->body = sl_arena_alloc(pp->arena, m->nbody * sizeof *m->body);
    m->param = sl_arena_alloc(pp->arena, m->nbody * sizeof *m->param);
    for (size_t k = 0; k < m->nbody; k++) {
        m->body[k] = v[i + k];
        m->body[k].flags &= ~SL_PPF_BOL;
        m->param[k] = -1;
        if (m->funclike && v[i + k].kind == SL_TOK_IDENT) {
            const char *name = sl_preproc_intern(pp, v[i + k].text, v[i + k].len);
            for (int p = 0; p < m->nparams; p++)
                if (m->params[p] == name)
                    m->param[k] = p;
        }
    }
    for (size_t k = 0; k < m->nbody; k++) {
        const sl_pptoken *t = &m->body[k];
        if (t->kind == SL_TOK_HASHHASH && (k == 0 || k + 1 == m->nbody)) {
            sl_diag_error(pp->diag, t->pos,
                          "'##' cannot appear at either end of a macro expansion");
            return NULL;
        }
        if (m->funclike && t->kind == SL_TOK_HASH &&
            (k + 1 == m->nbody || m->param[k + 1] < 0)) {
            sl_diag_error(pp->diag, t->pos, "'#' is not followed by a macro parameter");
            return NULL;
        }
    }
    return m;
}

static void install_macro(sl_preproc *pp, sl_macro *m)
{
    map_entry *e = map_put(&pp->macros, m->name, strlen(m->name));
    const sl_macro *old = e->value;
    if (old && !same_macro(old, m)) {
        sl_diag_warning(pp->diag, m->pos, "'%s' macro redefined", m->name);
        sl_diag_note(pp->diag, old->pos, "previous definition is here");
    }
    e->value = m;
}

bool sl_preproc_define(sl_preproc *self, const char *definition)
{
    /* "NAME=VALUE" is "#define NAME VALUE", "NAME" is "#define NAME 1" */
    size_t len = strlen(definition);
    char *text = sl_arena_alloc(self->arena, len + 3);
    memcpy(text, definition, len + 1);
    char *eq = strchr(text, '=');
    if (eq) {
        *eq = ' ';
    } else {
        memcpy(text + len, " 1", 3);
        len += 2;
    }
    sl_scanner sc;
    sl_scanner_init(&sc, "<command line>", text, len, NULL, 0, self->diag);
    sc.directive = true;
    tokvec v = { 0 };
    sl_pptoken t;
    for (sl_scanner_scan(&sc, &t); t.kind != SL_TOK_EOF && t.kind != SL_TOK_NEWLINE;
         sl_scanner_scan(&sc, &t))
        pp_tv_push(&v, &t);
    sl_pos start = { "<command line>", 1, 1 };
    sl_macro *m = parse_define(self, v.v, v.n, start, t.pos);
    pp_tv_clear(&v);
    if (m)
        install_macro(self, m);
    return m != NULL;
}

void sl_preproc_undefine(sl_preproc *self, const char *name)
{
    map_entry *e = map_get(&self->macros, name, strlen(name));
    if (e)
        e->value = NULL;
}

/* ---------------------------------------------------------------------- */
/* the raw input: open sources                                             */
/* ---------------------------------------------------------------------- */

static const pp_text *text_of(sl_preproc *pp, const sl_source *src)
{
    map_entry *e = map_put(&pp->texts, sl_preproc_intern(pp, src->name, strlen(src->name)),
                           strlen(src->name));
    if (e->value)
        return e->value;
    pp_text *t = sl_arena_alloc(pp->arena, sizeof *t);
    size_t *splices = xmalloc((src->len / 2 + 1) * sizeof *splices);
    t->src = src;
    t->name = e->key;
    t->text = sl_arena_alloc(pp->arena, src->len + 1);
    t->len = sl_scanner_clean(src->text, src->len, t->text, splices, &t->nsplices);
    t->splices = sl_arena_alloc(pp->arena, t->nsplices * sizeof *t->splices);
    if (t->nsplices)
        memcpy(t->splices, splices, t->nsplices * sizeof *splices);
    free(splices);
    e->value = t;
    return t;
}

static void push_source(sl_preproc *pp, const sl_source *src)
{
    const pp_text *t = text_of(pp, src);
    pp_frame *f = &pp->frames[pp->nframes++];
    sl_scanner_init(&f->sc, t->name, t->text, t->len, t->splices, t->nsplices, pp->diag);
    f->text = t;
    f->cond_base = pp->nconds;
}

/* The current source ended (tok is its EOF): close its conditionals; pop
 * it, marking tok as the end of an include, or, for the main source, end
 * the stream. */
static void end_of_source(sl_preproc *pp, sl_pptoken *tok)
{
    pp_frame *f = &pp->frames[pp->nframes - 1];
    for (size_t i = f->cond_base; i < pp->nconds; i++)
        sl_diag_error(pp->diag, pp->conds[i].pos, "unterminated '%s'", pp->conds[i].directive);
    pp->nconds = f->cond_base;
    if (pp->nframes == 1) {
        pp->eof_pos = tok->pos;
        pp->nframes = 0;
    } else {
        pp->nframes--;
        tok->flags |= SL_PPF_INCLUDE_END;
    }
}

static void directive(sl_preproc *pp, const sl_pptoken *hash);

/* The next token of the open sources, after directives and skipping. */
static void read_raw(sl_preproc *pp, sl_pptoken *tok)
{
    for (;;) {
        if (pp->dead || pp->nframes == 0 || sl_diag_full(pp->diag)) {
            pp_eof_token(pp, tok);
            return;
        }
        pp_frame *f = &pp->frames[pp->nframes - 1];
        f->sc.quiet = skipping(pp);
        sl_scanner_scan(&f->sc, tok);
        if (!spend(pp, 1, tok->pos)) {
            pp_eof_token(pp, tok);
            return;
        }
        if (tok->kind == SL_TOK_EOF) {
            end_of_source(pp, tok);
            return;
        }
        if (tok->kind == SL_TOK_HASH && (tok->flags & SL_PPF_BOL)) {
            directive(pp, tok);
            continue;
        }
        if (!skipping(pp))
            return;
    }
}

/* Reads the rest of a directive line into pp->line; pp->eol gets the
 * position of its end. */
static void read_line(sl_preproc *pp, sl_scanner *sc)
{
    pp->line.n = 0;
    for (;;) {
        sl_pptoken t;
        sl_scanner_scan(sc, &t);
        if (t.kind == SL_TOK_NEWLINE || t.kind == SL_TOK_EOF) {
            pp->eol = t.pos;
            return;
        }
        if (!spend(pp, 1, t.pos))
            return;
        pp_tv_push(&pp->line, &t);
    }
}

/* ---------------------------------------------------------------------- */
/* macro expansion                                                         */
/* ---------------------------------------------------------------------- */

static void input_get(sl_preproc *pp, pp_input *in, sl_pptoken *tok)
{
    if (in->pb.n > 0) {
        *tok = in->pb.v[--in->pb.n];
    } else if (in->raw) {
        read_raw(pp, tok);
    } else if (in->i < in->n) {
        *tok = in->list[in->i++];
    } else {
        pp_eof_token(pp, tok);
        tok->pos = in->end_pos;
    }
}

static void expand_next(sl_preproc *pp, pp_input *in, sl_pptoken *tok);

/* Fully macro-expands a token list on its own (a macro argument, an #if
 * line) into out. */
void pp_expand_list(sl_preproc *pp, const sl_pptoken *v, size_t n, sl_pos end, tokvec *out)
{
    pp_input in = { 0 };
    in.list = v;
    in.n = n;
    in.end_pos = end;
    for (;;) {
        sl_pptoken t;
        expand_next(pp, &in, &t);
        if (t.kind == SL_TOK_EOF)
            break;
        pp_tv_push(out, &t);
    }
    pp_tv_clear(&in.pb);
}

/* What an expansion appends: body tokens take the invocation's position
 * and the expansion's hide set; argument tokens keep their position and
 * get the hide set added. */
typedef struct pp_subst {
    sl_preproc *pp;
    const sl_macro *m;
    pp_arg *args;
    const sl_hideset *hs;
    const sl_pptoken *name;   /* the invoking token */
    tokvec *out;
} pp_subst;

/* Every token an expansion appends is charged as it is appended, so that
 * no expansion grows far beyond the budget before it is pushed back. */
static void append_body(pp_subst *s, const sl_pptoken *t)
{
    if (!spend(s->pp, 1, s->name->pos))
        return;
    sl_pptoken copy = *t;
    copy.pos = s->name->pos;
    copy.from = s->m;
    copy.hs = s->hs;
    copy.flags &= ~SL_PPF_BOL;
    pp_tv_push(s->out, &copy);
}

static void append_arg(pp_subst *s, const sl_pptoken *v, size_t n)
{
    for (size_t i = 0; i < n && spend(s->pp, 1, s->name->pos); i++) {
        sl_pptoken copy = v[i];
        copy.hs = hs_union(s->pp, copy.hs, s->hs, s->name->pos);
        copy.flags &= ~SL_PPF_BOL;
        pp_tv_push(s->out, &copy);
    }
}

/* `#param`: the argument's spelling as a string literal. */
static void append_stringized(pp_subst *s, const pp_arg *a)
{
    sl_strbuf b = { 0 };
    sl_strbuf_put(&b, "\"", 1);
    for (size_t i = 0; i < a->nraw; i++) {
        const sl_pptoken *t = &a->raw[i];
        if (i > 0 && (t->flags & SL_PPF_SPACE))
            sl_strbuf_put(&b, " ", 1);
        if (t->kind == SL_TOK_STRING) {
            for (size_t k = 0; k < t->len; k++) {
                if (t->text[k] == '"' || t->text[k] == '\\')
                    sl_strbuf_put(&b, "\\", 1);
                sl_strbuf_put(&b, &t->text[k], 1);
            }
        } else {
            sl_strbuf_put(&b, t->text, t->len);
        }
    }
    sl_strbuf_put(&b, "\"", 1);
    sl_pptoken t = { 0 };
    t.kind = SL_TOK_STRING;
    t.text = arena_strndup(s->pp, b.data, b.len);
    t.len = b.len;
    free(b.data);
    append_body(s, &t);
}

/* Appends operand i of the body (a token, a parameter or '#' parameter);
 * returns the index after it. Parameters next to '##' are not expanded. */
static size_t append_operand(pp_subst *s, size_t i)
{
    const sl_macro *m = s->m;
    if (m->funclike && m->body[i].kind == SL_TOK_HASH) {
        append_stringized(s, &s->args[m->param[i + 1]]);
        return i + 2;
    }
    if (m->param[i] < 0) {
        append_body(s, &m->body[i]);
        return i + 1;
    }
    pp_arg *a = &s->args[m->param[i]];
    bool pasted = (i > 0 && m->body[i - 1].kind == SL_TOK_HASHHASH) ||
                  (i + 1 < m->nbody && m->body[i + 1].kind == SL_TOK_HASHHASH);
    if (pasted) {
        append_arg(s, a->raw, a->nraw);
    } else {
        if (!a->has_expanded) {
            if (++s->pp->arg_nesting > PP_MAX_ARG_NESTING) {
                if (!s->pp->dead)
                    sl_diag_error(s->pp->diag, s->name->pos,
                                  "macro invocations nested too deeply in arguments (limit %d)",
                                  PP_MAX_ARG_NESTING);
                s->pp->dead = true;
            } else {
                pp_expand_list(s->pp, a->raw, a->nraw, s->name->pos, &a->expanded);
            }
            s->pp->arg_nesting--;
            a->has_expanded = true;
        }
        append_arg(s, a->expanded.v, a->expanded.n);
    }
    return i + 1;
}

/* lhs ## rhs: replaces *lhs by the token their spellings form together;
 * false (reported) if they do not form exactly one token. */
static bool paste(pp_subst *s, sl_pptoken *lhs, const sl_pptoken *rhs)
{
    sl_preproc *pp = s->pp;
    size_t len = lhs->len + rhs->len;
    char *text = sl_arena_alloc(pp->arena, len + 1);
    memcpy(text, lhs->text, lhs->len);
    memcpy(text + lhs->len, rhs->text, rhs->len);
    text[len] = '\0';

    bool ok = !(len >= 2 && text[0] == '/' && (text[1] == '/' || text[1] == '*'));
    sl_pptoken t;
    if (ok) {
        sl_scanner sc;
        sl_scanner_init(&sc, "<paste>", text, len, NULL, 0, pp->diag);
        sc.quiet = true;
        sc.directive = true;
        sl_scanner_scan(&sc, &t);
        ok = t.kind != SL_TOK_EOF && t.text == text && t.len == len &&
             !(t.flags & SL_PPF_UNTERMINATED);
    }
    if (!ok) {
        char a[4 * 64 + 8], b[4 * 64 + 8];
        sl_diag_error(pp->diag, s->name->pos,
                      "pasting '%s' and '%s' does not give a valid preprocessing token",
                      pp_spell_for_message(lhs, a), pp_spell_for_message(rhs, b));
        return false;
    }
    lhs->kind = t.kind;
    lhs->text = text;
    lhs->len = len;
    lhs->pos = s->name->pos;
    lhs->from = s->m;
    return true;
}

/* The body of m with arguments substituted, # and ## applied, into out. */
static void substitute(sl_preproc *pp, const sl_macro *m, pp_arg *args,
                       const sl_hideset *hs, const sl_pptoken *name, tokvec *out)
{
    pp_subst s = { pp, m, args, hs, name, out };
    bool last_empty = false;          /* the last operand gave no tokens */
    size_t i = 0;
    while (i < m->nbody && !pp->dead) {
        if (m->body[i].kind != SL_TOK_HASHHASH) {
            size_t before = out->n;
            i = append_operand(&s, i);
            last_empty = out->n == before;
            continue;
        }
        /* '##': paste the last token so far with the first of the next
         * operand; an empty operand is a placemarker */
        tokvec rhs = { 0 };
        s.out = &rhs;
        i = append_operand(&s, i + 1);
        s.out = out;
        size_t k = 0;
        if (rhs.n > 0 && !last_empty && out->n > 0) {
            if (paste(&s, &out->v[out->n - 1], &rhs.v[0]))
                k = 1;
        }
        for (; k < rhs.n; k++)
            pp_tv_push(out, &rhs.v[k]);
        if (rhs.n > 0)
            last_empty = false;
        pp_tv_clear(&rhs);
    }
}

/* Pushes an expansion back onto the input so that it is rescanned (its
 * tokens were charged as they were appended). */
static void push_back(sl_preproc *pp, pp_input *in, tokvec *out, const sl_pptoken *name)
{
    if (spend(pp, 0, name->pos))
        for (size_t k = out->n; k-- > 0;)
            pp_tv_push(&in->pb, &out->v[k]);
    pp_tv_clear(out);
}

/* Collects the arguments of an invocation of m (the '(' has been read)
 * and pushes its expansion back onto the input. */
static void expand_call(sl_preproc *pp, pp_input *in, const sl_macro *m,
                        const sl_pptoken *name)
{
    tokvec toks = { 0 };
    size_t *starts = xmalloc(8 * sizeof *starts);
    size_t nargs = 1, cap = 8;
    starts[0] = 0;
    int depth = 0;
    sl_pptoken t;
    for (;;) {
        input_get(pp, in, &t);
        if (t.kind == SL_TOK_EOF) {
            if (!pp->dead)
                sl_diag_error(pp->diag, name->pos,
                              "unterminated argument list invoking macro '%s'", m->name);
            pp_tv_push(&in->pb, &t);          /* the caller sees the end too */
            goto done;
        }
        if (t.kind == SL_TOK_LPAREN) {
            depth++;
        } else if (t.kind == SL_TOK_RPAREN) {
            if (depth == 0)
                break;
            depth--;
        } else if (t.kind == SL_TOK_COMMA && depth == 0) {
            if (nargs == cap) {
                cap *= 2;
                starts = xrealloc(starts, cap * sizeof *starts);
            }
            starts[nargs++] = toks.n;
            continue;
        }
        pp_tv_push(&toks, &t);
    }

    if (m->nparams == 0 && nargs == 1 && toks.n == 0)
        nargs = 0;                         /* f() takes no arguments */
    if ((long)nargs != m->nparams) {
        if ((long)nargs < m->nparams)
            sl_diag_error(pp->diag, name->pos,
                          "macro '%s' requires %d argument%s, but only %zu given",
                          m->name, m->nparams, plural(m->nparams), nargs);
        else
            sl_diag_error(pp->diag, name->pos,
                          "macro '%s' passed %zu argument%s, but takes just %d",
                          m->name, nargs, plural((long)nargs), m->nparams);
        sl_diag_note(pp->diag, m->pos, "macro '%s' defined here", m->name);
        goto done;
    }

    pp_arg *args = xmalloc((nargs ? nargs : 1) * sizeof *args);
    for (size_t a = 0; a < nargs; a++) {
        size_t end = a + 1 < nargs ? starts[a + 1] : toks.n;
        args[a].raw = toks.v ? toks.v + starts[a] : NULL;
        args[a].nraw = end - starts[a];
        memset(&args[a].expanded, 0, sizeof args[a].expanded);
        args[a].has_expanded = false;
    }
    const sl_hideset *hs = hs_add(pp, hs_intersect(pp, name->hs, t.hs, name->pos), m,
                                  name->pos);
    tokvec out = { 0 };
    substitute(pp, m, args, hs, name, &out);
    push_back(pp, in, &out, name);
    for (size_t a = 0; a < nargs; a++)
        pp_tv_clear(&args[a].expanded);
    free(args);
done:
    pp_tv_clear(&toks);
    free(starts);
}

/* The next token of `in` that is not a macro invocation: invocations are
 * replaced by their expansions, which are then read again (rescanning). */
static void expand_next(sl_preproc *pp, pp_input *in, sl_pptoken *tok)
{
    for (;;) {
        if (pp->dead || sl_diag_full(pp->diag)) {
            pp_eof_token(pp, tok);
            return;
        }
        input_get(pp, in, tok);
        if (tok->kind != SL_TOK_IDENT)
            return;
        const sl_macro *m = pp_find_macro(pp, tok->text, tok->len);
        if (!m || hs_has(tok->hs, m))
            return;
        if (m->funclike) {
            sl_pptoken next;
            input_get(pp, in, &next);
            if (next.kind != SL_TOK_LPAREN) {
                pp_tv_push(&in->pb, &next);   /* a name, not an invocation */
                return;
            }
            sl_pptoken name = *tok;
            expand_call(pp, in, m, &name);
        } else {
            sl_pptoken name = *tok;
            tokvec out = { 0 };
            substitute(pp, m, NULL, hs_add(pp, name.hs, m, name.pos), &name, &out);
            push_back(pp, in, &out, &name);
        }
    }
}

/* ---------------------------------------------------------------------- */
/* directives                                                              */
/* ---------------------------------------------------------------------- */

static void push_cond(sl_preproc *pp, const sl_pptoken *hash, const char *directive, bool value)
{
    if (pp->nconds == pp->capconds) {
        pp->capconds = pp->capconds ? 2 * pp->capconds : 16;
        pp->conds = xrealloc(pp->conds, pp->capconds * sizeof *pp->conds);
    }
    bool parent = !skipping(pp);
    pp_cond c = { hash->pos, directive, parent, parent && value, parent && value, false };
    pp->conds[pp->nconds++] = c;
}

/* The innermost conditional of the current source, or NULL. */
static pp_cond *current_cond(sl_preproc *pp)
{
    size_t base = pp->frames[pp->nframes - 1].cond_base;
    return pp->nconds > base ? &pp->conds[pp->nconds - 1] : NULL;
}

static void extra_tokens(sl_preproc *pp, const char *directive)
{
    if (pp->line.n > 0)
        sl_diag_warning(pp->diag, pp->line.v[0].pos,
                        "extra tokens at end of '%s' directive", directive);
}

/* #ifdef / #ifndef: the macro name on the line; false after an error. */
static bool ifdef_name(sl_preproc *pp, const sl_pptoken *name, const char *directive,
                       bool *defined)
{
    if (pp->line.n == 0) {
        sl_diag_error(pp->diag, name->pos, "no macro name given in '%s' directive", directive);
        return false;
    }
    const sl_pptoken *id = &pp->line.v[0];
    if (id->kind != SL_TOK_IDENT) {
        sl_diag_error(pp->diag, id->pos, "macro names must be identifiers");
        return false;
    }
    *defined = pp_find_macro(pp, id->text, id->len) != NULL;
    if (pp->line.n > 1)
        sl_diag_warning(pp->diag, pp->line.v[1].pos,
                        "extra tokens at end of '%s' directive", directive);
    return true;
}

static void do_ifdef(sl_preproc *pp, const sl_pptoken *hash, const sl_pptoken *name,
                     bool negate)
{
    const char *directive = negate ? "#ifndef" : "#ifdef";
    bool value = false, defined;
    if (!skipping(pp) && ifdef_name(pp, name, directive, &defined))
        value = defined != negate;
    push_cond(pp, hash, directive, value);
}

static void do_elif(sl_preproc *pp, const sl_pptoken *hash, const sl_pptoken *name)
{
    pp_cond *c = current_cond(pp);
    if (!c) {
        sl_diag_error(pp->diag, hash->pos, "'#elif' without '#if'");
        return;
    }
    if (c->seen_else) {
        sl_diag_error(pp->diag, hash->pos, "'#elif' after '#else'");
        c->active = false;
        return;
    }
    if (!c->was_active || c->taken) {
        c->active = false;
        return;
    }
    c->active = pp_eval_if(pp, name);
    c->taken = c->active;
}

static void do_else(sl_preproc *pp, const sl_pptoken *hash)
{
    pp_cond *c = current_cond(pp);
    if (!c) {
        sl_diag_error(pp->diag, hash->pos, "'#else' without '#if'");
        return;
    }
    if (c->seen_else) {
        sl_diag_error(pp->diag, hash->pos, "'#else' after '#else'");
        c->active = false;
        return;
    }
    if (c->was_active)
        extra_tokens(pp, "#else");
    c->seen_else = true;
    c->active = c->was_active && !c->taken;
    c->taken = true;
}

static void do_endif(sl_preproc *pp, const sl_pptoken *hash)
{
    pp_cond *c = current_cond(pp);
    if (!c) {
        sl_diag_error(pp->diag, hash->pos, "'#endif' without '#if'");
        return;
    }
    if (c->was_active)
        extra_tokens(pp, "#endif");
    pp->nconds--;
}

static void do_define(sl_preproc *pp, const sl_pptoken *name)
{
    sl_macro *m = parse_define(pp, pp->line.v, pp->line.n, name->pos, pp->eol);
    if (m)
        install_macro(pp, m);
}

static void do_undef(sl_preproc *pp, const sl_pptoken *name)
{
    if (pp->line.n == 0) {
        sl_diag_error(pp->diag, name->pos, "no macro name given in '#undef' directive");
        return;
    }
    const sl_pptoken *id = &pp->line.v[0];
    if (id->kind != SL_TOK_IDENT) {
        sl_diag_error(pp->diag, id->pos, "macro names must be identifiers");
        return;
    }
    if (pp_is_word(id, "defined")) {
        sl_diag_error(pp->diag, id->pos, "'defined' cannot be used as a macro name");
        return;
    }
    map_entry *e = map_get(&pp->macros, id->text, id->len);
    if (e)
        e->value = NULL;
    if (pp->line.n > 1)
        sl_diag_warning(pp->diag, pp->line.v[1].pos,
                        "extra tokens at end of '#undef' directive");
}

/* #error / #warning: the message is the line's tokens, single-spaced. */
static void do_message(sl_preproc *pp, const sl_pptoken *hash, sl_diag_level level)
{
    enum { MAX_TEXT = 512 };
    sl_strbuf b = { 0 };
    sl_strbuf_put(&b, "", 0);
    for (size_t i = 0; i < pp->line.n && b.len < MAX_TEXT; i++) {
        const sl_pptoken *t = &pp->line.v[i];
        if (i > 0 && (t->flags & SL_PPF_SPACE))
            sl_strbuf_put(&b, " ", 1);
        sl_strbuf_put(&b, t->text, t->len);
    }
    const char *word = level == SL_DIAG_ERROR ? "#error" : "#warning";
    sl_diag_report(pp->diag, level, hash->pos, "%s%s%.*s%s", word, b.len ? " " : "",
                   (int)(b.len > MAX_TEXT ? MAX_TEXT : b.len), b.data,
                   b.len > MAX_TEXT ? "..." : "");
    free(b.data);
}

static void do_include(sl_preproc *pp)
{
    pp_frame *f = &pp->frames[pp->nframes - 1];
    sl_pptoken file;
    bool angled = sl_scanner_header_name(&f->sc, &file);
    if (!angled)
        sl_scanner_scan(&f->sc, &file);
    if (file.kind != SL_TOK_NEWLINE && file.kind != SL_TOK_EOF)
        read_line(pp, &f->sc);
    else
        pp->line.n = 0;
    f->sc.directive = false;

    if (file.kind != SL_TOK_STRING) {
        sl_diag_error(pp->diag, file.pos, "'#include' expects \"FILENAME\" or <FILENAME>");
        return;
    }
    if (file.flags & SL_PPF_UNTERMINATED) {
        if (angled)
            sl_diag_error(pp->diag, file.pos, "missing terminating '>' character");
        return;                            /* a '"' was reported by the scanner */
    }
    extra_tokens(pp, "#include");
    if (file.len <= 2) {
        sl_diag_error(pp->diag, file.pos, "empty filename in '#include'");
        return;
    }
    char *name = xmalloc(file.len - 1);
    memcpy(name, file.text + 1, file.len - 2);
    name[file.len - 2] = '\0';

    char *searched = NULL;
    const sl_source *src = sl_source_set_resolve(pp->set, name, f->text->name,
                                                 (const char *const *)pp->search_path,
                                                 !angled, pp->diag, &searched);
    if (!src) {
        sl_diag_error(pp->diag, file.pos, "cannot find include file '%s' (searched: %s)",
                      name, searched ? searched : "");
        goto done;
    }
    for (int i = 0; i < pp->nframes; i++) {
        if (pp->frames[i].text->src != src)
            continue;
        sl_strbuf chain = { 0 };
        for (int k = i; k < pp->nframes; k++) {
            sl_strbuf_put(&chain, pp->frames[k].text->name, strlen(pp->frames[k].text->name));
            sl_strbuf_put(&chain, " -> ", 4);
        }
        sl_strbuf_put(&chain, src->name, strlen(src->name));
        sl_diag_error(pp->diag, file.pos, "include cycle: %s", chain.data);
        free(chain.data);
        goto done;
    }
    if (pp->nframes > SL_PP_MAX_INCLUDE_DEPTH) {
        sl_diag_error(pp->diag, file.pos, "#include nested too deeply (limit %d levels)",
                      SL_PP_MAX_INCLUDE_DEPTH);
        goto done;
    }
    push_source(pp, src);
done:
    free(searched);
    free(name);
}

/* A line starting with '#': read the directive and obey it. */
static void directive(sl_preproc *pp, const sl_pptoken *hash)
{
    pp_frame *f = &pp->frames[pp->nframes - 1];
    bool skip = skipping(pp);
    f->sc.directive = true;
    sl_pptoken name;
    sl_scanner_scan(&f->sc, &name);
    if (name.kind == SL_TOK_NEWLINE || name.kind == SL_TOK_EOF) {
        f->sc.directive = false;           /* the null directive */
        return;
    }
    if (!skip && pp_is_word(&name, "include")) {
        do_include(pp);
        return;
    }
    read_line(pp, &f->sc);
    f->sc.directive = false;

    if (pp_is_word(&name, "if")) {
        push_cond(pp, hash, "#if", !skip && pp_eval_if(pp, &name));
    } else if (pp_is_word(&name, "ifdef")) {
        do_ifdef(pp, hash, &name, false);
    } else if (pp_is_word(&name, "ifndef")) {
        do_ifdef(pp, hash, &name, true);
    } else if (pp_is_word(&name, "elif")) {
        do_elif(pp, hash, &name);
    } else if (pp_is_word(&name, "else")) {
        do_else(pp, hash);
    } else if (pp_is_word(&name, "endif")) {
        do_endif(pp, hash);
    } else if (skip) {
        return;                            /* anything goes in a skipped group */
    } else if (pp_is_word(&name, "define")) {
        do_define(pp, &name);
    } else if (pp_is_word(&name, "undef")) {
        do_undef(pp, &name);
    } else if (pp_is_word(&name, "error")) {
        do_message(pp, hash, SL_DIAG_ERROR);
    } else if (pp_is_word(&name, "warning")) {
        do_message(pp, hash, SL_DIAG_WARNING);
    } else if (pp_is_word(&name, "pragma")) {
        /* pragmas are accepted and ignored */
    } else {
        char buf[4 * 64 + 8];
        sl_diag_error(pp->diag, name.pos, "invalid preprocessing directive '#%s'",
                      pp_spell_for_message(&name, buf));
    }
}

/* ---------------------------------------------------------------------- */
/* the class                                                               */
/* ---------------------------------------------------------------------- */

sl_preproc *sl_preproc_new(sl_source_set *set, const char *main_file,
                           const char *const *search_path, sl_diag *diag)
{
    sl_preproc *self = xmalloc(sizeof *self);
    memset(self, 0, sizeof *self);
    self->set = set;
    self->diag = diag;
    self->arena = sl_arena_new();
    sl_diag_set_sources(diag, set);

    size_t n = 0;
    while (search_path && search_path[n])
        n++;
    self->search_path = xmalloc((n + 1) * sizeof *self->search_path);
    for (size_t i = 0; i < n; i++) {
        size_t len = strlen(search_path[i]);
        self->search_path[i] = xmalloc(len + 1);
        memcpy(self->search_path[i], search_path[i], len + 1);
    }
    self->search_path[n] = NULL;

    const sl_source *src = main_file ? sl_source_set_get(set, main_file, diag) : NULL;
    if (!src) {
        sl_diag_error(diag, no_pos(), "cannot find source '%s'", main_file ? main_file : "");
        self->dead = true;
        return self;
    }
    self->main.raw = true;
    push_source(self, src);
    self->eof_pos.file = self->frames[0].text->name;
    self->eof_pos.line = 1;
    self->eof_pos.col = 1;
    return self;
}

void sl_preproc_destroy(sl_preproc **self_p)
{
    if (!self_p || !*self_p)
        return;
    sl_preproc *self = *self_p;
    for (char **p = self->search_path; *p; p++)
        free(*p);
    free(self->search_path);
    free(self->conds);
    free(self->macros.slots);
    free(self->interned.slots);
    free(self->texts.slots);
    pp_tv_clear(&self->main.pb);
    pp_tv_clear(&self->line);
    sl_arena_destroy(&self->arena);
    free(self);
    *self_p = NULL;
}

bool sl_preproc_next(sl_preproc *self, sl_pptoken *tok)
{
    for (;;) {
        expand_next(self, &self->main, tok);
        if (tok->kind != SL_TOK_EOF)
            return true;
        if (!(tok->flags & SL_PPF_INCLUDE_END)) {
            pp_eof_token(self, tok);
            return false;
        }
    }
}

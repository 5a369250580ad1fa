/*
 * preproc_internal.h: what preproc.c (memory, hide sets, macros, the raw
 * input, expansion, directives) and preproc_expr.c (the #if expression
 * evaluator) share: the preprocessor's state and a few helpers. Private to
 * the preprocessor; its interface is preproc.h.
 */
#ifndef SL_PREPROC_INTERNAL_H
#define SL_PREPROC_INTERNAL_H

#include "sl/arena.h"
#include "sl/preproc.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct map_entry {
    const char *key;          /* NULL: empty slot */
    size_t len;
    uint32_t hash;
    void *value;
} map_entry;

typedef struct pp_map {
    map_entry *slots;
    size_t cap, count;        /* cap is 0 or a power of two */
} pp_map;

typedef struct tokvec {
    sl_pptoken *v;
    size_t n, cap;
} tokvec;

/* ---------------------------------------------------------------------- */
/* the preprocessor's state                                                */
/* ---------------------------------------------------------------------- */

struct sl_hideset {
    const sl_macro *macro;
    const struct sl_hideset *next;
};
typedef struct sl_hideset sl_hideset;

struct sl_macro {
    const char *name;         /* interned */
    sl_pos pos;               /* of its name in the #define */
    bool funclike;
    int nparams;
    const char **params;      /* interned parameter names */
    sl_pptoken *body;
    int *param;               /* per body token: parameter index or -1 */
    size_t nbody;
};

/* A source text with its line splices removed, kept for the preprocessor's
 * lifetime (token texts point into it); one per distinct source. */
typedef struct pp_text {
    const sl_source *src;
    const char *name;         /* interned */
    char *text;
    size_t len;
    size_t *splices;
    size_t nsplices;
} pp_text;

typedef struct pp_frame {
    sl_scanner sc;
    const pp_text *text;
    size_t cond_base;         /* its conditionals start here */
} pp_frame;

typedef struct pp_cond {
    sl_pos pos;               /* the '#' of the #if / #ifdef / #ifndef */
    const char *directive;    /* "#if", "#ifdef", "#ifndef" */
    bool was_active;          /* the enclosing group is active */
    bool taken;               /* a branch has been chosen */
    bool active;              /* the current branch is being read */
    bool seen_else;
} pp_cond;

/* Where expand_next reads from: a push-back stack in front of either the
 * raw input (raw) or a token list that ends in an EOF at end_pos. */
typedef struct pp_input {
    tokvec pb;
    bool raw;
    const sl_pptoken *list;
    size_t n, i;
    sl_pos end_pos;
} pp_input;

/* A macro argument: its tokens as written, and fully expanded (lazily). */
typedef struct pp_arg {
    const sl_pptoken *raw;
    size_t nraw;
    tokvec expanded;
    bool has_expanded;
} pp_arg;

enum { PP_MAX_ARG_NESTING = 200 };

struct sl_preproc {
    sl_source_set *set;
    sl_diag *diag;
    char **search_path;       /* NULL-terminated copy */

    pp_frame frames[SL_PP_MAX_INCLUDE_DEPTH + 1];
    int nframes;
    pp_cond *conds;
    size_t nconds, capconds;

    pp_map macros;            /* name -> sl_macro * (NULL once #undef'd) */
    pp_map interned;          /* string -> itself */
    pp_map texts;             /* source name -> pp_text * */

    pp_input main;
    tokvec line;              /* scratch: the tokens of a directive line */
    sl_pos eol;               /* position of the end of that line */

    sl_arena *arena;          /* everything token texts point into */
    size_t spent;             /* tokens scanned + produced, for the limit */
    int arg_nesting;          /* recursion of argument pre-expansion */
    bool dead;                /* a limit was hit: only EOF from now on */
    sl_pos eof_pos;
};

/* preproc.c: token vectors */
void pp_tv_push(tokvec *tv, const sl_pptoken *t);
void pp_tv_clear(tokvec *tv);

/* preproc.c: small helpers */
bool pp_is_word(const sl_pptoken *t, const char *word);
/* The spelling of a token for a message, at most 64 bytes of it; the
 * buffer holds 4 * 64 + 8 bytes. */
const char *pp_spell_for_message(const sl_pptoken *t, char *buf);
void pp_eof_token(const sl_preproc *pp, sl_pptoken *tok);
sl_macro *pp_find_macro(sl_preproc *pp, const char *name, size_t len);
/* Fully macro-expands a token list on its own (a macro argument, an #if
 * line) into out. */
void pp_expand_list(sl_preproc *pp, const sl_pptoken *v, size_t n, sl_pos end, tokvec *out);

/* preproc_expr.c: evaluates the #if / #elif line in pp->line (name: the
 * directive's name token, for messages). */
bool pp_eval_if(sl_preproc *pp, const sl_pptoken *name);

#endif

/*
 * preproc.h: the C-style preprocessor of the shading language (sl_preproc).
 *
 * It sits between the raw scanner and the lexer: it pulls preprocessing
 * tokens from the scanner of the current source, obeys directives (#define
 * #undef #if #ifdef #ifndef #elif #else #endif #include #error #warning
 * #pragma), expands macros, and hands the remaining tokens on one at a
 * time. Most users want sl_lexer (lexer.h), which wraps this.
 *
 * Macro expansion follows C: arguments are macro-expanded before they are
 * substituted (except next to # and ##), the result is rescanned together
 * with the rest of the input, and a macro is never expanded inside its own
 * expansion (Prosser's hide sets: every token carries the set of macros it
 * came out of). # (stringizing) and ## (pasting) are supported; variadic
 * macros are not.
 *
 * #include resolves through the source set only (source.h), never through
 * the file system directly.
 *
 * Limits, so that sources received over the network cannot exhaust a
 * worker: include depth SL_PP_MAX_INCLUDE_DEPTH (an include cycle is an
 * error at once), SL_PP_MAX_TOKENS tokens scanned plus produced by
 * expansion per preprocessor (charged as each expansion is built, before it
 * is pushed back, so a macro bomb stops after at most that many tokens of
 * work), SL_PP_MAX_BYTES bytes of preprocessor storage (token texts made
 * by # and ##, hide sets, macro bodies) per preprocessor, #if expressions
 * nested at most SL_PP_MAX_EXPR_DEPTH deep. Memory is bounded by these and
 * the source sizes. Everything the preprocessor allocates is freed by
 * sl_preproc_destroy, and no sooner (token texts point into it).
 */
#ifndef SL_PREPROC_H
#define SL_PREPROC_H

#include <stdbool.h>
#include <stddef.h>

#include "sl/diag.h"
#include "sl/lexer.h"
#include "sl/source.h"

enum {
    SL_PP_MAX_INCLUDE_DEPTH = 64,        /* nested #include levels */
    SL_PP_MAX_TOKENS        = 1 << 21,   /* scanned + expanded, per run */
    SL_PP_MAX_BYTES         = 64 << 20,  /* preprocessor storage, per run */
    SL_PP_MAX_EXPR_DEPTH    = 256,       /* nesting in #if expressions */
};

typedef struct sl_preproc sl_preproc;
typedef struct sl_macro sl_macro;

/* Same contract as sl_lexer_new (lexer.h). */
sl_preproc *sl_preproc_new(sl_source_set *set, const char *main_file,
                           const char *const *search_path, sl_diag *diag);
void sl_preproc_destroy(sl_preproc **self_p);

/* -D and -U (see sl_lexer_define). */
bool sl_preproc_define(sl_preproc *self, const char *definition);
void sl_preproc_undefine(sl_preproc *self, const char *name);

/* The next token after preprocessing. Returns false at the end of the main
 * source (or once the diagnostics are full or a limit was hit); *tok is
 * then an SL_TOK_EOF token positioned at the end of the main source. */
bool sl_preproc_next(sl_preproc *self, sl_pptoken *tok);

/* Storage that lives as long as the preprocessor. */
void *sl_preproc_alloc(sl_preproc *self, size_t size);
const char *sl_preproc_intern(sl_preproc *self, const char *text, size_t len);

/* About the macro a token came from (sl_pptoken.from). */
const char *sl_macro_name(const sl_macro *macro);
sl_pos sl_macro_pos(const sl_macro *macro);

#endif

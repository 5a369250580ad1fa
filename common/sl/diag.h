/*
 * diag.h: compiler diagnostics of the shading language (sl_diag).
 *
 * Every stage of common/sl (preprocessor, lexer, parser, checker) reports
 * errors, warnings and notes here instead of printing them. A diagnostic
 * carries a source position (file name, 1-based line and column) and a
 * message; it is printed the way C compilers print them:
 *
 *     wave.sl:12:7: error: expected ';' after expression
 *         x = 1
 *           ^
 *
 * that is `file:line:col: level: message`, then the source line as written,
 * then a caret line whose padding repeats the tabs of the source line so that
 * the caret sits under the column in any tab setting. Columns count bytes (a
 * tab is one column, like clang); the caret padding writes one space per
 * UTF-8 character, so the caret also lines up after non-ASCII text. A
 * diagnostic with no file prints as `level: message` with no source line.
 *
 * The source line is copied out of the attached source set when the
 * diagnostic is reported (sl_diag_set_sources), so diagnostics stay printable
 * after the sources are gone; lines longer than SL_DIAG_MAX_LINE bytes are
 * not copied (the diagnostic then prints without source and caret).
 *
 * Errors are capped (default SL_DIAG_DEFAULT_MAX_ERRORS): the error that
 * reaches the cap is followed by the note "too many errors emitted, stopping
 * now (limit N)", later errors and warnings are counted but not stored, and
 * sl_diag_full() tells the compiler to stop. Notes that follow a dropped
 * diagnostic are dropped with it.
 *
 * The worker renders diagnostics into a string (sl_diag_to_string) and sends
 * them to the master as text; the master's CLI prints them (sl_diag_print).
 */
#ifndef SL_DIAG_H
#define SL_DIAG_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#if defined(__GNUC__)
#define SL_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define SL_PRINTF(f, a)
#endif

enum {
    SL_DIAG_DEFAULT_MAX_ERRORS = 20,
    SL_DIAG_MAX_STORED_OTHERS  = 200,   /* warnings + notes kept, at most */
    SL_DIAG_MAX_LINE           = 4096,  /* longest source line copied */
};

/* A position in a source: file name (as named in the source set), 1-based
 * line and column (bytes). file == NULL: no position; line == 0: the whole
 * file. The file string is not owned by the position. */
typedef struct sl_pos {
    const char *file;
    int line;
    int col;
} sl_pos;

typedef enum sl_diag_level {
    SL_DIAG_ERROR,
    SL_DIAG_WARNING,
    SL_DIAG_NOTE,
} sl_diag_level;

/* One stored diagnostic; all strings owned by the sl_diag. */
typedef struct sl_diagnostic {
    sl_diag_level level;
    char *file;          /* NULL: no position */
    int line, col;
    char *message;
    char *source_line;   /* the line's text without its newline, or NULL */
} sl_diagnostic;

typedef struct sl_diag sl_diag;
struct sl_source_set;

sl_diag *sl_diag_new(void);
void sl_diag_destroy(sl_diag **self_p);

/* Source lines for carets come from this set (may be NULL: no carets). The
 * set must stay alive while diagnostics are reported, not while printed. */
void sl_diag_set_sources(sl_diag *self, const struct sl_source_set *set);

/* Maximum number of errors stored before stopping; 0 means no cap. */
void sl_diag_set_max_errors(sl_diag *self, int max_errors);

/* Report a diagnostic. The message is printf-formatted. */
void sl_diag_report(sl_diag *self, sl_diag_level level, sl_pos pos,
                    const char *fmt, ...) SL_PRINTF(4, 5);
void sl_diag_vreport(sl_diag *self, sl_diag_level level, sl_pos pos,
                     const char *fmt, va_list ap) SL_PRINTF(4, 0);
void sl_diag_error(sl_diag *self, sl_pos pos, const char *fmt, ...) SL_PRINTF(3, 4);
void sl_diag_warning(sl_diag *self, sl_pos pos, const char *fmt, ...) SL_PRINTF(3, 4);
void sl_diag_note(sl_diag *self, sl_pos pos, const char *fmt, ...) SL_PRINTF(3, 4);

/* Errors / warnings reported so far, including those not stored. */
int sl_diag_error_count(const sl_diag *self);
int sl_diag_warning_count(const sl_diag *self);

/* True once the error cap is reached: the caller should stop compiling. */
bool sl_diag_full(const sl_diag *self);

/* The stored diagnostics, in the order reported. */
size_t sl_diag_count(const sl_diag *self);
const sl_diagnostic *sl_diag_get(const sl_diag *self, size_t index);

/* Forget all diagnostics and counts (the cap and the sources stay). */
void sl_diag_clear(sl_diag *self);

/* Print one diagnostic / all of them in the format above. */
void sl_diag_print_one(const sl_diagnostic *d, FILE *out);
void sl_diag_print(const sl_diag *self, FILE *out);

/* All diagnostics as one NUL-terminated string in the format above; the
 * caller frees it. Never NULL (an empty string when there are none). */
char *sl_diag_to_string(const sl_diag *self);

#endif

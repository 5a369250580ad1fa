/*
 * check.h: the semantic checker of the shading language. It resolves
 * names (scopes, globals, parameters, user functions), types every
 * expression, resolves built-in overloads (builtins.h), inserts implicit
 * conversions (SL_N_CONV), finds the targets of break/continue/return and
 * what each statement may escape to, and rejects recursion (user functions
 * are inlined). uniform/varying are accepted and not enforced.
 *
 * Errors go to diag with file:line:col; an expression that failed has
 * type SL_TY_ERROR and produces no further messages.
 */
#ifndef SL_CHECK_H
#define SL_CHECK_H

#include "sl/ast.h"
#include "sl/diag.h"

/* Returns true when the file has no errors. */
bool sl_check(sl_ast_file *file, sl_arena *arena, sl_diag *diag);

/* The spaces transform() and the casts know, by name: SL_SPACE_* or -1. */
int sl_space_find(const char *name);

/* Walks a format string (format, printf): fn gets each conversion's spec
 * ("%5.2f", its length and conversion letter) with the literal text before
 * it, and once more the trailing literal (spec NULL, conv 0); "%%" comes as
 * a literal ending in one '%' (spec NULL, conv '%'). Returns the number of
 * conversions, -1 for a malformed one. */
int sl_format_walk(const char *fmt, void (*fn)(void *, const char *spec, size_t len, char conv,
                                              const char *lit, size_t litlen), void *arg);

#endif

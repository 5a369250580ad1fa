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

#include <stdatomic.h>

#include "sl/ast.h"
#include "sl/diag.h"

/* Returns true when the file has no errors. cancel: the program's stop
 * flag (a signal) or NULL, looked at before each definition; when it is
 * set, the check stops with the error "interrupted". */
bool sl_check(sl_ast_file *file, sl_arena *arena, const atomic_int *cancel, sl_diag *diag);

/* The spaces transform() and the casts know, by name: SL_SPACE_* or -1. */
#define SL_SPACE_NAMES "\"current\", \"world\", \"object\", \"shader\", \"camera\", " \
    "\"screen\", \"NDC\", \"raster\""
int sl_space_find(const char *name);

#endif

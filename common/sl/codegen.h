/*
 * codegen.h: lowering of a checked syntax tree (check.h) to the bytecode of
 * bytecode.h: slot allocation, scalar lowering of all vector work, inlined
 * user functions, structured control flow with merge tables for the
 * interval and affine modes (paper §4.1), and the limits that keep a
 * shader from the network small (SL_MAX_SLOTS, SL_MAX_CODE, inlining
 * depth SL_MAX_INLINE_DEPTH, nesting after inlining SL_CG_MAX_DEPTH).
 */
#ifndef SL_CODEGEN_H
#define SL_CODEGEN_H

#include "sl/ast.h"
#include "sl/bytecode.h"
#include "sl/diag.h"

enum { SL_MAX_INLINE_DEPTH = 64 };
/* Expressions and statements nested in the code being generated, counted
 * through inlined calls (each function's own nesting is bounded by the
 * parser's SL_PARSE_MAX_DEPTH, but 64 inlined levels of it are not): what
 * bounds the generator's recursion, and so its stack (docs/
 * shading-language.md, Limits). */
enum { SL_CG_MAX_DEPTH = 1000 };

/* Builds the program of a checked file; NULL (errors in diag) when a limit
 * is exceeded. */
sl_program *sl_codegen(const sl_ast_file *file, sl_diag *diag);

#endif

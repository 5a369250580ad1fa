/*
 * parser.h: the single-pass recursive-descent parser of the shading
 * language (RenderMan Interface Specification 3.2, Appendix B, "Shading
 * Language Syntax Summary"), from sl_lexer tokens to the tree of ast.h.
 *
 * Syntax errors are reported to the lexer's sl_diag with file:line:col and
 * what was expected ("expected ';' after expression"); the parser then
 * skips to the next statement (panic mode, as in clox) so that one mistake
 * gives one message. Nesting is bounded (SL_PARSE_MAX_DEPTH) so that a
 * hostile source cannot overflow the stack.
 */
#ifndef SL_PARSER_H
#define SL_PARSER_H

#include <stdatomic.h>

#include "sl/ast.h"
#include "sl/diag.h"
#include "sl/lexer.h"

enum { SL_PARSE_MAX_DEPTH = 200 };   /* nested expressions / statements */

/* Tokens read between two looks at the cancel flag (a token costs well
 * under a microsecond). */
enum { SL_PARSE_CANCEL_EVERY = 4096 };

/* Parses the whole token stream of lx. Never NULL; on errors the tree holds
 * what could be parsed (callers check sl_diag_error_count). cancel: the
 * program's stop flag (a signal) or NULL; when it is found set, the parse
 * ends with the one error "interrupted" as if the text ended there. */
sl_ast_file *sl_parse(sl_lexer *lx, sl_arena *arena, const atomic_int *cancel, sl_diag *diag);

#endif

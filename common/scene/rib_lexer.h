/*
 * rib_lexer.h: the tokens of ASCII RIB (RI Specification 3.2, Appendix C.1
 * "RIB Syntax") and the lexer that cuts a scene text into them.
 *
 * Tokens: request names (bare words), numbers, strings in double quotes
 * (escapes decoded), '[' and ']'. Comments run from '#' to the end of the
 * line ("##" structural comments are comments too). Binary RIB is not
 * supported: its bytes are reported as unexpected.
 *
 * Malformed text (a bad number, an unterminated string, an unexpected
 * character) comes back as one RIB_TOK_BAD token whose `error` says what
 * is wrong; the reader reports it naming the request it is in, and drops
 * that request.
 */
#ifndef SCENE_RIB_LEXER_H
#define SCENE_RIB_LEXER_H

#include <stdbool.h>
#include <stddef.h>

#include "sl/diag.h"

typedef enum rib_token_kind {
    RIB_TOK_EOF,
    RIB_TOK_NAME,        /* text/len: the word as written */
    RIB_TOK_NUMBER,      /* number */
    RIB_TOK_STRING,      /* text/len: the value, escapes decoded */
    RIB_TOK_LBRACKET,
    RIB_TOK_RBRACKET,
    RIB_TOK_BAD,         /* error: the reason */
} rib_token_kind;

typedef struct rib_token {
    rib_token_kind kind;
    sl_pos pos;
    const char *text;    /* valid until the next rib_lexer_next */
    size_t len;
    double number;
    const char *error;   /* RIB_TOK_BAD: "bad number '1.2.3'" */
} rib_token;

typedef struct rib_lexer rib_lexer;

/* The lexer reads text[0..len) (not copied: it must outlive the lexer);
 * positions carry `file` (not copied either). */
rib_lexer *rib_lexer_new(const char *file, const char *text, size_t len);
void rib_lexer_destroy(rib_lexer **self_p);

rib_token rib_lexer_next(rib_lexer *self);

/* The next token when it is a number read without strtod and without
 * error (true, its value in *v), for the long arrays of meshes: no token is
 * made. Else false, and only the blanks and comments before the token are
 * consumed: rib_lexer_next reads it (and says what is wrong with it). */
bool rib_lexer_next_number(rib_lexer *self, double *v);

#endif

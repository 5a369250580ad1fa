/*
 * lexer.h: the tokens of the shading language and the lexer the parser
 * pulls them from (sl_lexer), plus the raw scanner underneath it.
 *
 * Pipeline (docs/shading-language.md, "Preprocessor", "Lexical structure"):
 *
 *   source text --sl_scanner--> preprocessing tokens --sl_preproc-->
 *   (directives, #include, macro expansion) --sl_lexer--> sl_token
 *
 * The scanner (the character-level, clox-style part) turns one source text
 * into preprocessing tokens: identifiers, pp-numbers, strings with their
 * quotes, punctuators (also those only the preprocessor uses: # ## % ~ & |
 * << >>), single unexpected characters. The preprocessor (preproc.h) moves
 * those around. sl_lexer, at the end, classifies them: keywords, number
 * values, string escapes decoded; it reports what is not a token of the
 * language (malformed numbers, unexpected characters, stray '#').
 *
 * Parser-facing API: sl_lexer_new / sl_lexer_next / sl_lexer_peek. Every
 * token carries the position where its text was written: tokens produced by
 * a macro's body carry the position of the macro invocation (and name the
 * macro and its definition); tokens passed as macro arguments keep their
 * own positions. Token text stays valid until the lexer is destroyed.
 */
#ifndef SL_LEXER_H
#define SL_LEXER_H

#include <stdbool.h>
#include <stddef.h>

#include "sl/diag.h"
#include "sl/source.h"

typedef enum sl_token_kind {
    SL_TOK_EOF = 0,          /* end of the main source */
    SL_TOK_IDENT,            /* text: the name (interned) */
    SL_TOK_INT,              /* integer literal: number holds the value */
    SL_TOK_FLOAT,            /* floating literal (has '.' or exponent) */
    SL_TOK_STRING,           /* text/len: the value, escapes decoded */

    /* keywords (docs/shading-language.md lists them) */
    SL_KW_FLOAT, SL_KW_POINT, SL_KW_VECTOR, SL_KW_NORMAL, SL_KW_COLOR,
    SL_KW_STRING, SL_KW_MATRIX, SL_KW_VOID,
    SL_KW_UNIFORM, SL_KW_VARYING, SL_KW_OUTPUT, SL_KW_EXTERN,
    SL_KW_IF, SL_KW_ELSE, SL_KW_FOR, SL_KW_WHILE, SL_KW_BREAK,
    SL_KW_CONTINUE, SL_KW_RETURN,
    SL_KW_SURFACE, SL_KW_DISPLACEMENT, SL_KW_LIGHT, SL_KW_VOLUME, SL_KW_IMAGER,
    SL_KW_ILLUMINATE, SL_KW_ILLUMINANCE, SL_KW_SOLAR,

    /* operators and punctuation */
    SL_TOK_PLUS,          /* +  */
    SL_TOK_MINUS,         /* -  */
    SL_TOK_STAR,          /* *  */
    SL_TOK_SLASH,         /* /  */
    SL_TOK_ASSIGN,        /* =  */
    SL_TOK_PLUS_ASSIGN,   /* += */
    SL_TOK_MINUS_ASSIGN,  /* -= */
    SL_TOK_STAR_ASSIGN,   /* *= */
    SL_TOK_SLASH_ASSIGN,  /* /= */
    SL_TOK_EQ,            /* == */
    SL_TOK_NE,            /* != */
    SL_TOK_LT,            /* <  */
    SL_TOK_GT,            /* >  */
    SL_TOK_LE,            /* <= */
    SL_TOK_GE,            /* >= */
    SL_TOK_AND,           /* && */
    SL_TOK_OR,            /* || */
    SL_TOK_NOT,           /* !  */
    SL_TOK_QUESTION,      /* ?  */
    SL_TOK_COLON,         /* :  */
    SL_TOK_SEMICOLON,     /* ;  */
    SL_TOK_COMMA,         /* ,  */
    SL_TOK_DOT,           /* .  */
    SL_TOK_CARET,         /* ^  */
    SL_TOK_LPAREN,        /* (  */
    SL_TOK_RPAREN,        /* )  */
    SL_TOK_LBRACE,        /* {  */
    SL_TOK_RBRACE,        /* }  */
    SL_TOK_LBRACKET,      /* [  */
    SL_TOK_RBRACKET,      /* ]  */

    /* only between scanner and preprocessor; sl_lexer_next never returns
     * these (it reports them as errors) */
    SL_TOK_PERCENT,       /* %  */
    SL_TOK_TILDE,         /* ~  */
    SL_TOK_AMP,           /* &  */
    SL_TOK_PIPE,          /* |  */
    SL_TOK_SHL,           /* << */
    SL_TOK_SHR,           /* >> */
    SL_TOK_HASH,          /* #  */
    SL_TOK_HASHHASH,      /* ## */
    SL_TOK_PPNUMBER,      /* a pp-number, not yet classified */
    SL_TOK_OTHER,         /* one unexpected character (a UTF-8 sequence) */
    SL_TOK_NEWLINE,       /* end of a directive line */

    SL_TOK__COUNT
} sl_token_kind;

/* A token as the parser sees it. */
typedef struct sl_token {
    sl_token_kind kind;
    const char *text;     /* NUL-terminated: identifier name (interned: equal
                             names have equal pointers), number spelling,
                             string value (escapes decoded; may hold NULs,
                             see len), operator/keyword spelling, "" at EOF */
    size_t len;           /* length of text */
    double number;        /* value of SL_TOK_INT and SL_TOK_FLOAT */
    sl_pos pos;           /* where it was written (see above) */
    const char *macro;    /* the macro whose body produced it, or NULL */
    sl_pos macro_pos;     /* where that macro was #defined */
} sl_token;

/* After reporting an error at tok: if tok came out of a macro body, adds
 * the note "expanded from macro 'NAME'" at the macro's #define. */
void sl_token_note_macro(const sl_token *tok, sl_diag *diag);

/* "identifier", "number", "string", "end of file", or the quoted spelling
 * ("'float'", "'+='"): for messages like "expected ';' before 'else'". */
const char *sl_token_kind_name(sl_token_kind kind);

/* The spelling of a keyword or punctuator kind ("float", "+="), else NULL. */
const char *sl_token_kind_spelling(sl_token_kind kind);

/* ---------------------------------------------------------------------- */
/* the lexer (parser-facing)                                               */
/* ---------------------------------------------------------------------- */

enum { SL_LEXER_LOOKAHEAD = 4 };   /* sl_lexer_peek(self, k): k < this */

typedef struct sl_lexer sl_lexer;

/* A lexer over `main_file` (a name in `set`, or one its loader can load),
 * with `search_path` (NULL-terminated directories, copied; may be NULL) for
 * #include. Diagnostics go to `diag`; the lexer attaches `set` to it
 * (sl_diag_set_sources) for the source lines under messages, so keep `set`
 * alive while anything reports into `diag`, or detach it first. `set` and
 * `diag` must outlive the lexer. A main file that
 * cannot be found is reported ("cannot find source 'x.sl'") and the lexer
 * then yields just SL_TOK_EOF. Never returns NULL. */
sl_lexer *sl_lexer_new(sl_source_set *set, const char *main_file,
                       const char *const *search_path, sl_diag *diag);
void sl_lexer_destroy(sl_lexer **self_p);

/* Predefines a macro the way the -D option of a C compiler does, before
 * the first token is pulled: "NAME" (defines it as 1), "NAME=VALUE",
 * "F(a,b)=a*b". Errors are reported at "<command line>:1:col". Returns
 * false if the definition was rejected. */
bool sl_lexer_define(sl_lexer *self, const char *definition);
/* -U NAME: removes a macro. */
void sl_lexer_undefine(sl_lexer *self, const char *name);

/* Moves the next token into *tok. Returns false when it is SL_TOK_EOF
 * (end of the main file, or compilation stopped because sl_diag_full());
 * EOF carries the position just after the main file's last character and
 * repeats forever. Errors never stop the stream: a bad token is reported
 * and skipped (a malformed number still arrives, as value 0). */
bool sl_lexer_next(sl_lexer *self, sl_token *tok);

/* The token k places ahead without consuming it: k = 0 is what the next
 * sl_lexer_next returns. 0 <= k < SL_LEXER_LOOKAHEAD. The pointer is valid
 * until the next call of sl_lexer_next. */
const sl_token *sl_lexer_peek(sl_lexer *self, int k);

/* An interned copy of s[0..len): equal to the text of identifier tokens
 * with that name (pointer-equal). Valid until the lexer is destroyed. */
const char *sl_lexer_intern(sl_lexer *self, const char *s, size_t len);

/* ---------------------------------------------------------------------- */
/* below: the raw scanner and preprocessing tokens, used by preproc.c      */
/* ---------------------------------------------------------------------- */

enum {
    SL_PPF_BOL          = 1u << 0,  /* first token of its line */
    SL_PPF_SPACE        = 1u << 1,  /* whitespace or a comment before it */
    SL_PPF_UNTERMINATED = 1u << 2,  /* a string missing its closing quote */
    SL_PPF_INCLUDE_END  = 1u << 3,  /* SL_TOK_EOF marking an include's end */
};

struct sl_macro;
struct sl_hideset;

typedef struct sl_pptoken {
    sl_token_kind kind;
    unsigned flags;                 /* SL_PPF_* */
    const char *text;               /* spelling (not NUL-terminated) */
    size_t len;
    sl_pos pos;
    const struct sl_hideset *hs;    /* macros that may not expand it */
    const struct sl_macro *from;    /* macro whose body produced it */
} sl_pptoken;

/* Scans one source text. The text must already have its line splices
 * (backslash-newline) removed by sl_scanner_clean; `splices` lists the
 * offsets in the cleaned text where they were, so that positions are those
 * of the original text. file, text and splices must outlive the tokens. */
typedef struct sl_scanner {
    const char *file;
    const char *start, *cur, *end;
    const size_t *splices;
    size_t nsplices, next_splice;
    int line, col;
    bool bol;          /* the next token starts a line */
    bool directive;    /* inside a directive: a newline is SL_TOK_NEWLINE */
    bool quiet;        /* in a skipped #if group: report nothing but an
                          unterminated comment */
    sl_diag *diag;
} sl_scanner;

/* Removes backslash-newline line splices and makes every line end (LF,
 * CR-LF, or a lone CR as classic Mac files have) one LF, from src[0..len)
 * into dst (at least len bytes); writes the
 * offsets of the splices in dst into splices (at least len / 2 + 1 entries)
 * and their number into *nsplices. Returns the cleaned length. */
size_t sl_scanner_clean(const char *src, size_t len, char *dst,
                        size_t *splices, size_t *nsplices);

void sl_scanner_init(sl_scanner *sc, const char *file, const char *text, size_t len,
                     const size_t *splices, size_t nsplices, sl_diag *diag);

/* The next preprocessing token; SL_TOK_EOF (repeatedly) at the end. */
void sl_scanner_scan(sl_scanner *sc, sl_pptoken *tok);

/* In a directive, after "#include": if the next token starts with '<',
 * scans a header name "<...>" into *tok (kind SL_TOK_STRING, spelling with
 * the brackets; flag SL_PPF_UNTERMINATED when the '>' is missing) and
 * returns true; otherwise scans nothing and returns false. */
bool sl_scanner_header_name(sl_scanner *sc, sl_pptoken *tok);

/* Classifies a pp-number: SL_TOK_INT (digits), SL_TOK_FLOAT (digits with a
 * '.' and/or an exponent: 1.5 .5 5. 1e-3 2.5E+4) or SL_TOK_EOF (malformed). */
sl_token_kind sl_number_kind(const char *text, size_t len);

#endif

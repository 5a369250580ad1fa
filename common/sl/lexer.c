/*
 * lexer.c: the character-level scanner and the parser-facing lexer (see
 * lexer.h).
 *
 * The scanner is a small clox-style loop over one cleaned source text
 * (line splices removed beforehand by sl_scanner_clean): skip whitespace
 * and comments, look at one character, scan the longest token that starts
 * with it. It never fails: an unexpected character becomes an SL_TOK_OTHER
 * token, an unterminated string a string token flagged as such, so that the
 * preprocessor can skip them in #if 0 groups and the lexer can report them
 * where they really reach the program.
 *
 * sl_lexer pulls preprocessed tokens from sl_preproc, classifies them
 * (keywords, number values, string escapes) and keeps a small ring of
 * lookahead tokens for the parser.
 */
#include "sl/lexer.h"
#include "sl/preproc.h"
#include "util/xalloc.h"

#include <locale.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------- */
/* token kinds                                                             */
/* ---------------------------------------------------------------------- */

#define SL_SPELLINGS(X)                                                       \
    X(SL_KW_FLOAT, "float") X(SL_KW_POINT, "point") X(SL_KW_VECTOR, "vector") \
    X(SL_KW_NORMAL, "normal") X(SL_KW_COLOR, "color")                         \
    X(SL_KW_STRING, "string") X(SL_KW_MATRIX, "matrix") X(SL_KW_VOID, "void") \
    X(SL_KW_UNIFORM, "uniform") X(SL_KW_VARYING, "varying")                   \
    X(SL_KW_OUTPUT, "output") X(SL_KW_EXTERN, "extern") X(SL_KW_IF, "if")     \
    X(SL_KW_ELSE, "else") X(SL_KW_FOR, "for") X(SL_KW_WHILE, "while")         \
    X(SL_KW_BREAK, "break") X(SL_KW_CONTINUE, "continue")                     \
    X(SL_KW_RETURN, "return") X(SL_KW_SURFACE, "surface")                     \
    X(SL_KW_DISPLACEMENT, "displacement") X(SL_KW_LIGHT, "light")             \
    X(SL_KW_VOLUME, "volume") X(SL_KW_IMAGER, "imager")                       \
    X(SL_KW_ILLUMINATE, "illuminate") X(SL_KW_ILLUMINANCE, "illuminance")     \
    X(SL_KW_SOLAR, "solar")                                                   \
    X(SL_TOK_PLUS, "+") X(SL_TOK_MINUS, "-") X(SL_TOK_STAR, "*")              \
    X(SL_TOK_SLASH, "/") X(SL_TOK_ASSIGN, "=") X(SL_TOK_PLUS_ASSIGN, "+=")    \
    X(SL_TOK_MINUS_ASSIGN, "-=") X(SL_TOK_STAR_ASSIGN, "*=")                  \
    X(SL_TOK_SLASH_ASSIGN, "/=") X(SL_TOK_EQ, "==") X(SL_TOK_NE, "!=")        \
    X(SL_TOK_LT, "<") X(SL_TOK_GT, ">") X(SL_TOK_LE, "<=") X(SL_TOK_GE, ">=") \
    X(SL_TOK_AND, "&&") X(SL_TOK_OR, "||") X(SL_TOK_NOT, "!")                 \
    X(SL_TOK_QUESTION, "?") X(SL_TOK_COLON, ":") X(SL_TOK_SEMICOLON, ";")     \
    X(SL_TOK_COMMA, ",") X(SL_TOK_DOT, ".") X(SL_TOK_CARET, "^")              \
    X(SL_TOK_LPAREN, "(") X(SL_TOK_RPAREN, ")") X(SL_TOK_LBRACE, "{")         \
    X(SL_TOK_RBRACE, "}") X(SL_TOK_LBRACKET, "[") X(SL_TOK_RBRACKET, "]")     \
    X(SL_TOK_PERCENT, "%") X(SL_TOK_TILDE, "~") X(SL_TOK_AMP, "&")            \
    X(SL_TOK_PIPE, "|") X(SL_TOK_SHL, "<<") X(SL_TOK_SHR, ">>")               \
    X(SL_TOK_HASH, "#") X(SL_TOK_HASHHASH, "##")

static const char *const spellings[SL_TOK__COUNT] = {
#define SPELLING(kind, text) [kind] = text,
    SL_SPELLINGS(SPELLING)
#undef SPELLING
};

static const char *const quoted_names[SL_TOK__COUNT] = {
#define QUOTED(kind, text) [kind] = "'" text "'",
    SL_SPELLINGS(QUOTED)
#undef QUOTED
    [SL_TOK_EOF] = "end of file",
    [SL_TOK_IDENT] = "identifier",
    [SL_TOK_INT] = "number",
    [SL_TOK_FLOAT] = "number",
    [SL_TOK_STRING] = "string",
    [SL_TOK_PPNUMBER] = "number",
    [SL_TOK_OTHER] = "character",
    [SL_TOK_NEWLINE] = "end of line",
};

const char *sl_token_kind_name(sl_token_kind kind)
{
    if ((unsigned)kind >= SL_TOK__COUNT || !quoted_names[kind])
        return "token";
    return quoted_names[kind];
}

const char *sl_token_kind_spelling(sl_token_kind kind)
{
    return (unsigned)kind < SL_TOK__COUNT ? spellings[kind] : NULL;
}

void sl_token_note_macro(const sl_token *tok, sl_diag *diag)
{
    if (tok->macro)
        sl_diag_note(diag, tok->macro_pos, "expanded from macro '%s'", tok->macro);
}

static sl_token_kind keyword(const char *text, size_t len)
{
    for (int k = SL_KW_FLOAT; k <= SL_KW_SOLAR; k++) {
        const char *kw = spellings[k];
        if (strlen(kw) == len && memcmp(kw, text, len) == 0)
            return (sl_token_kind)k;
    }
    return SL_TOK_IDENT;
}

/* ---------------------------------------------------------------------- */
/* characters                                                              */
/* ---------------------------------------------------------------------- */

static bool is_digit(int c) { return c >= '0' && c <= '9'; }
static bool is_alpha(int c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
static bool is_alnum(int c) { return is_alpha(c) || is_digit(c); }

/* Writes a readable form of bytes p[0..n) for messages: printable ASCII as
 * is, anything else as \xNN escapes. buf holds at least 4 * n + 1. */
static const char *describe_bytes(const char *p, size_t n, char *buf)
{
    size_t o = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)p[i];
        if (c >= 0x20 && c < 0x7f)
            buf[o++] = (char)c;
        else
            o += (size_t)sprintf(buf + o, "\\x%02x", c);
    }
    buf[o] = '\0';
    return buf;
}

/* ---------------------------------------------------------------------- */
/* the scanner                                                             */
/* ---------------------------------------------------------------------- */

size_t sl_scanner_clean(const char *src, size_t len, char *dst,
                        size_t *splices, size_t *nsplices)
{
    size_t i = 0, o = 0, n = 0;
    while (i < len) {
        char c = src[i];
        /* a line ends in LF, CRLF or a lone CR (classic Mac): all become LF */
        size_t eol = i + 1 < len && src[i + 1] == '\n' ? 1
                   : i + 1 < len && src[i + 1] == '\r' ? (i + 2 < len && src[i + 2] == '\n' ? 2 : 1)
                   : 0;
        if (c == '\\' && eol) {
            splices[n++] = o;
            i += 1 + eol;
        } else if (c == '\r') {
            dst[o++] = '\n';
            i += i + 1 < len && src[i + 1] == '\n' ? 2 : 1;
        } else {
            dst[o++] = c;
            i++;
        }
    }
    *nsplices = n;
    return o;
}

void sl_scanner_init(sl_scanner *sc, const char *file, const char *text, size_t len,
                     const size_t *splices, size_t nsplices, sl_diag *diag)
{
    memset(sc, 0, sizeof *sc);
    sc->file = file;
    sc->start = sc->cur = text;
    sc->end = text + len;
    sc->splices = splices;
    sc->nsplices = nsplices;
    sc->line = sc->col = 1;
    sc->bol = true;
    sc->diag = diag;
    while (sc->next_splice < nsplices && splices[sc->next_splice] == 0) {
        sc->line++;
        sc->next_splice++;
    }
}

static int peek(const sl_scanner *sc)
{
    return sc->cur < sc->end ? (unsigned char)*sc->cur : -1;
}

static int peek_at(const sl_scanner *sc, size_t k)
{
    return (size_t)(sc->end - sc->cur) > k ? (unsigned char)sc->cur[k] : -1;
}

static sl_pos here(const sl_scanner *sc)
{
    sl_pos pos = { sc->file, sc->line, sc->col };
    return pos;
}

/* Moves past one character, keeping line and column those of the original
 * text: a removed splice before the new character starts a new line. */
static void advance(sl_scanner *sc)
{
    if (*sc->cur++ == '\n') {
        sc->line++;
        sc->col = 1;
    } else {
        sc->col++;
    }
    size_t offset = (size_t)(sc->cur - sc->start);
    while (sc->next_splice < sc->nsplices && sc->splices[sc->next_splice] <= offset) {
        sc->line++;
        sc->col = 1;
        sc->next_splice++;
    }
}

static bool match(sl_scanner *sc, int c)
{
    if (peek(sc) != c)
        return false;
    advance(sc);
    return true;
}

/* Skips whitespace and comments; returns SL_PPF_SPACE if it skipped any.
 * In a directive it stops in front of the newline that ends it. */
static unsigned skip_space(sl_scanner *sc)
{
    unsigned flags = 0;
    for (;;) {
        switch (peek(sc)) {
        case ' ': case '\t': case '\v': case '\f': case '\r':
            advance(sc);
            break;
        case '\n':
            if (sc->directive)
                return flags;
            advance(sc);
            sc->bol = true;
            break;
        case '/':
            if (peek_at(sc, 1) == '/') {
                while (peek(sc) >= 0 && peek(sc) != '\n')
                    advance(sc);
                break;
            }
            if (peek_at(sc, 1) == '*') {
                sl_pos start = here(sc);
                advance(sc);
                advance(sc);
                for (;;) {
                    if (peek(sc) < 0) {
                        sl_diag_error(sc->diag, start, "unterminated /* comment");
                        break;
                    }
                    if (peek(sc) == '*' && peek_at(sc, 1) == '/') {
                        advance(sc);
                        advance(sc);
                        break;
                    }
                    advance(sc);
                }
                break;
            }
            return flags;
        default:
            return flags;
        }
        flags = SL_PPF_SPACE;
    }
}

static void scan_string(sl_scanner *sc, sl_pptoken *tok)
{
    for (;;) {
        int c = peek(sc);
        if (c < 0 || c == '\n') {
            if (!sc->quiet)
                sl_diag_error(sc->diag, tok->pos, "missing terminating '\"' character");
            tok->flags |= SL_PPF_UNTERMINATED;
            return;
        }
        if (c == '"') {
            advance(sc);
            return;
        }
        if (c == '\\') {
            sl_pos at = here(sc);
            advance(sc);
            int e = peek(sc);
            if (e < 0 || e == '\n')
                continue;                 /* reported as unterminated */
            if ((e == 0 || !strchr("nt\"\\r'abfv", e)) && !sc->quiet) {
                char buf[8];
                sl_diag_error(sc->diag, at, "unknown escape sequence '\\%s'",
                              describe_bytes(sc->cur, 1, buf));
            }
        }
        advance(sc);
    }
}

static void scan_number(sl_scanner *sc, int first)
{
    int prev = first;
    for (;;) {
        int c = peek(sc);
        if (is_alnum(c) || c == '.' ||
            ((c == '+' || c == '-') && (prev == 'e' || prev == 'E'))) {
            prev = c;
            advance(sc);
        } else {
            return;
        }
    }
}

static sl_token_kind scan_punct(sl_scanner *sc, int c)
{
    switch (c) {
    case '+': return match(sc, '=') ? SL_TOK_PLUS_ASSIGN : SL_TOK_PLUS;
    case '-': return match(sc, '=') ? SL_TOK_MINUS_ASSIGN : SL_TOK_MINUS;
    case '*': return match(sc, '=') ? SL_TOK_STAR_ASSIGN : SL_TOK_STAR;
    case '/': return match(sc, '=') ? SL_TOK_SLASH_ASSIGN : SL_TOK_SLASH;
    case '=': return match(sc, '=') ? SL_TOK_EQ : SL_TOK_ASSIGN;
    case '!': return match(sc, '=') ? SL_TOK_NE : SL_TOK_NOT;
    case '<':
        if (match(sc, '='))
            return SL_TOK_LE;
        return match(sc, '<') ? SL_TOK_SHL : SL_TOK_LT;
    case '>':
        if (match(sc, '='))
            return SL_TOK_GE;
        return match(sc, '>') ? SL_TOK_SHR : SL_TOK_GT;
    case '&': return match(sc, '&') ? SL_TOK_AND : SL_TOK_AMP;
    case '|': return match(sc, '|') ? SL_TOK_OR : SL_TOK_PIPE;
    case '#': return match(sc, '#') ? SL_TOK_HASHHASH : SL_TOK_HASH;
    case '%': return SL_TOK_PERCENT;
    case '~': return SL_TOK_TILDE;
    case '^': return SL_TOK_CARET;
    case '?': return SL_TOK_QUESTION;
    case ':': return SL_TOK_COLON;
    case ';': return SL_TOK_SEMICOLON;
    case ',': return SL_TOK_COMMA;
    case '.': return SL_TOK_DOT;
    case '(': return SL_TOK_LPAREN;
    case ')': return SL_TOK_RPAREN;
    case '{': return SL_TOK_LBRACE;
    case '}': return SL_TOK_RBRACE;
    case '[': return SL_TOK_LBRACKET;
    case ']': return SL_TOK_RBRACKET;
    default:
        break;
    }
    /* an unexpected character: take a whole UTF-8 sequence as one */
    if (c >= 0xC0 && c < 0xF8) {
        int more = c >= 0xF0 ? 3 : c >= 0xE0 ? 2 : 1;
        while (more-- > 0 && (peek(sc) & 0xC0) == 0x80 && peek(sc) >= 0)
            advance(sc);
    }
    return SL_TOK_OTHER;
}

void sl_scanner_scan(sl_scanner *sc, sl_pptoken *tok)
{
    unsigned flags = skip_space(sc);
    tok->pos = here(sc);
    tok->flags = flags | (sc->bol ? SL_PPF_BOL : 0);
    tok->hs = NULL;
    tok->from = NULL;
    tok->text = sc->cur;

    int c = peek(sc);
    if (c < 0) {
        tok->kind = SL_TOK_EOF;
        tok->len = 0;
        return;
    }
    advance(sc);
    if (c == '\n') {                   /* only seen inside a directive */
        tok->kind = SL_TOK_NEWLINE;
        tok->len = 1;
        sc->bol = true;
        return;
    }
    sc->bol = false;

    if (is_alpha(c)) {
        while (is_alnum(peek(sc)))
            advance(sc);
        tok->kind = SL_TOK_IDENT;
    } else if (is_digit(c) || (c == '.' && is_digit(peek(sc)))) {
        scan_number(sc, c);
        tok->kind = SL_TOK_PPNUMBER;
    } else if (c == '"') {
        tok->kind = SL_TOK_STRING;
        scan_string(sc, tok);
    } else {
        tok->kind = scan_punct(sc, c);
    }
    tok->len = (size_t)(sc->cur - tok->text);
}

bool sl_scanner_header_name(sl_scanner *sc, sl_pptoken *tok)
{
    unsigned flags = skip_space(sc);
    if (peek(sc) != '<')
        return false;
    tok->pos = here(sc);
    tok->flags = flags;
    tok->hs = NULL;
    tok->from = NULL;
    tok->text = sc->cur;
    tok->kind = SL_TOK_STRING;
    advance(sc);
    while (peek(sc) >= 0 && peek(sc) != '\n' && peek(sc) != '>')
        advance(sc);
    if (!match(sc, '>'))
        tok->flags |= SL_PPF_UNTERMINATED;
    tok->len = (size_t)(sc->cur - tok->text);
    sc->bol = false;
    return true;
}

sl_token_kind sl_number_kind(const char *text, size_t len)
{
    size_t i = 0, before = 0, after = 0;
    bool is_float = false;
    while (i < len && is_digit(text[i])) {
        i++;
        before++;
    }
    if (i < len && text[i] == '.') {
        i++;
        while (i < len && is_digit(text[i])) {
            i++;
            after++;
        }
        is_float = true;
    }
    if (before + after == 0)
        return SL_TOK_EOF;
    if (i < len && (text[i] == 'e' || text[i] == 'E')) {
        i++;
        if (i < len && (text[i] == '+' || text[i] == '-'))
            i++;
        size_t exp = 0;
        while (i < len && is_digit(text[i])) {
            i++;
            exp++;
        }
        if (exp == 0)
            return SL_TOK_EOF;
        is_float = true;
    }
    if (i != len)
        return SL_TOK_EOF;
    return is_float ? SL_TOK_FLOAT : SL_TOK_INT;
}

/* ---------------------------------------------------------------------- */
/* the lexer                                                               */
/* ---------------------------------------------------------------------- */

struct sl_lexer {
    sl_preproc *pp;
    sl_diag *diag;
    sl_token ahead[SL_LEXER_LOOKAHEAD];   /* ring of peeked tokens */
    int head, count;
    locale_t c_locale;                    /* numbers read in the C locale */
};

sl_lexer *sl_lexer_new(sl_source_set *set, const char *main_file,
                       const char *const *search_path, sl_diag *diag)
{
    sl_lexer *self = xcalloc(1, sizeof *self);
    self->diag = diag;
    self->pp = sl_preproc_new(set, main_file, search_path, diag);
    self->c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
    return self;
}

void sl_lexer_destroy(sl_lexer **self_p)
{
    if (!self_p || !*self_p)
        return;
    sl_lexer *self = *self_p;
    sl_preproc_destroy(&self->pp);
    if (self->c_locale != (locale_t)0)
        freelocale(self->c_locale);
    free(self);
    *self_p = NULL;
}

bool sl_lexer_define(sl_lexer *self, const char *definition)
{
    return sl_preproc_define(self->pp, definition);
}

void sl_lexer_undefine(sl_lexer *self, const char *name)
{
    sl_preproc_undefine(self->pp, name);
}

const char *sl_lexer_intern(sl_lexer *self, const char *s, size_t len)
{
    return sl_preproc_intern(self->pp, s, len);
}

/* Reads a C-locale decimal number whatever the process locale is: the
 * value of a literal must not depend on the host's settings. */
static double read_number(sl_lexer *self, const char *text)
{
    if (self->c_locale == (locale_t)0)
        return strtod(text, NULL);
    locale_t old = uselocale(self->c_locale);
    double value = strtod(text, NULL);
    uselocale(old);
    return value;
}

/* At most 64 bytes of a spelling for a message, with "..." if longer. */
static const char *excerpt(const char *text, size_t len, char *buf)
{
    char tmp[4 * 64 + 1];
    describe_bytes(text, len > 64 ? 64 : len, tmp);
    sprintf(buf, "%s%s", tmp, len > 64 ? "..." : "");
    return buf;
}

/* The decoded value of a string token, in preprocessor storage. */
static void decode_string(sl_lexer *self, const sl_pptoken *pt, sl_token *tok)
{
    const char *p = pt->text + 1;
    const char *end = pt->text + pt->len;
    if (!(pt->flags & SL_PPF_UNTERMINATED) && end > p)
        end--;                              /* the closing quote */
    char *out = sl_preproc_alloc(self->pp, (size_t)(end - p) + 1);
    size_t n = 0;
    while (p < end) {
        char c = *p++;
        if (c == '\\' && p < end) {
            c = *p++;
            switch (c) {
            case 'n': c = '\n'; break;
            case 't': c = '\t'; break;
            case 'r': c = '\r'; break;
            case 'a': c = '\a'; break;
            case 'b': c = '\b'; break;
            case 'f': c = '\f'; break;
            case 'v': c = '\v'; break;
            default: break;                 /* \" \\ \' and unknown ones */
            }
        }
        out[n++] = c;
    }
    out[n] = '\0';
    tok->text = out;
    tok->len = n;
}

/* Turns a preprocessed token into a parser token; false (after reporting
 * it) if it is not a token of the language. */
static bool classify(sl_lexer *self, const sl_pptoken *pt, sl_token *tok)
{
    char buf[4 * 64 + 8];
    tok->kind = pt->kind;
    tok->pos = pt->pos;
    tok->number = 0;
    tok->macro = pt->from ? sl_macro_name(pt->from) : NULL;
    if (pt->from) {
        tok->macro_pos = sl_macro_pos(pt->from);
    } else {
        sl_pos none = { NULL, 0, 0 };
        tok->macro_pos = none;
    }

    switch (pt->kind) {
    case SL_TOK_IDENT:
        tok->kind = keyword(pt->text, pt->len);
        if (tok->kind == SL_TOK_IDENT) {
            tok->text = sl_preproc_intern(self->pp, pt->text, pt->len);
            tok->len = pt->len;
        } else {
            tok->text = spellings[tok->kind];
            tok->len = strlen(tok->text);
        }
        return true;

    case SL_TOK_PPNUMBER:
        tok->text = sl_preproc_intern(self->pp, pt->text, pt->len);
        tok->len = pt->len;
        tok->kind = sl_number_kind(pt->text, pt->len);
        if (tok->kind == SL_TOK_EOF) {
            sl_diag_error(self->diag, pt->pos, "malformed number '%s'",
                          excerpt(pt->text, pt->len, buf));
            tok->kind = SL_TOK_FLOAT;
            return true;
        }
        tok->number = read_number(self, tok->text);
        if (isinf(tok->number)) {
            sl_diag_error(self->diag, pt->pos, "number '%s' is too large",
                          excerpt(pt->text, pt->len, buf));
            tok->number = 0;
        }
        return true;

    case SL_TOK_STRING:
        decode_string(self, pt, tok);
        return true;

    case SL_TOK_HASH:
    case SL_TOK_HASHHASH:
        sl_diag_error(self->diag, pt->pos, "stray '%s' in program", spellings[pt->kind]);
        return false;

    case SL_TOK_PERCENT: case SL_TOK_TILDE: case SL_TOK_AMP:
    case SL_TOK_PIPE: case SL_TOK_SHL: case SL_TOK_SHR:
        sl_diag_error(self->diag, pt->pos,
                      "operator '%s' is not part of the shading language",
                      spellings[pt->kind]);
        return false;

    case SL_TOK_OTHER:
        sl_diag_error(self->diag, pt->pos, "unexpected character '%s'",
                      excerpt(pt->text, pt->len, buf));
        return false;

    case SL_TOK_NEWLINE:
    case SL_TOK_EOF:
    case SL_TOK_INT:
    case SL_TOK_FLOAT:
    case SL_TOK__COUNT:
        return false;

    default:                                /* keywords never come raw */
        tok->text = spellings[pt->kind];
        tok->len = strlen(tok->text);
        return true;
    }
}

/* Produces the next classified token. */
static void produce(sl_lexer *self, sl_token *tok)
{
    sl_pptoken pt;
    for (;;) {
        if (!sl_preproc_next(self->pp, &pt)) {
            memset(tok, 0, sizeof *tok);
            tok->kind = SL_TOK_EOF;
            tok->text = "";
            tok->pos = pt.pos;
            return;
        }
        if (classify(self, &pt, tok))
            return;
    }
}

bool sl_lexer_next(sl_lexer *self, sl_token *tok)
{
    if (self->count > 0) {
        *tok = self->ahead[self->head];
        self->head = (self->head + 1) % SL_LEXER_LOOKAHEAD;
        self->count--;
    } else {
        produce(self, tok);
    }
    return tok->kind != SL_TOK_EOF;
}

const sl_token *sl_lexer_peek(sl_lexer *self, int k)
{
    if (k < 0)
        k = 0;
    if (k >= SL_LEXER_LOOKAHEAD)
        k = SL_LEXER_LOOKAHEAD - 1;
    while (self->count <= k) {
        produce(self, &self->ahead[(self->head + self->count) % SL_LEXER_LOOKAHEAD]);
        self->count++;
    }
    return &self->ahead[(self->head + k) % SL_LEXER_LOOKAHEAD];
}

/*
 * rib_lexer.c: ASCII RIB tokens (see rib_lexer.h).
 *
 * A hand-written scanner in the clox manner: one switch on the first byte
 * of a token. Numbers are checked against the RIB number syntax
 * ([+-] digits [. digits] [e [+-] digits], digits on at least one side of
 * the point) over the whole run of non-delimiter bytes, so "1.2.3" and
 * "12abc" are one bad number, not two tokens. A run of unexpected bytes is
 * reported once.
 */
#include "scene/rib_lexer.h"
#include "sl/strbuf.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct rib_lexer {
    const char *file;
    const char *text, *end, *p;
    const char *line_start;
    int line;
    sl_strbuf str;          /* the last decoded string */
    char err[ERR_LEN];      /* the last bad token's reason */
};

rib_lexer *rib_lexer_new(const char *file, const char *text, size_t len)
{
    rib_lexer *self = xrealloc(NULL, sizeof *self);
    memset(self, 0, sizeof *self);
    self->file = file;
    self->text = self->p = self->line_start = text;
    self->end = text + len;
    self->line = 1;
    /* a UTF-8 byte order mark is not part of the scene */
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        self->p += 3;
    return self;
}

void rib_lexer_destroy(rib_lexer **self_p)
{
    if (!self_p || !*self_p)
        return;
    free((*self_p)->str.data);
    free(*self_p);
    *self_p = NULL;
}

/* ---------------------------------------------------------------------- */
/* characters                                                              */
/* ---------------------------------------------------------------------- */

static sl_pos pos_at(const rib_lexer *self, const char *p)
{
    sl_pos pos = { self->file, self->line, (int)(p - self->line_start) + 1 };
    return pos;
}

static void newline(rib_lexer *self, const char *after)
{
    self->line++;
    self->line_start = after;
}

static bool is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

static bool is_digit(char c) { return c >= '0' && c <= '9'; }

static bool is_name_start(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}

static bool is_name_char(char c) { return is_name_start(c) || is_digit(c); }

/* Bytes that end a number or a bad word. */
static bool is_delimiter(char c)
{
    return is_space(c) || c == '[' || c == ']' || c == '"' || c == '#';
}

static bool starts_token(char c)
{
    return is_space(c) || is_name_start(c) || is_digit(c) || c == '[' || c == ']' ||
           c == '"' || c == '#' || c == '+' || c == '-' || c == '.';
}

static void skip_space_and_comments(rib_lexer *self)
{
    while (self->p < self->end) {
        char c = *self->p;
        if (c == '\n' || c == '\r') {      /* LF, CR-LF or a lone CR (classic Mac) */
            self->p++;
            if (c == '\r' && self->p < self->end && *self->p == '\n')
                self->p++;
            newline(self, self->p);
        } else if (is_space(c)) {
            self->p++;
        } else if (c == '#') {
            while (self->p < self->end && *self->p != '\n' && *self->p != '\r')
                self->p++;
        } else {
            return;
        }
    }
}

/* Turns *t into a bad token with the printf-formatted reason. */
static void bad(rib_lexer *self, rib_token *t, const char *fmt, ...) SL_PRINTF(3, 4);
static void bad(rib_lexer *self, rib_token *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    err_vset(self->err, sizeof self->err, fmt, ap);
    va_end(ap);
    t->kind = RIB_TOK_BAD;
    t->error = self->err;
}

static rib_token make(rib_lexer *self, rib_token_kind kind, const char *start)
{
    rib_token t = { .kind = kind, .pos = pos_at(self, start), .text = start,
                    .len = (size_t)(self->p - start) };
    return t;
}

/* ---------------------------------------------------------------------- */
/* numbers                                                                 */
/* ---------------------------------------------------------------------- */

/* How a run of bytes reads as a number (scan_number). */
typedef enum number_kind {
    NUMBER_BAD,          /* not the RIB number syntax */
    NUMBER_FAST,         /* its value is had without strtod */
    NUMBER_STRTOD,       /* its value is strtod's */
} number_kind;

/* Reads the number at p (before end) in one pass: its syntax and its value
 * together, then (a number must end at a delimiter) the rest of the run of
 * non-delimiter bytes, so that "1.2.3" and "12abc" are one bad token; *stop
 * is where the token ends. The value (*v, NUMBER_FAST) is had without
 * strtod when it can be the same double: at most 15 significant digits
 * (the whole number then fits a double exactly) and a power of ten within
 * 10^22 (exact too), so that the one multiplication or division is the
 * correctly rounded result strtod gives (Clinger 1990, the fast path); any
 * other number is NUMBER_STRTOD (tests/scene/test_scene_numbers.c holds
 * both to strtod). */
static number_kind scan_number(const char *p, const char *end, const char **stop, double *v)
{
    static const double pow10[] = { 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10,
                                    1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19,
                                    1e20, 1e21, 1e22 };
    const char *q = p;
    bool negative = false, ok = true;
    uint64_t m = 0;                    /* the significant digits (when at most 15) */
    if (q < end && (*q == '+' || *q == '-'))
        negative = *q++ == '-';
    /* whole part: leading zeros, then the significant digits */
    const char *d0 = q;
    while (q < end && *q == '0')
        q++;
    const char *s0 = q;
    for (; q < end && is_digit(*q); q++)
        m = m * 10 + (uint64_t)(*q - '0');
    long significant = q - s0, scale = 0;    /* value: m * 10^(scale + exponent) */
    long digits = q - d0;
    if (q < end && *q == '.') {
        const char *f0 = ++q;
        if (m == 0)                    /* zeros after the point before the first digit */
            while (q < end && *q == '0')
                q++;
        const char *f1 = q;
        for (; q < end && is_digit(*q); q++)
            m = m * 10 + (uint64_t)(*q - '0');
        significant += q - f1;
        scale = -(q - f0);
        digits += q - f0;
    }
    /* (m wraps past 19 digits: then significant > 15 and m is not used) */
    ok = digits > 0;
    long exponent = 0;
    if (ok && q < end && (*q == 'e' || *q == 'E')) {
        q++;
        bool exp_negative = false;
        if (q < end && (*q == '+' || *q == '-'))
            exp_negative = *q++ == '-';
        size_t exp_digits = 0;
        for (; q < end && is_digit(*q); q++, exp_digits++)
            if (exponent < 100000) exponent = exponent * 10 + (*q - '0');
        ok = exp_digits > 0;
        if (exp_negative) exponent = -exponent;
    }
    if (q < end && !is_delimiter(*q)) {    /* more of the word: not a number */
        ok = false;
        while (q < end && !is_delimiter(*q))
            q++;
    }
    *stop = q;
    if (!ok)
        return NUMBER_BAD;
    long e = scale + exponent;
    if (significant <= 15 && (m == 0 || (e >= -22 && e <= 22))) {
        double x = m == 0 ? 0.0 : e >= 0 ? (double)m * pow10[e] : (double)m / pow10[-e];
        *v = negative ? -x : x;
        return NUMBER_FAST;
    }
    return NUMBER_STRTOD;
}

static rib_token lex_number(rib_lexer *self)
{
    const char *start = self->p;
    double v = 0;
    number_kind kind = scan_number(start, self->end, &self->p, &v);
    rib_token t = make(self, RIB_TOK_NUMBER, start);
    t.number = v;
    int shown = t.len > 40 ? 40 : (int)t.len;
    const char *more = t.len > 40 ? "..." : "";
    if (kind == NUMBER_BAD) {
        bad(self, &t, "bad number '%.*s%s'", shown, start, more);
        return t;
    }
    char buf[512];
    if (t.len >= sizeof buf) {
        bad(self, &t, "number '%.*s%s' is too long", shown, start, more);
        return t;
    }
    if (kind == NUMBER_FAST)
        return t;
    memcpy(buf, start, t.len);
    buf[t.len] = '\0';
    t.number = strtod(buf, NULL);
    if (!isfinite(t.number)) {
        bad(self, &t, "number '%.*s%s' is out of range", shown, start, more);
    }
    return t;
}

bool rib_lexer_next_number(rib_lexer *self, double *v)
{
    skip_space_and_comments(self);
    if (self->p >= self->end)
        return false;
    char c = *self->p;
    if (!is_digit(c) && c != '+' && c != '-' && c != '.')
        return false;
    const char *stop;
    if (scan_number(self->p, self->end, &stop, v) != NUMBER_FAST || stop - self->p >= 512)
        return false;                  /* rib_lexer_next reads it (strtod, or its error) */
    self->p = stop;
    return true;
}

/* ---------------------------------------------------------------------- */
/* strings                                                                 */
/* ---------------------------------------------------------------------- */

/* Decodes one escape after a backslash at self->p[-1]; RI Spec C.1 lists
 * \n \r \t \b \f \\ \" and octal \ddd; a backslash before a line end
 * continues the string on the next line. Others stand for themselves. */
static void lex_escape(rib_lexer *self)
{
    char c = *self->p++;
    switch (c) {
    case 'n': sl_strbuf_putc(&self->str, '\n'); return;
    case 'r': sl_strbuf_putc(&self->str, '\r'); return;
    case 't': sl_strbuf_putc(&self->str, '\t'); return;
    case 'b': sl_strbuf_putc(&self->str, '\b'); return;
    case 'f': sl_strbuf_putc(&self->str, '\f'); return;
    case '\r':
        if (self->p < self->end && *self->p == '\n')
            self->p++;
        newline(self, self->p);
        return;
    case '\n': newline(self, self->p); return;
    default: break;
    }
    if (c >= '0' && c <= '7') {
        int v = c - '0';
        for (int k = 0; k < 2 && self->p < self->end && *self->p >= '0' && *self->p <= '7'; k++)
            v = v * 8 + (*self->p++ - '0');
        sl_strbuf_putc(&self->str, (char)(v & 0xFF));
        return;
    }
    sl_strbuf_putc(&self->str, c);
}

static rib_token lex_string(rib_lexer *self)
{
    const char *start = self->p++;
    sl_pos pos = pos_at(self, start);
    self->str.len = 0;
    sl_strbuf_put(&self->str, "", 0);
    while (self->p < self->end && *self->p != '"' && *self->p != '\n' && *self->p != '\r') {
        if (*self->p == '\\' && self->p + 1 < self->end) {
            self->p++;
            lex_escape(self);
        } else {
            sl_strbuf_putc(&self->str, *self->p++);
        }
    }
    rib_token t;
    memset(&t, 0, sizeof t);
    t.pos = pos;
    if (self->p >= self->end || *self->p != '"') {
        bad(self, &t, "unterminated string (missing '\"' before the end of the line)");
        return t;
    }
    self->p++;
    t.kind = RIB_TOK_STRING;
    t.text = self->str.data;
    t.len = self->str.len;
    return t;
}

/* ---------------------------------------------------------------------- */
/* the token switch                                                        */
/* ---------------------------------------------------------------------- */

static rib_token lex_unexpected(rib_lexer *self)
{
    const char *start = self->p;
    unsigned char c = (unsigned char)*self->p;
    rib_token t = make(self, RIB_TOK_BAD, start);
    if (c >= 0x20 && c < 0x7F)
        bad(self, &t, "unexpected character '%c'", c);
    else
        bad(self, &t, "unexpected byte 0x%02x (binary RIB is not supported)", c);
    while (self->p < self->end && !starts_token(*self->p))
        self->p++;
    if (self->p == start)
        self->p++;
    return t;
}

rib_token rib_lexer_next(rib_lexer *self)
{
    skip_space_and_comments(self);
    if (self->p >= self->end)
        return make(self, RIB_TOK_EOF, self->p);
    char c = *self->p;
    if (c == '[' || c == ']') {
        const char *start = self->p++;
        return make(self, c == '[' ? RIB_TOK_LBRACKET : RIB_TOK_RBRACKET, start);
    }
    if (c == '"')
        return lex_string(self);
    if (is_digit(c) || c == '+' || c == '-' || c == '.')
        return lex_number(self);
    if (is_name_start(c)) {
        const char *start = self->p;
        while (self->p < self->end && is_name_char(*self->p))
            self->p++;
        return make(self, RIB_TOK_NAME, start);
    }
    return lex_unexpected(self);
}

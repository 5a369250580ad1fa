/*
 * diag.c: compiler diagnostics of the shading language (see diag.h).
 *
 * Diagnostics are stored in a growing array; every string in a stored
 * diagnostic is a private copy (file name, message, the source line), so
 * the sources may be freed before the diagnostics are printed. Formatting
 * goes through one small string builder used both for FILE output and for
 * sl_diag_to_string, so both produce byte-identical text.
 */
#include "sl/diag.h"
#include "sl/strbuf.h"
#include "sl/source.h"
#include "util/xalloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

struct sl_diag {
    sl_diagnostic *items;
    size_t count, cap;
    int errors, warnings;
    int max_errors;
    size_t others_stored;            /* warnings + notes stored */
    bool full;                       /* cap reached: store no more */
    bool dropped_last;               /* the last error/warning was dropped */
    const sl_source_set *sources;
};

static const char *level_name(sl_diag_level level)
{
    switch (level) {
    case SL_DIAG_ERROR:   return "error";
    case SL_DIAG_WARNING: return "warning";
    case SL_DIAG_NOTE:    return "note";
    }
    return "error";
}

/* Appends one diagnostic: the header line, then the source and caret lines
 * when the source line is known and the column lies on it (or just past
 * its end, where "expected ';'" errors point). */
static void format_one(sl_strbuf *b, const sl_diagnostic *d)
{
    char num[32];
    if (d->file) {
        sl_strbuf_puts(b, d->file);
        if (d->line > 0) {
            snprintf(num, sizeof num, ":%d:%d", d->line, d->col);
            sl_strbuf_puts(b, num);
        }
        sl_strbuf_puts(b, ": ");
    }
    sl_strbuf_puts(b, level_name(d->level));
    sl_strbuf_puts(b, ": ");
    sl_strbuf_puts(b, d->message);
    sl_strbuf_putc(b, '\n');

    if (!d->source_line || d->col < 1)
        return;
    size_t len = strlen(d->source_line);
    size_t before = (size_t)d->col - 1;
    if (before > len)
        return;
    sl_strbuf_puts(b, d->source_line);
    sl_strbuf_putc(b, '\n');
    for (size_t i = 0; i < before; i++) {
        unsigned char c = (unsigned char)d->source_line[i];
        if (c == '\t')
            sl_strbuf_putc(b, '\t');
        else if ((c & 0xC0) != 0x80)   /* one space per UTF-8 character */
            sl_strbuf_putc(b, ' ');
    }
    sl_strbuf_puts(b, "^\n");
}

/* ---------------------------------------------------------------------- */
/* the class                                                               */
/* ---------------------------------------------------------------------- */

sl_diag *sl_diag_new(void)
{
    sl_diag *self = xmalloc(sizeof *self);
    memset(self, 0, sizeof *self);
    self->max_errors = SL_DIAG_DEFAULT_MAX_ERRORS;
    return self;
}

static void free_items(sl_diag *self)
{
    for (size_t i = 0; i < self->count; i++) {
        free(self->items[i].file);
        free(self->items[i].message);
        free(self->items[i].source_line);
    }
    free(self->items);
    self->items = NULL;
    self->count = self->cap = 0;
}

void sl_diag_destroy(sl_diag **self_p)
{
    if (!self_p || !*self_p)
        return;
    free_items(*self_p);
    free(*self_p);
    *self_p = NULL;
}

void sl_diag_set_sources(sl_diag *self, const sl_source_set *set)
{
    self->sources = set;
}

void sl_diag_set_max_errors(sl_diag *self, int max_errors)
{
    self->max_errors = max_errors < 0 ? 0 : max_errors;
}

void sl_diag_clear(sl_diag *self)
{
    free_items(self);
    self->errors = self->warnings = 0;
    self->others_stored = 0;
    self->full = self->dropped_last = false;
}

static void store(sl_diag *self, sl_diag_level level, sl_pos pos, char *message)
{
    if (self->count == self->cap) {
        self->cap = self->cap ? 2 * self->cap : 16;
        self->items = xrealloc(self->items, self->cap * sizeof *self->items);
    }
    sl_diagnostic *d = &self->items[self->count++];
    d->level = level;
    d->file = pos.file ? xstrndup(pos.file, strlen(pos.file)) : NULL;
    d->line = pos.file ? pos.line : 0;
    d->col = pos.file && pos.line > 0 ? pos.col : 0;
    d->message = message;
    d->source_line = NULL;
    if (pos.file && pos.line > 0 && self->sources) {
        size_t len;
        const char *text = sl_source_set_line(self->sources, pos.file, pos.line, &len);
        if (text && len <= SL_DIAG_MAX_LINE)
            d->source_line = xstrndup(text, len);
    }
    if (level != SL_DIAG_ERROR)
        self->others_stored++;
}

void sl_diag_vreport(sl_diag *self, sl_diag_level level, sl_pos pos,
                     const char *fmt, va_list ap)
{
    if (level == SL_DIAG_ERROR)
        self->errors++;
    else if (level == SL_DIAG_WARNING)
        self->warnings++;

    bool drop;
    if (level == SL_DIAG_NOTE)
        drop = self->dropped_last || self->others_stored >= SL_DIAG_MAX_STORED_OTHERS;
    else
        drop = self->full || (level == SL_DIAG_WARNING &&
                              self->others_stored >= SL_DIAG_MAX_STORED_OTHERS);
    if (level != SL_DIAG_NOTE)
        self->dropped_last = drop;
    if (drop)
        return;

    va_list ap2;
    va_copy(ap2, ap);
    int n = vsnprintf(NULL, 0, fmt, ap2);
    va_end(ap2);
    if (n < 0)
        n = 0;
    char *message = xmalloc((size_t)n + 1);
    vsnprintf(message, (size_t)n + 1, fmt, ap);
    store(self, level, pos, message);

    if (level == SL_DIAG_ERROR && self->max_errors > 0 &&
        self->errors >= self->max_errors) {
        self->full = true;
        char note[96];
        snprintf(note, sizeof note,
                 "too many errors emitted, stopping now (limit %d)", self->max_errors);
        sl_pos none = { NULL, 0, 0 };
        store(self, SL_DIAG_NOTE, none, xstrndup(note, strlen(note)));
        self->dropped_last = true;   /* notes of the last error go too */
    }
}

void sl_diag_report(sl_diag *self, sl_diag_level level, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(self, level, pos, fmt, ap);
    va_end(ap);
}

void sl_diag_error(sl_diag *self, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(self, SL_DIAG_ERROR, pos, fmt, ap);
    va_end(ap);
}

void sl_diag_warning(sl_diag *self, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(self, SL_DIAG_WARNING, pos, fmt, ap);
    va_end(ap);
}

void sl_diag_note(sl_diag *self, sl_pos pos, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(self, SL_DIAG_NOTE, pos, fmt, ap);
    va_end(ap);
}

int sl_diag_error_count(const sl_diag *self) { return self->errors; }
int sl_diag_warning_count(const sl_diag *self) { return self->warnings; }
bool sl_diag_full(const sl_diag *self) { return self->full; }
size_t sl_diag_count(const sl_diag *self) { return self->count; }

const sl_diagnostic *sl_diag_get(const sl_diag *self, size_t index)
{
    return index < self->count ? &self->items[index] : NULL;
}

void sl_diag_print_one(const sl_diagnostic *d, FILE *out)
{
    sl_strbuf b = { 0 };
    format_one(&b, d);
    if (b.len)
        fwrite(b.data, 1, b.len, out);
    free(b.data);
}

void sl_diag_print(const sl_diag *self, FILE *out)
{
    for (size_t i = 0; i < self->count; i++)
        sl_diag_print_one(&self->items[i], out);
}

char *sl_diag_to_string(const sl_diag *self)
{
    sl_strbuf b = { 0 };
    sl_strbuf_put(&b, "", 0);
    for (size_t i = 0; i < self->count; i++)
        format_one(&b, &self->items[i]);
    return b.data;
}

/*
 * console.c: the master's log lines and progress display (see console.h).
 */
#include "console.h"
#include "util/xalloc.h"

#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct console {
    int verbosity;
    bool tty;
    char line[200];        /* the progress line shown on the terminal */
    bool shown;            /* line is on screen now */
    int64_t last_ms;       /* last redraw or progress log */
    int last_tenth;        /* last tenth of the image logged */
    int resumed;           /* tiles done before the start (--resume): not in the rate */
    char prefix[64];       /* before the tile counts: frames done in a sequence */
    char tail[CONSOLE_TAIL][CONSOLE_TAIL_LINE];   /* a ring: the last lines logged */
    int tail_next, tail_count;
};

int console_tail_count(const console *self)
{
    return self->tail_count;
}

const char *console_tail_line(const console *self, int i)
{
    if (i < 0 || i >= self->tail_count) return "";
    int first = (self->tail_next - self->tail_count + CONSOLE_TAIL) % CONSOLE_TAIL;
    return self->tail[(first + i) % CONSOLE_TAIL];
}

void console_set_prefix(console *self, const char *text)
{
    snprintf(self->prefix, sizeof self->prefix, "%s", text);
}

void console_set_resumed(console *self, int tiles)
{
    self->resumed = tiles;
}

console *console_new(int verbosity, bool tty)
{
    console *self = xcalloc(1, sizeof *self);
    self->verbosity = verbosity;
    self->tty = tty;
    self->last_ms = INT64_MIN / 2;
    return self;
}

void console_destroy(console **self_p)
{
    console *self = *self_p;
    if (!self) return;
    if (self->shown) fputc('\n', stderr);
    free(self);
    *self_p = NULL;
}

static void clear_line(console *self)
{
    if (!self->shown) return;
    fputs("\r\033[K", stderr);
    self->shown = false;
}

static void draw_line(console *self)
{
    if (!self->line[0]) return;
    fprintf(stderr, "\r%s\033[K", self->line);
    fflush(stderr);
    self->shown = true;
}

void console_log(console *self, console_level level, const char *fmt, ...)
{
    bool keep = level <= CONSOLE_INFO;
    if ((int)level > self->verbosity && !keep) return;
    va_list ap;
    va_start(ap, fmt);
    if (keep) {
        va_list copy;
        va_copy(copy, ap);
        vsnprintf(self->tail[self->tail_next], CONSOLE_TAIL_LINE, fmt, copy);
        va_end(copy);
        self->tail_next = (self->tail_next + 1) % CONSOLE_TAIL;
        if (self->tail_count < CONSOLE_TAIL) self->tail_count++;
    }
    if ((int)level > self->verbosity) {
        va_end(ap);
        return;
    }
    clear_line(self);
    fputs("aafarm-master: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    if (self->tty && self->line[0]) draw_line(self);
    fflush(stderr);
}

static void format_progress(char *buf, size_t n, const char *prefix, int done, int total,
                            int resumed, int workers, double secs)
{
    double rate = secs > 0 ? (done - resumed) / secs : 0;
    char eta[32] = "-";
    if (rate > 0 && done < total) snprintf(eta, sizeof eta, "%.0f s", (total - done) / rate);
    else if (done == total) snprintf(eta, sizeof eta, "0 s");
    snprintf(buf, n, "%s%d/%d tiles (%d%%), %.1f tiles/s, ETA %s, %d worker%s alive",
             prefix, done, total, total ? (int)(100.0 * done / total) : 100, rate, eta, workers,
             workers == 1 ? "" : "s");
}

void console_progress(console *self, int done, int total, int workers, int64_t start_ms,
                      int64_t now_ms, bool final)
{
    if (self->verbosity < 0) return;
    double secs = (double)(now_ms - start_ms) / 1000.0;
    if (self->tty) {
        if (!final && now_ms - self->last_ms < 100) return;
        self->last_ms = now_ms;
        char body[160];
        format_progress(body, sizeof body, self->prefix, done, total, self->resumed, workers,
                        secs);
        snprintf(self->line, sizeof self->line, "  %s", body);
        draw_line(self);
        if (final) {
            fputc('\n', stderr);
            self->shown = false;
            self->line[0] = '\0';
        }
        return;
    }
    int tenth = total ? done * 10 / total : 10;
    if (!final && (tenth <= self->last_tenth || now_ms - self->last_ms < 2000)) return;
    self->last_tenth = tenth;
    self->last_ms = now_ms;
    char body[160];
    format_progress(body, sizeof body, self->prefix, done, total, self->resumed, workers,
                        secs);
    fprintf(stderr, "aafarm-master: %s\n", body);
    fflush(stderr);
}

/* ---- repeated warnings of one kind, aggregated ---- */

void console_tally_init(console_tally *self, const char *one, const char *many,
                        const char *detail, int64_t interval_ms)
{
    memset(self, 0, sizeof *self);
    snprintf(self->one, sizeof self->one, "%s", one);
    snprintf(self->many, sizeof self->many, "%s", many);
    snprintf(self->detail, sizeof self->detail, "%s", detail ? detail : "");
    self->interval_ms = interval_ms;
    self->said_ms = INT64_MIN / 2;
}

void console_tally_add(console_tally *self, int tile, const char *detail)
{
    self->count++;
    if (tile >= 0) {
        if (self->ntiles < CONSOLE_TALLY_TILES) self->tiles[self->ntiles] = tile;
        self->ntiles++;
    }
    if (detail) snprintf(self->detail, sizeof self->detail, "%s", detail);
}

/* "4 s", "0.5 s", "12 s" */
static void format_span(char *buf, size_t n, int64_t ms)
{
    if (ms < 10000 && ms % 1000) snprintf(buf, n, "%.1f s", (double)ms / 1000.0);
    else snprintf(buf, n, "%.0f s", (double)ms / 1000.0);
}

bool console_tally_format(const console_tally *self, int64_t now_ms, char *buf, size_t n)
{
    if (!self->count || !n) return false;
    char when[48] = "", span[24];
    if (self->said) {
        format_span(span, sizeof span, now_ms - self->said_ms);
        snprintf(when, sizeof when, " in the last %s", span);
    }
    char tiles[160] = "";
    if (self->ntiles) {
        size_t len = (size_t)snprintf(tiles, sizeof tiles, " (tile%s", self->ntiles == 1 ? "" : "s");
        uint64_t shown = self->ntiles < CONSOLE_TALLY_TILES ? self->ntiles : CONSOLE_TALLY_TILES;
        for (uint64_t i = 0; i < shown && len < sizeof tiles; i++)
            len += (size_t)snprintf(tiles + len, sizeof tiles - len, "%s %d", i ? "," : "",
                                    self->tiles[i]);
        if (self->ntiles > shown && len < sizeof tiles)
            len += (size_t)snprintf(tiles + len, sizeof tiles - len, " and %" PRIu64 " more",
                                    self->ntiles - shown);
        if (len < sizeof tiles) snprintf(tiles + len, sizeof tiles - len, ")");
    }
    snprintf(buf, n, "%" PRIu64 " %s%s%s%s%s", self->count, self->count == 1 ? self->one : self->many,
             when, tiles, self->detail[0] && !strchr(":,;", self->detail[0])
             ? " " : "", self->detail);
    return true;
}

bool console_tally_flush(console_tally *self, console *con, int64_t now_ms, bool force)
{
    if (!self->count) return false;
    if (!force && self->said && now_ms - self->said_ms < self->interval_ms) return false;
    char line[600];
    console_tally_format(self, now_ms, line, sizeof line);
    console_log(con, CONSOLE_INFO, "%s", line);
    self->said = true;
    self->said_ms = now_ms;
    self->count = 0;
    self->ntiles = 0;
    return true;
}

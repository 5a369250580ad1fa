/*
 * console.h: what the master says on stderr. Log lines
 * ("aafarm-master: worker local-1 joined ...") at three levels, and the
 * progress of the render: on a terminal one line redrawn in place (tiles
 * done/total, rate, ETA, workers alive), otherwise a plain log line at
 * every tenth of the image and at most every two seconds, so that logs of
 * farm renders stay readable in files.
 *
 * Warnings that can come by the dozen (leases past their deadline on a
 * busy host) go through a console_tally: the first batch is said at once,
 * the ones after it at most once per interval as one line with a count and
 * the first few tiles ("3 leases passed their deadlines in the last 10 s
 * (tiles 4, 9, 17) ...").
 */
#ifndef MASTER_CONSOLE_H
#define MASTER_CONSOLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum console_level {
    CONSOLE_ERROR = -1,    /* always printed */
    CONSOLE_INFO = 0,      /* printed unless -q */
    CONSOLE_DETAIL = 1     /* printed with -v */
} console_level;

typedef struct console console;

/* verbosity: -1 (-q), 0, 1 (-v). tty: draw progress in place. */
console *console_new(int verbosity, bool tty);
void console_destroy(console **self_p);

/* One line, prefixed "aafarm-master: ", when level <= verbosity. Clears a
 * progress line first and redraws it afterwards. */
void console_log(console *self, console_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* The log tail (the live monitor's, master/farm_monitor.c): the last
 * CONSOLE_TAIL lines at CONSOLE_INFO or ERROR, kept whatever the
 * verbosity, without the program's prefix; i = 0 is the oldest. */
enum { CONSOLE_TAIL = 40, CONSOLE_TAIL_LINE = 400 };
int console_tail_count(const console *self);
const char *console_tail_line(const console *self, int i);

/* The render's progress at time now_ms (elapsed since start_ms); redraws or
 * logs when due. final: the last call (always shown, ends the line). */
/* Tiles that were done before the render started (--resume): the rate
 * and the ETA count only the others. */
void console_set_resumed(console *self, int tiles);
/* Text shown before the tile counts ("2/3 frames, "), "" for none. */
void console_set_prefix(console *self, const char *text);

void console_progress(console *self, int done, int total, int workers, int64_t start_ms,
                      int64_t now_ms, bool final);

/* ---- repeated warnings of one kind, aggregated ---- */

enum { CONSOLE_TALLY_TILES = 5 };   /* tiles named in a line; the others counted */

typedef struct console_tally {
    char one[64], many[64];        /* "lease passed its deadline", "leases passed their deadlines" */
    char detail[256];              /* after the count and the tiles (the last event's) */
    int64_t interval_ms;           /* at most one line per interval */
    int64_t said_ms;               /* when a line was last said (INT64_MIN / 2: never) */
    bool said;                     /* a line of this kind was said before */
    uint64_t count;                /* events not said yet */
    int tiles[CONSOLE_TALLY_TILES];
    uint64_t ntiles;               /* tiles of those events; the first few kept in tiles */
} console_tally;

/* one: the words after a count of 1, many: after more; detail: after the
 * count and the tiles ("without a result: back in the queue"), or NULL. */
void console_tally_init(console_tally *self, const char *one, const char *many,
                        const char *detail, int64_t interval_ms);
/* Counts one event: its tile (-1: none; only the first few are kept, the
 * others counted) and detail (NULL: keep the words so far). */
void console_tally_add(console_tally *self, int tile, const char *detail);
/* Says the events counted, as one line at INFO, when the interval has
 * passed since the last line of this kind (or none was said yet), or
 * always with force (the end of the render). True when it said one. */
bool console_tally_flush(console_tally *self, console *con, int64_t now_ms, bool force);
/* The line for the events counted (without the program's prefix), as
 * console_tally_flush would say it at now_ms; false when none are. */
bool console_tally_format(const console_tally *self, int64_t now_ms, char *buf, size_t n);

#endif

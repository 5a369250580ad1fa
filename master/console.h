/*
 * console.h: what the master says on stderr. Log lines
 * ("aafarm-master: worker local-1 joined ...") at three levels, and the
 * progress of the render: on a terminal one line redrawn in place (tiles
 * done/total, rate, ETA, workers alive), otherwise a plain log line at
 * every tenth of the image and at most every two seconds, so that logs of
 * farm renders stay readable in files.
 */
#ifndef MASTER_CONSOLE_H
#define MASTER_CONSOLE_H

#include <stdbool.h>
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

/* The render's progress at time now_ms (elapsed since start_ms); redraws or
 * logs when due. final: the last call (always shown, ends the line). */
/* Tiles that were done before the render started (--resume): the rate
 * and the ETA count only the others. */
void console_set_resumed(console *self, int tiles);
/* Text shown before the tile counts ("2/3 frames, "), "" for none. */
void console_set_prefix(console *self, const char *text);

void console_progress(console *self, int done, int total, int workers, int64_t start_ms,
                      int64_t now_ms, bool final);

#endif

/*
 * strbuf.h: memory helpers shared by the shading language's front end:
 * an allocator that never returns NULL (out of memory aborts with a message:
 * the compiler has no sensible way to go on), and a growing NUL-terminated
 * string buffer used for diagnostics, stringizing and #error texts.
 */
#ifndef SL_STRBUF_H
#define SL_STRBUF_H

#include <stddef.h>

/* realloc that aborts with "sl: out of memory" instead of returning NULL. */
void *sl_xrealloc(void *p, size_t size);

/* A copy of s[0..len) with a terminating NUL. */
char *sl_xstrndup(const char *s, size_t len);

/* A growing string; zero-initialise, append, free(data) when done. data is
 * always NUL-terminated once anything was appended. */
typedef struct sl_strbuf {
    char *data;
    size_t len, cap;
} sl_strbuf;

void sl_strbuf_put(sl_strbuf *b, const char *s, size_t n);
void sl_strbuf_puts(sl_strbuf *b, const char *s);
void sl_strbuf_putc(sl_strbuf *b, char c);

#endif

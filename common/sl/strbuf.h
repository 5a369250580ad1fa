/*
 * strbuf.h: a growing NUL-terminated string buffer, used by the shading
 * language's front end for diagnostics, stringizing and #error texts
 * (memory from util/xalloc.h: out of memory aborts).
 */
#ifndef SL_STRBUF_H
#define SL_STRBUF_H

#include <stddef.h>

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

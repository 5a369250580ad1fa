/*
 * strbuf.c: the never-failing allocator and the growing string buffer of
 * strbuf.h.
 */
#include "sl/strbuf.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void *sl_xrealloc(void *p, size_t size)
{
    void *q = realloc(p, size ? size : 1);
    if (!q) {
        fputs("sl: out of memory\n", stderr);
        abort();
    }
    return q;
}

char *sl_xstrndup(const char *s, size_t len)
{
    char *copy = sl_xrealloc(NULL, len + 1);
    memcpy(copy, s, len);
    copy[len] = '\0';
    return copy;
}

void sl_strbuf_put(sl_strbuf *b, const char *s, size_t n)
{
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 64;
        while (cap < b->len + n + 1)
            cap *= 2;
        b->data = sl_xrealloc(b->data, cap);
        b->cap = cap;
    }
    memcpy(b->data + b->len, s, n);
    b->len += n;
    b->data[b->len] = '\0';
}

void sl_strbuf_puts(sl_strbuf *b, const char *s) { sl_strbuf_put(b, s, strlen(s)); }
void sl_strbuf_putc(sl_strbuf *b, char c) { sl_strbuf_put(b, &c, 1); }

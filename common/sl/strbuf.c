/*
 * strbuf.c: the growing string buffer of strbuf.h.
 */
#include "sl/strbuf.h"

#include "util/xalloc.h"

#include <string.h>

void sl_strbuf_put(sl_strbuf *b, const char *s, size_t n)
{
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 64;
        while (cap < b->len + n + 1)
            cap *= 2;
        b->data = xrealloc(b->data, cap);
        b->cap = cap;
    }
    memcpy(b->data + b->len, s, n);
    b->len += n;
    b->data[b->len] = '\0';
}

void sl_strbuf_puts(sl_strbuf *b, const char *s) { sl_strbuf_put(b, s, strlen(s)); }
void sl_strbuf_putc(sl_strbuf *b, char c) { sl_strbuf_put(b, &c, 1); }

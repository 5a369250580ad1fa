/*
 * xalloc.c: the allocator wrappers of xalloc.h. The only file outside
 * tests/ that calls malloc, calloc, realloc and strdup directly.
 */
#include "util/xalloc.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static _Noreturn void out_of_memory(size_t n, size_t size)
{
    if (size == 1)
        fprintf(stderr, "aafarm: out of memory (%zu bytes)\n", n);
    else
        fprintf(stderr, "aafarm: out of memory (%zu x %zu bytes)\n", n, size);
    abort();
}

void *try_malloc(size_t size)
{
    return malloc(size ? size : 1);
}

void *try_calloc(size_t n, size_t size)
{
    return calloc(n ? n : 1, size ? size : 1);
}

void *try_realloc(void *p, size_t size)
{
    return realloc(p, size ? size : 1);
}

void *try_reallocarray(void *p, size_t n, size_t size)
{
    if (size && n > SIZE_MAX / size)
        return NULL;
    return try_realloc(p, n * size);
}

char *try_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = try_malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

void *xmalloc(size_t size)
{
    void *p = try_malloc(size);
    if (!p)
        out_of_memory(size, 1);
    return p;
}

void *xcalloc(size_t n, size_t size)
{
    void *p = try_calloc(n, size);
    if (!p)
        out_of_memory(n, size);
    return p;
}

void *xrealloc(void *p, size_t size)
{
    void *q = try_realloc(p, size);
    if (!q)
        out_of_memory(size, 1);
    return q;
}

void *xreallocarray(void *p, size_t n, size_t size)
{
    void *q = try_reallocarray(p, n, size);
    if (!q)
        out_of_memory(n, size);
    return q;
}

char *xstrdup(const char *s)
{
    char *d = try_strdup(s);
    if (!d)
        out_of_memory(strlen(s) + 1, 1);
    return d;
}

char *xstrndup(const char *s, size_t len)
{
    char *d = xmalloc(len + 1);
    memcpy(d, s, len);
    d[len] = '\0';
    return d;
}

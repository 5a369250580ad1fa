/*
 * xalloc.h: aafarm's one allocator wrapper (docs/conventions.md).
 *
 * x* never return NULL: out of memory prints "aafarm: out of memory
 * (N bytes)" and aborts, as Redis's zmalloc and Lua's allocator do. A
 * renderer has no sensible way on without the memory it asked for, and a
 * worker that dies is requeued by the master (no tile is lost).
 *
 * try_* return NULL instead, for the few places that must survive out of
 * memory and say so in their header: a size that came from the wire or a
 * file (proto/, image/, the master's stitcher), where NULL becomes an error
 * message and not a dead process. Array forms check n * size for overflow.
 *
 * Memory from either family is released with plain free().
 */
#ifndef UTIL_XALLOC_H
#define UTIL_XALLOC_H

#include <stddef.h>

void *xmalloc(size_t size);
void *xcalloc(size_t n, size_t size);
void *xrealloc(void *p, size_t size);
void *xreallocarray(void *p, size_t n, size_t size);
char *xstrdup(const char *s);
char *xstrndup(const char *s, size_t len);   /* s[0..len) plus a NUL */

void *try_malloc(size_t size);
void *try_calloc(size_t n, size_t size);
void *try_realloc(void *p, size_t size);
void *try_reallocarray(void *p, size_t n, size_t size);
char *try_strdup(const char *s);

#endif

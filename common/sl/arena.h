/*
 * arena.h: sl_arena, the compiler's region allocator: memory handed out in
 * chunks of 64 KB (a larger request gets a chunk of its own), every
 * allocation zeroed and aligned for any type, all of it freed at once by
 * sl_arena_destroy. The syntax tree (ast.h) and the preprocessor's tokens,
 * macros and source texts (preproc.c) live in one each.
 */
#ifndef SL_ARENA_H
#define SL_ARENA_H

#include <stddef.h>

typedef struct sl_arena sl_arena;
sl_arena *sl_arena_new(void);
void sl_arena_destroy(sl_arena **self_p);
void *sl_arena_alloc(sl_arena *self, size_t size);     /* zeroed */
/* The bytes handed out so far (each request rounded up to the alignment):
 * what a caller with a memory limit counts. */
size_t sl_arena_bytes(const sl_arena *self);

#endif

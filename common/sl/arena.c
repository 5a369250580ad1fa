/*
 * arena.c: sl_arena, a list of chunks, each allocation zeroed (see
 * arena.h).
 */
#include "sl/arena.h"
#include "util/xalloc.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

typedef struct chunk {
    struct chunk *next;
    size_t used, size;
    max_align_t data[];
} chunk;

struct sl_arena {
    chunk *head;
    size_t bytes;             /* handed out, rounded: sl_arena_bytes */
};

enum { CHUNK_SIZE = 64 * 1024 };

sl_arena *sl_arena_new(void)
{
    sl_arena *self = xmalloc(sizeof *self);
    self->head = NULL;
    self->bytes = 0;
    return self;
}

void sl_arena_destroy(sl_arena **self_p)
{
    if (!*self_p)
        return;
    chunk *c = (*self_p)->head;
    while (c) {
        chunk *next = c->next;
        free(c);
        c = next;
    }
    free(*self_p);
    *self_p = NULL;
}

void *sl_arena_alloc(sl_arena *self, size_t size)
{
    size_t align = sizeof(max_align_t);
    size = (size + align - 1) / align * align;
    chunk *c = self->head;
    if (!c || c->used + size > c->size) {
        size_t cap = size > CHUNK_SIZE ? size : CHUNK_SIZE;
        c = xmalloc(sizeof *c + cap);
        c->used = 0;
        c->size = cap;
        c->next = self->head;
        self->head = c;
    }
    void *p = (char *)c->data + c->used;
    c->used += size;
    assert(c->used <= c->size && c->used % align == 0);
    self->bytes += size;
    memset(p, 0, size);
    return p;
}

size_t sl_arena_bytes(const sl_arena *self)
{
    return self->bytes;
}

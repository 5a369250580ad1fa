/*
 * lazy_roots.c: a displaced mesh's root boxes, published once by
 * whichever thread makes them first (see lazy_roots.h).
 */
#include "trace/lazy_roots.h"

#include <assert.h>
#include <stdatomic.h>
#include <stdlib.h>

#include "util/xalloc.h"

enum { CHUNK = 16 };
enum { EMPTY = 0, WRITING = 1, KNOWN = 2 };

typedef struct root_entry {
    trace_box root;
    double du, dv;
} root_entry;

typedef struct root_chunk {
    atomic_uchar state[CHUNK];
    root_entry e[CHUNK];
} root_chunk;

struct trace_lazy_roots {
    int npieces;
    _Atomic(root_chunk *) *chunks;     /* ceil(npieces / CHUNK), NULL until made */
    atomic_long known;                 /* root boxes published */
    atomic_long chunks_made;
};

static int chunks_for(int n)
{
    return n > 0 ? (n + CHUNK - 1) / CHUNK : 0;
}

trace_lazy_roots *trace_lazy_roots_new(int npieces)
{
    assert(npieces >= 0);
    trace_lazy_roots *self = xcalloc(1, sizeof *self);
    self->npieces = npieces;
    self->chunks = xcalloc((size_t)chunks_for(npieces) + 1, sizeof *self->chunks);
    for (int i = 0; i < chunks_for(npieces); i++) atomic_init(&self->chunks[i], NULL);
    atomic_init(&self->known, 0);
    atomic_init(&self->chunks_made, 0);
    return self;
}

void trace_lazy_roots_destroy(trace_lazy_roots **self_p)
{
    trace_lazy_roots *self = *self_p;
    if (!self) return;
    for (int i = 0; i < chunks_for(self->npieces); i++) free(atomic_load(&self->chunks[i]));
    free(self->chunks);
    free(self);
    *self_p = NULL;
}

/* Piece k's chunk, made (zeroed: every entry EMPTY) when missing; two
 * threads making it at once keep the first and drop the other */
static root_chunk *chunk_of(trace_lazy_roots *self, int k)
{
    _Atomic(root_chunk *) *slot = &self->chunks[k / CHUNK];
    root_chunk *c = atomic_load_explicit(slot, memory_order_acquire);
    if (c) return c;
    root_chunk *made = xcalloc(1, sizeof *made);
    root_chunk *expected = NULL;
    if (atomic_compare_exchange_strong_explicit(slot, &expected, made, memory_order_acq_rel,
                                                memory_order_acquire)) {
        atomic_fetch_add_explicit(&self->chunks_made, 1, memory_order_relaxed);
        return made;
    }
    free(made);
    return expected;
}

const trace_box *trace_lazy_root(const trace_lazy_roots *self, int k, double dudv[2])
{
    assert(k >= 0 && k < self->npieces);
    root_chunk *c = atomic_load_explicit(&self->chunks[k / CHUNK], memory_order_acquire);
    if (!c || atomic_load_explicit(&c->state[k % CHUNK], memory_order_acquire) != KNOWN)
        return NULL;
    const root_entry *e = &c->e[k % CHUNK];
    dudv[0] = e->du;
    dudv[1] = e->dv;
    return &e->root;
}

bool trace_lazy_root_put(trace_lazy_roots *self, int k, const trace_box *root, double du,
                         double dv)
{
    assert(k >= 0 && k < self->npieces);
    root_chunk *c = chunk_of(self, k);
    unsigned char expected = EMPTY;
    if (!atomic_compare_exchange_strong_explicit(&c->state[k % CHUNK], &expected, WRITING,
                                                 memory_order_acquire, memory_order_relaxed))
        return false;                  /* made by another thread: the same bits */
    c->e[k % CHUNK] = (root_entry){*root, du, dv};
    atomic_store_explicit(&c->state[k % CHUNK], KNOWN, memory_order_release);
    atomic_fetch_add_explicit(&self->known, 1, memory_order_relaxed);
    return true;
}

long trace_lazy_roots_known(const trace_lazy_roots *self)
{
    return atomic_load_explicit(&self->known, memory_order_relaxed);
}

size_t trace_lazy_roots_bytes(const trace_lazy_roots *self)
{
    if (!self) return 0;
    size_t b = sizeof *self + ((size_t)chunks_for(self->npieces) + 1) * sizeof *self->chunks;
    return b + (size_t)atomic_load_explicit(&self->chunks_made, memory_order_relaxed) *
                   sizeof(root_chunk);
}

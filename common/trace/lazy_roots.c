/*
 * lazy_roots.c: a displaced mesh's root boxes, published by whichever
 * thread makes them first, in slots of a sequence lock each, under a byte
 * budget (see lazy_roots.h).
 */
#include "trace/lazy_roots.h"

#include <assert.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "util/xalloc.h"

enum { CHUNK = 16 };

typedef struct root_entry {
    trace_box root;
    double du, dv;
} root_entry;

enum { WORDS = sizeof(root_entry) / sizeof(uint64_t) };
_Static_assert(sizeof(root_entry) == WORDS * sizeof(uint64_t), "a root entry is whole words");

/* seq: 0 empty, odd being written, even (not 0) holds piece `key` */
typedef struct root_slot {
    atomic_uint seq;
    atomic_int key;
    _Atomic uint64_t w[WORDS];         /* a root_entry, word by word */
} root_slot;

struct trace_lazy_roots {
    int npieces, nslots, nchunks;
    _Atomic(root_slot *) *chunks;      /* nchunks, NULL until made */
    atomic_long known;                 /* slots holding a root */
    atomic_long evicted;
    atomic_long slots_made;         /* in the chunks made */
};

static size_t chunk_slots(const trace_lazy_roots *self, int c)
{
    int n = self->nslots - c * CHUNK;
    return (size_t)(n < CHUNK ? n : CHUNK);
}

trace_lazy_roots *trace_lazy_roots_new(int npieces, size_t budget_bytes)
{
    assert(npieces >= 0);
    trace_lazy_roots *self = xcalloc(1, sizeof *self);
    self->npieces = npieces;
    size_t slots = (size_t)npieces;
    if (budget_bytes > 0) {
        /* a slot and its share of the chunk table (a pointer per slot:
         * more than the table takes), after the store itself */
        size_t fixed = sizeof *self + sizeof *self->chunks;
        size_t per = sizeof(root_slot) + sizeof *self->chunks;
        size_t afford = budget_bytes > fixed ? (budget_bytes - fixed) / per : 0;
        if (afford < slots) slots = afford;
        if (slots < 1) slots = 1;
    }
    self->nslots = (int)slots;
    self->nchunks = (self->nslots + CHUNK - 1) / CHUNK;
    self->chunks = xcalloc((size_t)self->nchunks + 1, sizeof *self->chunks);
    for (int i = 0; i < self->nchunks; i++) atomic_init(&self->chunks[i], NULL);
    atomic_init(&self->known, 0);
    atomic_init(&self->evicted, 0);
    atomic_init(&self->slots_made, 0);
    return self;
}

void trace_lazy_roots_destroy(trace_lazy_roots **self_p)
{
    trace_lazy_roots *self = *self_p;
    if (!self) return;
    for (int i = 0; i < self->nchunks; i++) free(atomic_load(&self->chunks[i]));
    free(self->chunks);
    free(self);
    *self_p = NULL;
}

/* Slot s's chunk, made (zeroed: every slot empty) when missing; two
 * threads making it at once keep the first and drop the other */
static root_slot *chunk_of(trace_lazy_roots *self, int s)
{
    _Atomic(root_slot *) *at = &self->chunks[s / CHUNK];
    root_slot *c = atomic_load_explicit(at, memory_order_acquire);
    if (c) return c;
    size_t n = chunk_slots(self, s / CHUNK);
    root_slot *made = xcalloc(n, sizeof *made);
    for (size_t i = 0; i < n; i++) {
        atomic_init(&made[i].seq, 0);
        atomic_init(&made[i].key, -1);
        for (int j = 0; j < WORDS; j++) atomic_init(&made[i].w[j], 0);
    }
    root_slot *expected = NULL;
    if (atomic_compare_exchange_strong_explicit(at, &expected, made, memory_order_acq_rel,
                                                memory_order_acquire)) {
        atomic_fetch_add_explicit(&self->slots_made, (long)n, memory_order_relaxed);
        return made;
    }
    free(made);
    return expected;
}

bool trace_lazy_root(const trace_lazy_roots *self, int k, trace_box *root, double dudv[2])
{
    assert(k >= 0 && k < self->npieces);
    int s = k % self->nslots;
    root_slot *c = atomic_load_explicit(&self->chunks[s / CHUNK], memory_order_acquire);
    if (!c) return false;
    root_slot *slot = &c[s % CHUNK];
    unsigned s1 = atomic_load_explicit(&slot->seq, memory_order_acquire);
    if (s1 == 0 || (s1 & 1u)) return false;
    int key = atomic_load_explicit(&slot->key, memory_order_relaxed);
    uint64_t w[WORDS];
    for (int j = 0; j < WORDS; j++) w[j] = atomic_load_explicit(&slot->w[j], memory_order_relaxed);
    atomic_thread_fence(memory_order_acquire);
    if (atomic_load_explicit(&slot->seq, memory_order_relaxed) != s1 || key != k) return false;
    root_entry e;
    memcpy(&e, w, sizeof e);
    *root = e.root;
    dudv[0] = e.du;
    dudv[1] = e.dv;
    return true;
}

bool trace_lazy_root_put(trace_lazy_roots *self, int k, const trace_box *root, double du,
                         double dv)
{
    assert(k >= 0 && k < self->npieces);
    int s = k % self->nslots;
    root_slot *slot = &chunk_of(self, s)[s % CHUNK];
    unsigned seq = atomic_load_explicit(&slot->seq, memory_order_relaxed);
    if (seq & 1u) return false;        /* another thread is writing it */
    if (seq != 0 && atomic_load_explicit(&slot->key, memory_order_relaxed) == k)
        return false;                  /* made by another thread: the same bits */
    /* claimed only if nobody wrote it since we looked */
    if (!atomic_compare_exchange_strong_explicit(&slot->seq, &seq, seq + 1, memory_order_acquire,
                                                 memory_order_relaxed))
        return false;
    atomic_thread_fence(memory_order_release);
    uint64_t w[WORDS];
    root_entry e = {*root, du, dv};
    memcpy(w, &e, sizeof w);
    atomic_store_explicit(&slot->key, k, memory_order_relaxed);
    for (int j = 0; j < WORDS; j++) atomic_store_explicit(&slot->w[j], w[j], memory_order_relaxed);
    unsigned next = seq + 2 != 0 ? seq + 2 : 2;  /* 0 stays "empty" */
    atomic_store_explicit(&slot->seq, next, memory_order_release);
    atomic_fetch_add_explicit(seq == 0 ? &self->known : &self->evicted, 1, memory_order_relaxed);
    return true;
}

long trace_lazy_roots_known(const trace_lazy_roots *self)
{
    return atomic_load_explicit(&self->known, memory_order_relaxed);
}

long trace_lazy_roots_evicted(const trace_lazy_roots *self)
{
    return atomic_load_explicit(&self->evicted, memory_order_relaxed);
}

int trace_lazy_roots_slots(const trace_lazy_roots *self)
{
    return self->nslots;
}

size_t trace_lazy_roots_bytes(const trace_lazy_roots *self)
{
    if (!self) return 0;
    size_t b = sizeof *self + ((size_t)self->nchunks + 1) * sizeof *self->chunks;
    long made = atomic_load_explicit(&self->slots_made, memory_order_relaxed);
    return b + (size_t)made * sizeof(root_slot);
}

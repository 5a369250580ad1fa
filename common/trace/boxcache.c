/*
 * boxcache.c: quadtree broods in one pool with an LRU list, byte budget and
 * eviction by subtree (see boxcache.h; Heidrich & Seidel §6).
 *
 * The pool is an array of broods addressed by index (stable under realloc);
 * evicted broods go on a free list. The LRU list runs from most recently
 * used (head) to least (tail).
 */
#include "trace/boxcache.h"
#include "util/xalloc.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

struct trace_boxcache {
    trace_brood *pool;
    int32_t capacity;        /* allocated entries */
    int32_t limit;           /* most broods allowed (budget) */
    int32_t used;            /* entries ever handed out (high water) */
    int32_t live;
    trace_brood_id free_head;
    trace_brood_id head, tail;
    trace_brood_id *roots;   /* per object: brood of the root's children */
    int nobjects;
    trace_boxcache_stats stats;
};

size_t trace_boxcache_brood_bytes(void) { return sizeof(trace_brood); }

trace_boxcache *trace_boxcache_new(size_t budget_bytes, int nobjects)
{
    trace_boxcache *self = xcalloc(1, sizeof *self);
    size_t n = budget_bytes ? budget_bytes / sizeof(trace_brood) : (size_t)INT32_MAX;
    if (n > (size_t)INT32_MAX) n = INT32_MAX;
    self->limit = (int32_t)n;
    self->free_head = self->head = self->tail = TRACE_BROOD_NONE;
    self->nobjects = nobjects;
    self->roots = xrealloc(NULL, sizeof(trace_brood_id) * (size_t)(nobjects > 0 ? nobjects : 1));
    for (int i = 0; i < nobjects; i++) self->roots[i] = TRACE_BROOD_NONE;
    return self;
}

void trace_boxcache_destroy(trace_boxcache **self_p)
{
    trace_boxcache *self = *self_p;
    if (!self) return;
    free(self->pool);
    free(self->roots);
    free(self);
    *self_p = NULL;
}

const trace_boxcache_stats *trace_boxcache_stats_get(const trace_boxcache *self)
{
    return &self->stats;
}

/* ---- LRU list ---- */

static void lru_unlink(trace_boxcache *self, trace_brood_id id)
{
    trace_brood *b = &self->pool[id];
    if (b->lru_prev != TRACE_BROOD_NONE) self->pool[b->lru_prev].lru_next = b->lru_next;
    else self->head = b->lru_next;
    if (b->lru_next != TRACE_BROOD_NONE) self->pool[b->lru_next].lru_prev = b->lru_prev;
    else self->tail = b->lru_prev;
    b->lru_prev = b->lru_next = TRACE_BROOD_NONE;
}

static void lru_push_front(trace_boxcache *self, trace_brood_id id)
{
    trace_brood *b = &self->pool[id];
    b->lru_prev = TRACE_BROOD_NONE;
    b->lru_next = self->head;
    if (self->head != TRACE_BROOD_NONE) self->pool[self->head].lru_prev = id;
    self->head = id;
    if (self->tail == TRACE_BROOD_NONE) self->tail = id;
}

static void lru_touch(trace_boxcache *self, trace_brood_id id)
{
    if (self->head == id) return;
    lru_unlink(self, id);
    lru_push_front(self, id);
}

/* ---- links ---- */

static trace_brood_id *link_of(trace_boxcache *self, int object,
                               trace_brood_id parent, int slot)
{
    if (parent == TRACE_BROOD_UNCACHED) return NULL;
    if (parent == TRACE_BROOD_NONE) {
        if (object < 0 || object >= self->nobjects) return NULL;
        return &self->roots[object];
    }
    assert(parent >= 0 && parent < self->used);
    return &self->pool[parent].child[slot];
}

/* ---- eviction ---- */

/* Pins lie on the traversal's path, so below an unpinned brood nothing is
 * pinned: an evicted brood and its whole subtree are unpinned. */
static void free_subtree(trace_boxcache *self, trace_brood_id id)
{
    trace_brood *b = &self->pool[id];
    assert(b->pinned == 0);
    for (int i = 0; i < 4; i++)
        if (b->child[i] != TRACE_BROOD_NONE) {
            /* brood links: a child's parent is this brood, at slot i */
            assert(self->pool[b->child[i]].parent == id && self->pool[b->child[i]].slot == i);
            free_subtree(self, b->child[i]);
        }
    b = &self->pool[id];
    lru_unlink(self, id);
    b->lru_next = self->free_head;
    self->free_head = id;
    b->parent = TRACE_BROOD_NONE;
    self->live--;
    assert(self->live >= 0);
    self->stats.evictions++;
}

static bool evict_one(trace_boxcache *self)
{
    for (trace_brood_id id = self->tail; id != TRACE_BROOD_NONE;
         id = self->pool[id].lru_prev) {
        trace_brood *b = &self->pool[id];
        if (b->pinned) continue;
        trace_brood_id *link = link_of(self, b->object, b->parent, b->slot);
        if (link) *link = TRACE_BROOD_NONE;
        free_subtree(self, id);
        return true;
    }
    return false;
}

static trace_brood_id alloc_brood(trace_boxcache *self)
{
    while (self->live >= self->limit)
        if (!evict_one(self)) return TRACE_BROOD_NONE;
    trace_brood_id id;
    if (self->free_head != TRACE_BROOD_NONE) {
        id = self->free_head;
        self->free_head = self->pool[id].lru_next;
    } else {
        if (self->used == self->capacity) {
            int32_t cap = self->capacity ? self->capacity * 2 : 64;
            if (cap > self->limit) cap = self->limit;
            self->pool = xrealloc(self->pool, sizeof(trace_brood) * (size_t)cap);
            self->capacity = cap;
        }
        id = self->used++;
    }
    self->live++;
    assert(self->live <= self->limit && id < self->capacity);   /* the budget is hard */
    size_t bytes = (size_t)self->live * sizeof(trace_brood);
    self->stats.bytes = bytes;
    if (bytes > self->stats.peak_bytes) self->stats.peak_bytes = bytes;
    return id;
}

/* ---- public ---- */

trace_brood_id trace_boxcache_lookup(trace_boxcache *self, int object,
                                     trace_brood_id parent, int slot,
                                     trace_box out[4])
{
    return trace_boxcache_lookup_at(self, object, parent, slot, NULL, out);
}

trace_brood_id trace_boxcache_lookup_at(trace_boxcache *self, int object,
                                        trace_brood_id parent, int slot,
                                        const trace_box *base, trace_box out[4])
{
    trace_brood_id *link = link_of(self, object, parent, slot);
    if (!link || *link == TRACE_BROOD_NONE) {
        self->stats.misses++;
        return TRACE_BROOD_NONE;
    }
    trace_brood_id id = *link;
    assert(id >= 0 && id < self->used && self->pool[id].parent == parent);
    double blo[3], bhi[3];             /* the four share their base */
    trace_fbox_base(base, blo, bhi);
    for (int i = 0; i < 4; i++) trace_fbox_unpack_on(&self->pool[id].box[i], blo, bhi, &out[i]);
    lru_touch(self, id);
    self->stats.hits++;
    return id;
}

trace_brood_id trace_boxcache_insert(trace_boxcache *self, int object,
                                     trace_brood_id parent, int slot,
                                     const trace_box boxes[4])
{
    return trace_boxcache_insert_at(self, object, parent, slot, NULL, boxes);
}

/* A new brood under (parent, slot), linked and on the LRU list, its boxes
 * not yet written; TRACE_BROOD_UNCACHED where it cannot be stored */
static trace_brood_id new_brood(trace_boxcache *self, int object, trace_brood_id parent, int slot)
{
    if (!link_of(self, object, parent, slot)) {
        self->stats.not_stored++;
        return TRACE_BROOD_UNCACHED;
    }
    /* the parent must stay put while we make room */
    if (parent >= 0) self->pool[parent].pinned++;
    trace_brood_id id = alloc_brood(self);
    if (parent >= 0) {
        assert(self->pool[parent].pinned > 0);
        self->pool[parent].pinned--;
    }
    if (id == TRACE_BROOD_NONE) {
        self->stats.not_stored++;
        return TRACE_BROOD_UNCACHED;
    }
    trace_brood *b = &self->pool[id];
    for (int i = 0; i < 4; i++) b->child[i] = TRACE_BROOD_NONE;
    b->parent = parent;
    b->object = object;
    b->slot = (uint8_t)(parent == TRACE_BROOD_NONE ? 4 : slot);
    b->pinned = 0;
    lru_push_front(self, id);
    *link_of(self, object, parent, slot) = id;
    self->stats.bytes = (size_t)self->live * sizeof(trace_brood);
    return id;
}

trace_brood_id trace_boxcache_insert_at(trace_boxcache *self, int object,
                                        trace_brood_id parent, int slot,
                                        const trace_box *base, const trace_box boxes[4])
{
    trace_brood_id id = new_brood(self, object, parent, slot);
    if (id >= 0)
        for (int i = 0; i < 4; i++) trace_fbox_pack(&boxes[i], base, &self->pool[id].box[i]);
    return id;
}

/* box i packed (with its linear bound) into f, and given back as f keeps
 * it, its codes in *code where asked */
static void pack_kept(trace_fbox *f, trace_box *box, const trace_lin *lin, const trace_box *base,
                      trace_qlin *code)
{
    trace_fbox_pack_lin(box, lin, base, f);
    trace_fbox_unpack(f, base, box);
    if (code) *code = f->qlin;
}

trace_brood_id trace_boxcache_insert_kept(trace_boxcache *self, int object,
                                          trace_brood_id parent, int slot,
                                          const trace_box *base, trace_box boxes[4],
                                          const trace_lin lins[4], trace_qlin codes[4])
{
    trace_brood_id id = new_brood(self, object, parent, slot);
    for (int i = 0; i < 4; i++) {
        trace_fbox tmp;
        pack_kept(id >= 0 ? &self->pool[id].box[i] : &tmp, &boxes[i], lins ? &lins[i] : NULL,
                  base, codes ? &codes[i] : NULL);
    }
    return id;
}

void trace_boxcache_update_kept(trace_boxcache *self, trace_brood_id id, int i,
                                const trace_box *base, trace_box *box, const trace_lin *lin,
                                trace_qlin *code)
{
    assert(i >= 0 && i < 4);
    trace_fbox tmp, *f = &tmp;
    if (id >= 0) {
        assert(id < self->used);
        f = &self->pool[id].box[i];
    }
    pack_kept(f, box, lin, base, code);
}

const trace_qlin *trace_boxcache_qlin(const trace_boxcache *self, trace_brood_id id, int i)
{
    assert(id >= 0 && id < self->used && i >= 0 && i < 4);
    return &self->pool[id].box[i].qlin;
}

void trace_boxcache_pin(trace_boxcache *self, trace_brood_id id)
{
    if (id < 0) return;
    assert(id < self->used && self->pool[id].pinned < UINT8_MAX);
    self->pool[id].pinned++;
}

void trace_boxcache_unpin(trace_boxcache *self, trace_brood_id id)
{
    if (id < 0) return;
    assert(id < self->used);
    assert(self->pool[id].pinned > 0 && "box cache: unpinning a brood that is not pinned");
    self->pool[id].pinned--;
}

/*
 * boxcache.h: the affine bounding-box cache of Heidrich & Seidel §6, one
 * per rendering thread.
 *
 * For every displaced object the cache holds a quadtree over the object's
 * (u,v) square. A node is a box (what the bounding arithmetic gave for its
 * (u,v) range) plus its four children; the (u,v) range is implicit in the
 * path from the root (child i covers the half [i&1] in u and [i>>1] in v).
 * The four children of a node are always computed together (the traversal
 * needs all four to order them front to back), so the unit of storage is a
 * BROOD: the four child boxes of one node, with links to the broods of
 * their own children.
 *
 * Budget and eviction: the cache never holds more broods than fit in its
 * byte budget (0 = unlimited). When a new brood does not fit, the least
 * recently used brood is evicted together with its whole subtree ("LRU by
 * subtree"; docs/renderer.md compares it with the paper's policy). Broods
 * on the traversal's current path are PINNED and never evicted; if
 * everything is pinned the new brood is simply not stored (the caller keeps
 * its own copy), so the budget is a hard limit.
 *
 * Boxes are stored as float offsets from their node's box, rounded
 * outward (trace_fbox, box.h: 52 bytes a box instead of 88, a brood 244
 * instead of 392). The cache changes speed only, never pixels: a box is a
 * pure function of (object, u-range, v-range), and the traversal rounds
 * every box it makes that way before it uses or stores it
 * (trace_box_round_float), so a recomputed box equals the cached one.
 */
#ifndef TRACE_BOXCACHE_H
#define TRACE_BOXCACHE_H

#include <stddef.h>
#include <stdint.h>

#include "trace/box.h"

typedef int32_t trace_brood_id;       /* -1: none, -2: not stored */
#define TRACE_BROOD_NONE (-1)
/* A node whose brood could not be stored: its children's broods cannot
 * be either (a lookup misses, an insert stores nothing), never confused
 * with an object's root (NONE) */
#define TRACE_BROOD_UNCACHED (-2)

typedef struct trace_brood {
    trace_fbox box[4];                /* floats rounded outward (box.h) */
    trace_brood_id child[4];          /* brood of child i's children */
    trace_brood_id parent;            /* brood holding our parent node, or NONE */
    int32_t object;                   /* object id (for roots) */
    uint8_t slot;                     /* index of our node in the parent brood; 4: object root */
    uint8_t pinned;
    trace_brood_id lru_prev, lru_next;
} trace_brood;

typedef struct trace_boxcache_stats {
    long hits, misses, evictions, not_stored;
    size_t bytes, peak_bytes;
} trace_boxcache_stats;

typedef struct trace_boxcache trace_boxcache;

/* budget_bytes == 0: unlimited. nobjects: number of objects (roots). */
trace_boxcache *trace_boxcache_new(size_t budget_bytes, int nobjects);
void trace_boxcache_destroy(trace_boxcache **self_p);

/* The brood of the children of a node: the node is child `slot` of brood
 * `parent`, or the root of `object` when parent is TRACE_BROOD_NONE. On a
 * hit copies the four boxes into out and returns the brood id (and marks it
 * recently used); on a miss returns TRACE_BROOD_NONE (always when parent is
 * TRACE_BROOD_UNCACHED). */
trace_brood_id trace_boxcache_lookup(trace_boxcache *self, int object,
                                     trace_brood_id parent, int slot,
                                     trace_box out[4]);

/* Stores the four child boxes of that node; returns the new brood's id, or
 * TRACE_BROOD_UNCACHED when it could not be stored (the parent is not
 * stored, or the budget is full of pinned broods). */
trace_brood_id trace_boxcache_insert(trace_boxcache *self, int object,
                                     trace_brood_id parent, int slot,
                                     const trace_box boxes[4]);

/* The same with the boxes stored as offsets from a base box (trace_fbox,
 * box.h): the node's own box; a lookup must give the base it was inserted
 * with (NULL: none, as the two above) */
trace_brood_id trace_boxcache_lookup_at(trace_boxcache *self, int object,
                                        trace_brood_id parent, int slot,
                                        const trace_box *base, trace_box out[4]);
trace_brood_id trace_boxcache_insert_at(trace_boxcache *self, int object,
                                        trace_brood_id parent, int slot,
                                        const trace_box *base, const trace_box boxes[4]);

/* trace_boxcache_insert_at for the intersector: each box with its linear
 * bound lins[i] (lin_bound.h; lins NULL: none) kept as codes, and the
 * boxes given back as the cache keeps them (stored or not, a later lookup
 * gives these very boxes), the codes in codes[4] where asked (a brood
 * that could not be stored has them nowhere else) */
trace_brood_id trace_boxcache_insert_kept(trace_boxcache *self, int object,
                                          trace_brood_id parent, int slot,
                                          const trace_box *base, trace_box boxes[4],
                                          const trace_lin lins[4], trace_qlin codes[4]);

/* Replaces box i of a brood (a lazy child evaluated: intersect.c) as
 * trace_boxcache_insert_kept stores one (id < 0: a brood not stored,
 * rounded alike) */
void trace_boxcache_update_kept(trace_boxcache *self, trace_brood_id id, int i,
                                const trace_box *base, trace_box *box, const trace_lin *lin,
                                trace_qlin *code);

/* The linear bound's codes of box i of a stored brood (the lookups leave
 * them out); valid until the next insertion */
const trace_qlin *trace_boxcache_qlin(const trace_boxcache *self, trace_brood_id id, int i);

/* Pin / unpin a brood while the traversal is below it. */
void trace_boxcache_pin(trace_boxcache *self, trace_brood_id id);
void trace_boxcache_unpin(trace_boxcache *self, trace_brood_id id);

const trace_boxcache_stats *trace_boxcache_stats_get(const trace_boxcache *self);
size_t trace_boxcache_brood_bytes(void);

#endif

/*
 * edge_sort.h: the sort behind the shared edges of polygons (world.c):
 * edges by the hash of their exact key, equal hashes by where they are,
 * so that equal edges are neighbours. A list of millions (a mesh of 10^6
 * faces has 6 x 10^6) is sorted over the world's build threads, in the
 * order one qsort gives for any thread count.
 */
#ifndef TRACE_EDGE_SORT_H
#define TRACE_EDGE_SORT_H

#include <stddef.h>
#include <stdint.h>

/* An edge: the hash of its key, and its ref (object or piece id times 64
 * plus its index in the polygon), unique in a list */
typedef struct trace_edge {
    uint64_t h, ref;
} trace_edge;

/* The list made of parts[0..nparts) one after another (lens[p] edges
 * each), sorted by h, then by ref: the order of qsort with that comparison,
 * over `threads` threads (< 1: one), into a new array (the caller frees
 * it; the parts are left as they are). A list of 4096 or more must come in
 * increasing ref (world.c makes it so; asserted). */
trace_edge *trace_edges_sort_parts(trace_edge *const *parts, const size_t *lens, int nparts,
                                   int threads);

/* The same list, sorted the same, handed to each(ctx, e, n) in slices,
 * in order (their concatenation is the list trace_edges_sort_parts
 * returns), one slice held at a time: a slice is a run of the sort's
 * buckets (the hashes' top bits), so equal hashes are never split
 * between two, of at most slice_edges edges (0: the whole list) unless
 * one bucket is longer. The peak beside the parts is a slice, not the
 * list (issue 23: the world's edges at 10^7 faces). A short list (under
 * 4096) or one of more than 64 parts is one slice. */
typedef void (*trace_edges_fn)(void *ctx, const trace_edge *e, size_t n);
void trace_edges_sort_each(trace_edge *const *parts, const size_t *lens, int nparts, int threads,
                           size_t slice_edges, trace_edges_fn each, void *ctx);

/* The same for one list e[0..n), in place. */
void trace_edges_sort(trace_edge *e, size_t n, int threads);

#endif

/*
 * edge_sort.c: sorting the world's polygon edges by hash (edge_sort.h),
 * over the build threads, in the order of one qsort.
 */
#include "trace/edge_sort.h"
#include "trace/thread.h"
#include "util/xalloc.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

static int edge_cmp(const void *x, const void *y)
{
    const trace_edge *a = x, *b = y;
    if (a->h != b->h) return a->h < b->h ? -1 : 1;
    return (a->ref > b->ref) - (a->ref < b->ref);
}

/* Sorting the edges by hash, and equal hashes by ref (edge_cmp's
 * order: a total order, since refs differ, so any correct sort gives the
 * same list). A long list (made in ref order, in parts: the world's
 * threads' lists) is sorted over the build threads: its edges are dealt
 * into buckets by the top `top` bits of their hashes (each thread counting
 * and dealing its parts, the parts in order within each bucket, so a
 * bucket keeps ref order), then each bucket, a few thousand edges that
 * stay in cache, by a stable radix sort of the hashes' other bits. qsort
 * of the 6 million edges of a 1M-quad mesh took a second, one radix sort
 * of 16-bit digits over the whole list 0.35 s (its digits' scatter over
 * 96 MB misses the cache). */
enum { EDGE_SORT_MIN = 4096, EDGE_BUCKET = 16384, EDGE_DIGIT_MAX = 11, EDGE_PARTS_MAX = 64 };

typedef struct edge_sort {
    trace_edge *const *part;           /* the list: its parts, in order */
    const size_t *len;
    int nparts;
    trace_edge *out;                   /* the slice being sorted: buckets
                                        * [b0, b1), the list's [base, base + m) */
    size_t b0, b1, base, m;
    size_t n;
    int top, threads;
    size_t *count;                     /* per part, per bucket: its edges in
                                        * it, then where they go */
    size_t *start;                     /* per bucket: its first in out (nb + 1) */
} edge_sort;

typedef struct edge_sort_share {
    edge_sort *s;
    int t;
    trace_edge *scratch;               /* as long as the longest bucket */
} edge_sort_share;

/* thread t's parts: every threads-th from t */
static void *count_parts(void *arg)
{
    edge_sort_share *sh = arg;
    const edge_sort *s = sh->s;
    int shift = 64 - s->top;
    for (int p = sh->t; p < s->nparts; p += s->threads) {
        size_t *count = s->count + ((size_t)p << s->top);
        for (size_t i = 0; i < s->len[p]; i++) count[s->part[p][i].h >> shift]++;
    }
    return NULL;
}

/* the slice's edges of thread t's parts, to where they go in it */
static void *deal_parts(void *arg)
{
    edge_sort_share *sh = arg;
    const edge_sort *s = sh->s;
    int shift = 64 - s->top;
    size_t b0 = s->b0, nb = s->b1 - s->b0;
    trace_edge *out = s->out - s->base;
    for (int p = sh->t; p < s->nparts; p += s->threads) {
        size_t *at = s->count + ((size_t)p << s->top);
        const trace_edge *e = s->part[p];
        for (size_t i = 0; i < s->len[p]; i++) {
            size_t b = (size_t)(e[i].h >> shift);
            if (b - b0 < nb) out[at[b]++] = e[i];
        }
    }
    return NULL;
}

/* A bucket's m edges e[0..m), by their hashes' bits below `bits` (the
 * bucket's top bits are its own): LSD radix between e and scratch, an even
 * number of passes, so the sorted bucket ends in e */
static void sort_bucket(trace_edge *e, trace_edge *scratch, size_t m, int bits)
{
    int passes = (bits + EDGE_DIGIT_MAX - 1) / EDGE_DIGIT_MAX;
    if (passes % 2 == 1) passes++;
    int digit = (bits + passes - 1) / passes;
    size_t count[1 << EDGE_DIGIT_MAX];
    uint64_t mask = ((uint64_t)1 << digit) - 1;
    trace_edge *from = e, *to = scratch;
    for (int pass = 0; pass < passes; pass++) {
        int shift = digit * pass;
        memset(count, 0, sizeof count[0] << digit);
        for (size_t i = 0; i < m; i++) count[(from[i].h >> shift) & mask]++;
        size_t at = 0;
        for (size_t d = 0; d <= mask; d++) {
            size_t c = count[d];
            count[d] = at;
            at += c;
        }
        for (size_t i = 0; i < m; i++) to[count[(from[i].h >> shift) & mask]++] = from[i];
        trace_edge *t = from;
        from = to;
        to = t;
    }
    assert(from == e);
}

/* thread t's buckets of the slice: those whose first edge lies in its
 * t-th of the slice */
static void *sort_buckets(void *arg)
{
    edge_sort_share *sh = arg;
    const edge_sort *s = sh->s;
    size_t lo = s->base + s->m * (size_t)sh->t / (size_t)s->threads;   /* n < 2^31 (refs) */
    size_t hi = s->base + s->m * (size_t)(sh->t + 1) / (size_t)s->threads;
    for (size_t b = s->b0; b < s->b1; b++) {
        size_t first = s->start[b], m = s->start[b + 1] - first;
        if (first < lo || first >= hi || m == 0) continue;
        sort_bucket(s->out + (first - s->base), sh->scratch, m, 64 - s->top);
    }
    return NULL;
}

/* The sort of the list in slices (trace_edges_sort_each); buf: where the
 * slices go (NULL: made here, and freed), as long as the list when
 * slice_edges is 0 */
static void sort_slices(trace_edge *const *parts, const size_t *lens, int nparts, int threads,
                        size_t slice_edges, trace_edges_fn each, void *ctx, trace_edge *buf)
{
    size_t n = 0;
    for (int p = 0; p < nparts; p++) n += lens[p];
    if (slice_edges == 0 || slice_edges > n) slice_edges = n;
    trace_edge *own = NULL;
    if (n < EDGE_SORT_MIN || nparts > EDGE_PARTS_MAX) {
        /* short (one qsort), or of many parts (one for the deal): one
         * slice, the whole list */
        trace_edge *out = buf ? buf : (own = xmalloc(sizeof *out * (n > 0 ? n : 1)));
        size_t at = 0;
        for (int p = 0; p < nparts; p++) {
            if (lens[p] > 0) memcpy(out + at, parts[p], sizeof *out * lens[p]);
            at += lens[p];
        }
        if (n < EDGE_SORT_MIN) qsort(out, n, sizeof *out, edge_cmp);
        else trace_edges_sort(out, n, threads);
        if (each) each(ctx, out, n);
        free(own);
        return;
    }
#ifndef NDEBUG
    const trace_edge *last = NULL;
    for (int p = 0; p < nparts; p++)
        for (size_t i = 0; i < lens[p]; i++) {
            assert(!last || last->ref < parts[p][i].ref);
            last = &parts[p][i];
        }
#endif
    edge_sort s = {.part = parts, .len = lens, .nparts = nparts, .n = n, .top = 1,
                   .threads = threads < 1 ? 1 : threads};
    while (s.top < 16 && (n >> s.top) > EDGE_BUCKET) s.top++;
    size_t nb = (size_t)1 << s.top;
    s.count = xcalloc((size_t)nparts * nb, sizeof *s.count);
    s.start = xmalloc(sizeof *s.start * (nb + 1));
    edge_sort_share *sh = xcalloc((size_t)s.threads, sizeof *sh);
    for (int t = 0; t < s.threads; t++) sh[t] = (edge_sort_share){&s, t, NULL};
    trace_run_shares(sh, sizeof *sh, s.threads, count_parts);
    /* bucket by bucket, the parts in order */
    size_t at = 0, longest = 0;
    for (size_t b = 0; b < nb; b++) {
        s.start[b] = at;
        for (int p = 0; p < nparts; p++) {
            size_t c = s.count[((size_t)p << s.top) + b];
            s.count[((size_t)p << s.top) + b] = at;
            at += c;
        }
        if (at - s.start[b] > longest) longest = at - s.start[b];
    }
    s.start[nb] = at;
    assert(at == n);
    /* slices: runs of whole buckets, each at most slice_edges (or one
     * bucket longer than that), dealt from the parts and sorted in turn */
    if (slice_edges < longest) slice_edges = longest;
    s.out = buf ? buf : (own = xmalloc(sizeof *s.out * slice_edges));
    for (int t = 0; t < s.threads; t++) sh[t].scratch = xmalloc(sizeof *s.out * longest);
    for (size_t b0 = 0; b0 < nb;) {
        size_t b1 = b0 + 1;
        while (b1 < nb && s.start[b1 + 1] - s.start[b0] <= slice_edges) b1++;
        s.b0 = b0;
        s.b1 = b1;
        s.base = s.start[b0];
        s.m = s.start[b1] - s.base;
        trace_run_shares(sh, sizeof *sh, s.threads, deal_parts);
        trace_run_shares(sh, sizeof *sh, s.threads, sort_buckets);
        if (each && s.m > 0) each(ctx, s.out, s.m);
        b0 = b1;
    }
    for (int t = 0; t < s.threads; t++) free(sh[t].scratch);
    free(own);
    free(sh);
    free(s.start);
    free(s.count);
}

trace_edge *trace_edges_sort_parts(trace_edge *const *parts, const size_t *lens, int nparts,
                                   int threads)
{
    size_t n = 0;
    for (int p = 0; p < nparts; p++) n += lens[p];
    trace_edge *out = xmalloc(sizeof *out * (n > 0 ? n : 1));
    sort_slices(parts, lens, nparts, threads, 0, NULL, NULL, out);   /* one slice */
    return out;
}

void trace_edges_sort_each(trace_edge *const *parts, const size_t *lens, int nparts, int threads,
                           size_t slice_edges, trace_edges_fn each, void *ctx)
{
    sort_slices(parts, lens, nparts, threads, slice_edges, each, ctx, NULL);
}

void trace_edges_sort(trace_edge *e, size_t n, int threads)
{
    if (n < EDGE_SORT_MIN) {
        qsort(e, n, sizeof *e, edge_cmp);
        return;
    }
    /* the list in as many parts as threads */
    int t = threads < 1 ? 1 : threads > EDGE_PARTS_MAX ? EDGE_PARTS_MAX : threads;
    trace_edge *parts[EDGE_PARTS_MAX];
    size_t lens[EDGE_PARTS_MAX];
    for (int i = 0; i < t; i++) {
        size_t lo = n * (size_t)i / (size_t)t, hi = n * (size_t)(i + 1) / (size_t)t;
        parts[i] = e + lo;
        lens[i] = hi - lo;
    }
    trace_edge *out = trace_edges_sort_parts(parts, lens, t, threads);
    memcpy(e, out, sizeof *e * n);
    free(out);
}

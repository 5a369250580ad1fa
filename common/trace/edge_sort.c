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
 * same list). A long list (made in ref order) is sorted over the build
 * threads: its elements are dealt into buckets by the top `top` bits of
 * their hashes (each thread counting and dealing a slice of the list, the
 * slices in order within each bucket, so a bucket keeps ref order), then
 * each bucket, a few thousand edges that stay in cache, by a stable radix
 * sort of the hashes' other bits. qsort of the 6 million edges of a
 * 1M-quad mesh took a second, one radix sort of 16-bit digits over the
 * whole list 0.35 s (its digits' scatter over 96 MB misses the cache). */
enum { EDGE_SORT_MIN = 4096, EDGE_BUCKET = 16384, EDGE_DIGIT_MAX = 11 };

typedef struct edge_sort {
    trace_edge *e, *tmp;               /* the list, and as long a scratch */
    size_t n;
    int top, threads;
    size_t *count;                     /* per thread, per bucket: its slice's
                                        * edges in it, then where they go */
    size_t *start;                     /* per bucket: its first in the list (nb + 1) */
} edge_sort;

typedef struct edge_sort_share {
    edge_sort *s;
    int t;
} edge_sort_share;

static size_t slice_at(const edge_sort *s, int t)
{
    return s->n * (size_t)t / (size_t)s->threads;   /* n < 2^31 (refs), threads < 2^16 */
}

static void *count_slice(void *arg)
{
    edge_sort_share *sh = arg;
    const edge_sort *s = sh->s;
    size_t *count = s->count + ((size_t)sh->t << s->top);
    int shift = 64 - s->top;
    for (size_t i = slice_at(s, sh->t); i < slice_at(s, sh->t + 1); i++)
        count[s->e[i].h >> shift]++;
    return NULL;
}

static void *deal_slice(void *arg)
{
    edge_sort_share *sh = arg;
    const edge_sort *s = sh->s;
    size_t *at = s->count + ((size_t)sh->t << s->top);
    int shift = 64 - s->top;
    for (size_t i = slice_at(s, sh->t); i < slice_at(s, sh->t + 1); i++)
        s->tmp[at[s->e[i].h >> shift]++] = s->e[i];
    return NULL;
}

/* A bucket's m edges from src to dst, by their hashes' bits below `bits`
 * (the bucket's top bits are its own): LSD radix, an odd number of passes
 * between src and dst, so the sorted list ends in dst */
static void sort_bucket(trace_edge *src, trace_edge *dst, size_t m, int bits)
{
    int passes = (bits + EDGE_DIGIT_MAX - 1) / EDGE_DIGIT_MAX;
    if (passes % 2 == 0) passes++;
    int digit = (bits + passes - 1) / passes;
    size_t count[1 << EDGE_DIGIT_MAX];
    uint64_t mask = ((uint64_t)1 << digit) - 1;
    trace_edge *from = src, *to = dst;
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
    assert(from == dst);
}

/* thread t's buckets: those whose first edge lies in its slice */
static void *sort_buckets(void *arg)
{
    edge_sort_share *sh = arg;
    const edge_sort *s = sh->s;
    size_t lo = slice_at(s, sh->t), hi = slice_at(s, sh->t + 1);
    for (size_t b = 0; b < (size_t)1 << s->top; b++) {
        size_t first = s->start[b], m = s->start[b + 1] - first;
        if (first < lo || first >= hi || m == 0) continue;
        sort_bucket(s->tmp + first, s->e + first, m, 64 - s->top);
    }
    return NULL;
}

void trace_edges_sort(trace_edge *e, size_t n, int threads)
{
    if (n < EDGE_SORT_MIN) {
        qsort(e, n, sizeof *e, edge_cmp);
        return;
    }
    for (size_t i = 1; i < n; i++) assert(e[i - 1].ref < e[i].ref);
    edge_sort s = {.e = e, .tmp = xmalloc(sizeof *e * n), .n = n, .top = 1,
                   .threads = threads < 1 ? 1 : threads};
    while (s.top < 16 && (n >> s.top) > EDGE_BUCKET) s.top++;
    size_t nb = (size_t)1 << s.top;
    s.count = xcalloc((size_t)s.threads * nb, sizeof *s.count);
    s.start = xmalloc(sizeof *s.start * (nb + 1));
    edge_sort_share *sh = xmalloc(sizeof *sh * (size_t)s.threads);
    for (int t = 0; t < s.threads; t++) sh[t] = (edge_sort_share){&s, t};
    trace_run_shares(sh, sizeof *sh, s.threads, count_slice);
    /* bucket by bucket, the slices in order */
    size_t at = 0;
    for (size_t b = 0; b < nb; b++) {
        s.start[b] = at;
        for (int t = 0; t < s.threads; t++) {
            size_t c = s.count[((size_t)t << s.top) + b];
            s.count[((size_t)t << s.top) + b] = at;
            at += c;
        }
    }
    s.start[nb] = at;
    assert(at == n);
    trace_run_shares(sh, sizeof *sh, s.threads, deal_slice);
    trace_run_shares(sh, sizeof *sh, s.threads, sort_buckets);
    free(sh);
    free(s.start);
    free(s.count);
    free(s.tmp);
}

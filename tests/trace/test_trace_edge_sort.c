/*
 * test_trace_edge_sort.c: the sort of the world's polygon edges
 * (trace/edge_sort.h) gives the order of one qsort by (hash, ref) for any
 * thread count: lists short (the qsort) and long (buckets by the hashes'
 * top bits, a radix sort in each), whole or in parts (the world's
 * threads' lists, 70 of them more than are dealt at once), hashes random,
 * drawn from a few values
 * (groups of equal hashes, whose refs must stay in order: the shared
 * edges are found between neighbours), and all in one bucket or sharing
 * their low bits (the radix's digits, each of them, must count).
 * Handed over in slices (trace_edges_sort_each), the list is the same,
 * each slice within its size and no group of equal hashes split.
 */
#include <malloc.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "trace/edge_sort.h"

static uint64_t rng = 0x2545f4914f6cdd1dull;

static uint64_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

static int cmp(const void *x, const void *y)
{
    const trace_edge *a = x, *b = y;
    if (a->h != b->h) return a->h < b->h ? -1 : 1;
    return (a->ref > b->ref) - (a->ref < b->ref);
}

typedef enum { RANDOM, FEW, ONE_BUCKET, LOW_SAME } kind;

/* n edges of increasing refs, their hashes of kind k */
static void make(trace_edge *e, size_t n, kind k)
{
    uint64_t ref = next() % 100;
    uint64_t few[7];
    for (int i = 0; i < 7; i++) few[i] = next();
    for (size_t i = 0; i < n; i++) {
        uint64_t h = next();
        if (k == FEW) h = few[next() % 7];
        if (k == ONE_BUCKET) h = (h >> 20) | 0xabc0000000000000ull;   /* top 12 bits fixed */
        if (k == LOW_SAME) h = (h & ~0xffffffull) | 0x123456;
        e[i].h = h;
        ref += 1 + next() % 3;
        e[i].ref = ref;
    }
}

static void test_sorts_as_qsort(void **state)
{
    (void)state;
    static const size_t sizes[] = {0, 1, 2, 17, 4095, 4096, 4097, 20000, 70001, 300000};
    static const int threads[] = {1, 2, 3, 5};
    size_t cap = 300000;
    trace_edge *src = malloc(sizeof *src * cap), *want = malloc(sizeof *src * cap),
               *got = malloc(sizeof *src * cap);
    assert_non_null(src);
    assert_non_null(want);
    assert_non_null(got);
    int lists = 0;
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        for (int k = RANDOM; k <= LOW_SAME; k++) {
            size_t n = sizes[s];
            make(src, n, (kind)k);
            memcpy(want, src, sizeof *src * n);
            qsort(want, n, sizeof *want, cmp);
            for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
                memcpy(got, src, sizeof *src * n);
                trace_edges_sort(got, n, threads[t]);
                if (n > 0 && memcmp(got, want, sizeof *got * n) != 0) {
                    size_t i = 0;
                    while (!memcmp(&got[i], &want[i], sizeof *got)) i++;
                    fail_msg("%zu edges (kind %d), %d threads: edge %zu is (%016llx, %llu), "
                             "qsort's (%016llx, %llu)", n, k, threads[t], i,
                             (unsigned long long)got[i].h, (unsigned long long)got[i].ref,
                             (unsigned long long)want[i].h, (unsigned long long)want[i].ref);
                }
                lists++;
            }
            /* the list in parts (some empty; more than the deal takes at
             * once: 64), as the world hands its threads' lists over */
            static const int nparts[] = {1, 2, 7, 70};
            for (size_t q = 0; q < sizeof nparts / sizeof nparts[0]; q++) {
                trace_edge *parts[70];
                size_t lens[70], at = 0;
                for (int i = 0; i < nparts[q]; i++) {
                    size_t step = i % 3 == 1 ? 0 : next() % (n / 8 + 1);
                    size_t end = i + 1 == nparts[q] ? n : at + step;
                    if (end > n) end = n;
                    parts[i] = src + at;
                    lens[i] = end - at;
                    at = end;
                }
                trace_edge *out = trace_edges_sort_parts(parts, lens, nparts[q], 1 + (int)q);
                if (n > 0 && memcmp(out, want, sizeof *out * n) != 0)
                    fail_msg("%zu edges (kind %d) in %d parts: not qsort's order", n, k,
                             nparts[q]);
                free(out);
                lists++;
            }
        }
    printf("%d lists sorted as qsort sorts them\n", lists);
    free(src);
    free(want);
    free(got);
}

/* ---- in slices ---------------------------------------------------------- */

typedef struct slices {
    trace_edge *got;                   /* the slices one after another */
    size_t n, longest, count;
    int split;                         /* equal hashes across a slice boundary */
    size_t heap0, heap_over;           /* the heap before the sort; the most
                                        * beyond it while a slice is handed over */
} slices;

/* Bytes the allocator holds (0 under a sanitizer's allocator) */
static size_t heap_bytes(void)
{
    struct mallinfo2 mi = mallinfo2();
    return mi.uordblks + mi.hblkhd;
}

static void take(void *ctx, const trace_edge *e, size_t n)
{
    slices *s = ctx;
    assert_true(n > 0);
    if (s->n > 0 && s->got[s->n - 1].h == e[0].h) s->split++;
    memcpy(s->got + s->n, e, sizeof *e * n);
    s->n += n;
    if (n > s->longest) s->longest = n;
    s->count++;
    size_t h = heap_bytes();
    if (h > s->heap0 && h - s->heap0 > s->heap_over) s->heap_over = h - s->heap0;
}

/* The slices of trace_edges_sort_each: qsort's list, in order, each within
 * its size (the buckets here are far shorter than it), equal hashes never
 * split, and several of them; the heap beside the parts is a slice */
static void test_slices(void **state)
{
    (void)state;
    enum { N = 300000, PARTS = 5 };
    trace_edge *src = malloc(sizeof *src * N), *want = malloc(sizeof *src * N);
    slices s = {.got = malloc(sizeof *src * N)};
    assert_non_null(src);
    assert_non_null(want);
    assert_non_null(s.got);
    for (int k = RANDOM; k <= FEW; k++) {
        make(src, N, (kind)k);
        memcpy(want, src, sizeof *src * N);
        qsort(want, N, sizeof *want, cmp);
        trace_edge *parts[PARTS];
        size_t lens[PARTS];
        for (int i = 0; i < PARTS; i++) {
            parts[i] = src + (size_t)N * i / PARTS;
            lens[i] = (size_t)N * (i + 1) / PARTS - (size_t)N * i / PARTS;
        }
        for (int threads = 1; threads <= 3; threads += 2) {
            s.n = s.longest = s.count = 0;
            s.split = 0;
            s.heap_over = 0;
            s.heap0 = heap_bytes();
            trace_edges_sort_each(parts, lens, PARTS, threads, N / 4, take, &s);
            printf("%s hashes, %d threads: %zu slices, the longest %zu edges (at most %d), "
                   "%d groups of equal hashes split; the heap held %zu bytes beyond the "
                   "parts (the list: %zu)\n", k == RANDOM ? "random" : "7",
                   threads, s.count, s.longest, N / 4, s.split, s.heap_over,
                   sizeof(trace_edge) * N);
            assert_int_equal(s.n, N);
            assert_memory_equal(s.got, want, sizeof *want * N);
            assert_int_equal(s.split, 0);
            if (k == RANDOM) {
                /* buckets of ~16k edges: slices of nearly N / 4 */
                assert_true(s.longest <= N / 4);
                assert_true(s.count >= 4 && s.count <= 5);
                /* a slice and the radix's scratch, far from the list */
                assert_true(s.heap_over <= sizeof(trace_edge) * N / 2);
            }
        }
    }
    free(src);
    free(want);
    free(s.got);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sorts_as_qsort),
        cmocka_unit_test(test_slices),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

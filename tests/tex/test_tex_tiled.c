/*
 * tests/tex/test_tex_tiled.c: aafarm-maketx files opened with their stored
 * pyramids and read in tiles on demand (common/tex/read_tiled.c, tiles.c).
 *
 *  - a map written with its pyramids (tex_write_exr, what aafarm-maketx
 *    writes) opens with levels in tiles, and gives exactly what the same
 *    image built in memory gives: every texel of every level, the filter
 *    and its derivatives (float and dual), the bound of random ranges
 *    (interval), the single cells (affine), cells-or-bound (the affine
 *    lookup: the same as the two), the derivative bounds, all
 *    wraps, both odd and even sizes and 1 to 3 channels;
 *  - with a pool of a budget of a few tiles, 4 threads doing random
 *    lookups get bit for bit what the in-memory map gives, while tiles are
 *    evicted (evictions > 0) and the pool stays within its budget plus the
 *    tiles the threads can pin at once;
 *  - aafarm-maketx of such a file (a tiled texture written again) gives
 *    the same file contents back;
 *  - a file claiming another layout version, one whose derivative bounds
 *    attribute is damaged, and a truncated one are refused with the file's
 *    name and what to do.
 */
#define _GNU_SOURCE               /* memmem */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tex/tex.h"

static char dir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/test_tex_tiled.XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

typedef struct rng { uint64_t s; } rng;
static double uniform(rng *r)
{
    r->s ^= r->s << 13;
    r->s ^= r->s >> 7;
    r->s ^= r->s << 17;
    return (double)(r->s >> 11) / 9007199254740992.0;
}
static double between(rng *r, double lo, double hi) { return lo + (hi - lo) * uniform(r); }

/* a smooth map with noise: not constant at any level */
static tex_texture *make_map(int w, int h, int nch, rng *r)
{
    float *px = malloc((size_t)w * h * nch * sizeof *px);
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++)
            for (int c = 0; c < nch; c++)
                px[((size_t)j * w + i) * nch + c] =
                    (float)(sin(0.05 * i + c) * cos(0.03 * j) + 0.2 * between(r, -1, 1));
    tex_texture *t = tex_from_pixels(px, w, h, nch, "mem");
    free(px);
    assert_non_null(t);
    return t;
}

static char *write_map(const tex_texture *t, const char *name)
{
    static char path[4][300];
    static int next;
    char *p = path[next++ % 4];
    snprintf(p, 300, "%s/%s", dir, name);
    char err[512];
    assert_true(tex_write_exr(p, t, true, err, sizeof err));
    return p;
}

/* tex_cells_or_bound against tex_cells, then tex_bound where that gives
 * no cells (the affine lookup's path, issue 24): 1 when they differ */
static int cells_or_bound_differs(const tex_texture *t, int c, const tex_range *rg,
                                  tex_wrap sw, tex_wrap tw)
{
    tex_cell one[2], two[2];
    double lo1 = 0, hi1 = 0, lo2, hi2;
    memset(one, 0, sizeof one);
    memset(two, 0, sizeof two);
    int n1 = tex_cells(t, c, rg, sw, tw, one);
    if (n1 == 0)
        tex_bound(t, c, rg, sw, tw, 0.5, &lo1, &hi1);
    int n2 = tex_cells_or_bound(t, c, rg, sw, tw, 0.5, two, &lo2, &hi2);
    if (n1 != n2)
        return 1;
    if (n1 > 0)
        return memcmp(one, two, (size_t)n1 * sizeof one[0]) != 0;
    return !(memcmp(&lo1, &lo2, sizeof lo1) == 0 && memcmp(&hi1, &hi2, sizeof hi1) == 0);
}

/* one random lookup of every kind, a against b: the number of results
 * that differ (0: all exactly equal) */
static int compare_once(const tex_texture *a, const tex_texture *b, rng *r)
{
    int nch = tex_channels(a);
    int c = (int)(uniform(r) * nch);
    tex_wrap sw = (tex_wrap)(uniform(r) * 3), tw = (tex_wrap)(uniform(r) * 3);
    double s = between(r, -0.3, 1.3), t = between(r, -0.3, 1.3);
    double ws = uniform(r) < 0.5 ? 0 : pow(10, between(r, -4, -1));
    double wt = uniform(r) < 0.5 ? ws : pow(10, between(r, -4, -1));
    double da, db, ea, eb;
    double va = tex_sample(a, c, s, t, ws, wt, sw, tw, 0.5, &da, &ea);
    double vb = tex_sample(b, c, s, t, ws, wt, sw, tw, 0.5, &db, &eb);
    int bad = !(va == vb && da == db && ea == eb);
    double ds = pow(10, between(r, -5, -0.5)), dt = pow(10, between(r, -5, -0.5));
    double w0 = uniform(r) < 0.3 ? 0 : pow(10, between(r, -5, -1));
    tex_range rg = { { s, s + ds }, { t, t + dt }, { w0, w0 * 1.5 }, { w0, w0 * 1.5 } };
    double la, ha, lb, hb;
    tex_bound(a, c, &rg, sw, tw, 0.5, &la, &ha);
    tex_bound(b, c, &rg, sw, tw, 0.5, &lb, &hb);
    bad += !(la == lb && ha == hb);
    tex_range pt = { { s, s + ds * 1e-4 }, { t, t + dt * 1e-4 }, { ws, ws }, { ws, ws } };
    tex_cell ca[2], cb[2];
    int na = tex_cells(a, c, &pt, sw, tw, ca), nb = tex_cells(b, c, &pt, sw, tw, cb);
    bad += na != nb || (na > 0 && memcmp(ca, cb, (size_t)na * sizeof ca[0]) != 0);
    bad += cells_or_bound_differs(a, c, &rg, sw, tw) + cells_or_bound_differs(b, c, &rg, sw, tw);
    bad += cells_or_bound_differs(a, c, &pt, sw, tw) + cells_or_bound_differs(b, c, &pt, sw, tw);
    tex_range odd = uniform(r) < 0.5 ? rg : pt;       /* a NaN end; a missing channel */
    if (uniform(r) < 0.5)
        odd.s[0] = NAN;
    else
        odd.ws[1] = NAN;
    bad += cells_or_bound_differs(b, c, &odd, sw, tw) + cells_or_bound_differs(b, nch, &pt, sw, tw);
    return bad;
}

static void test_stored_equals_built(void **state)
{
    (void)state;
    static const int sizes[][3] = { { 700, 430, 1 }, { 512, 512, 3 }, { 301, 999, 2 } };
    rng r = { 0x1234567ull };
    for (int q = 0; q < 3; q++) {
        int w = sizes[q][0], h = sizes[q][1], nch = sizes[q][2];
        tex_texture *mem = make_map(w, h, nch, &r);
        char *path = write_map(mem, "stored.exr");
        char err[512] = "";
        tex_texture *file = tex_open(path, err, sizeof err);
        if (!file)
            fail_msg("%s", err);
        assert_true(tex_tiled_levels(file) >= 1);     /* levels left to tiles */
        assert_true(tex_bytes(file) < tex_bytes(mem));
        assert_int_equal(tex_width(file), w);
        assert_int_equal(tex_height(file), h);
        assert_int_equal(tex_channels(file), nch);
        assert_int_equal(tex_levels(file), tex_levels(mem));
        assert_string_equal(tex_type(file), tex_type(mem));
        for (int c = 0; c < nch; c++) {
            double a, b, x, y;
            tex_lipschitz(mem, c, &a, &b);
            tex_lipschitz(file, c, &x, &y);
            assert_true(a == x && b == y && a > 0);
        }
        for (int k = 0; k < tex_levels(mem); k++) {
            int lw = (w + (1 << k) - 1) >> k, lh = (h + (1 << k) - 1) >> k;
            for (int j = 0; j < lh; j++)
                for (int i = 0; i < lw; i++)
                    for (int c = 0; c < nch; c++)
                        if (tex_texel(mem, k, c, i, j) != tex_texel(file, k, c, i, j))
                            fail_msg("level %d texel %d,%d channel %d differs", k, i, j, c);
        }
        for (int n = 0; n < 20000; n++)
            assert_int_equal(compare_once(mem, file, &r), 0);
        /* written again from its tiles: the same texture */
        char *again = write_map(file, "again.exr");
        tex_texture *file2 = tex_open(again, err, sizeof err);
        assert_non_null(file2);
        for (int n = 0; n < 5000; n++)
            assert_int_equal(compare_once(mem, file2, &r), 0);
        tex_destroy(&file2);
        tex_destroy(&file);
        tex_destroy(&mem);
    }
}

typedef struct worker {
    const tex_texture *mem, *file;
    uint64_t seed;
    int differ;
} worker;

static void *lookups(void *arg)
{
    worker *wk = arg;
    rng r = { wk->seed };
    for (int n = 0; n < 6000; n++)
        wk->differ += compare_once(wk->mem, wk->file, &r);
    return NULL;
}

static void test_tiny_budget_same_results(void **state)
{
    (void)state;
    rng r = { 0xfeedull };
    tex_texture *mem = make_map(900, 700, 2, &r);
    char *path = write_map(mem, "budget.exr");
    size_t tile = 64 * 64 * 2 * sizeof(float);
    tex_tiles *pool = tex_tiles_new(4 * tile);
    char err[512] = "";
    tex_texture *file = tex_open_in(path, pool, err, sizeof err);
    if (!file)
        fail_msg("%s", err);
    assert_int_equal(tex_tiled_levels(file), 2);    /* 900x700 and 450x350 */
    enum { THREADS = 4 };
    pthread_t th[THREADS];
    worker wk[THREADS];
    for (int k = 0; k < THREADS; k++) {
        wk[k] = (worker){ mem, file, 0x9e3779b97f4a7c15ull * (uint64_t)(k + 1), 0 };
        assert_int_equal(pthread_create(&th[k], NULL, lookups, &wk[k]), 0);
    }
    for (int k = 0; k < THREADS; k++) {
        pthread_join(th[k], NULL);
        assert_int_equal(wk[k].differ, 0);
    }
    tex_tile_stats st;
    tex_tiles_stats(pool, &st);
    assert_true(st.evictions > 0);
    assert_true(st.loads > st.evictions);
    assert_true(st.failures == 0);
    assert_true(st.bytes <= st.budget);             /* nobody pins now */
    assert_true(st.peak_bytes <= st.budget + (THREADS * 16 + 1) * tile);
    /* the same pool without a budget: loads once, evicts none */
    tex_tiles *all = tex_tiles_new(0);
    tex_texture *file2 = tex_open_in(path, all, err, sizeof err);
    assert_non_null(file2);
    for (int n = 0; n < 3000; n++)
        assert_int_equal(compare_once(mem, file2, &r), 0);
    tex_tiles_stats(all, &st);
    assert_true(st.evictions == 0 && st.loads > 0);
    assert_true(st.loads <= (size_t)(15 * 11 + 8 * 6 + 8 * 6 + 8 * 6));  /* each tile once */
    tex_destroy(&file2);
    tex_tiles_destroy(&all);
    tex_destroy(&file);
    tex_tiles_stats(pool, &st);
    assert_true(st.bytes == 0);                     /* freeing a texture frees its tiles */
    tex_tiles_destroy(&pool);
    tex_destroy(&mem);
}

/* Writes n bytes `to` at `skip` bytes after the first `from` (of nf
 * bytes) in the file. */
static void patch_after(const char *path, const void *from, size_t nf, size_t skip,
                        const void *to, size_t n)
{
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    char *buf = malloc((size_t)size);
    fseek(f, 0, SEEK_SET);
    assert_int_equal(fread(buf, 1, (size_t)size, f), (size_t)size);
    char *at = memmem(buf, (size_t)size, from, nf);
    assert_non_null(at);
    fseek(f, at - buf + (long)skip, SEEK_SET);
    fwrite(to, 1, n, f);
    fclose(f);
    free(buf);
}

static void test_bad_files_refused(void **state)
{
    (void)state;
    rng r = { 0xabcdefull };
    tex_texture *mem = make_map(300, 300, 1, &r);
    char err[512];
    /* another layout version */
    char *path = write_map(mem, "version.exr");
    static const char v1[] = "aafarmTexture\0int\0\4\0\0\0\1\0\0\0";
    static const char v7[] = "aafarmTexture\0int\0\4\0\0\0\7\0\0\0";
    patch_after(path, v1, sizeof v1 - 1, 0, v7, sizeof v7 - 1);
    assert_null(tex_open(path, err, sizeof err));
    assert_non_null(strstr(err, path));
    assert_non_null(strstr(err, "version 7"));
    assert_non_null(strstr(err, "make it again with this aafarm-maketx"));
    /* damaged derivative bounds */
    path = write_map(mem, "lipschitz.exr");
    static const char lip[] = "aafarmLipschitz\0string\0";
    patch_after(path, lip, sizeof lip - 1, sizeof lip - 1 + 4, "zz", 2);  /* after the size */
    assert_null(tex_open(path, err, sizeof err));
    assert_non_null(strstr(err, path));
    assert_non_null(strstr(err, "aafarmLipschitz"));
    assert_non_null(strstr(err, "make it again with aafarm-maketx"));
    /* truncated: the pixels are not all there */
    path = write_map(mem, "short.exr");
    FILE *f = fopen(path, "r+b");
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    assert_int_equal(truncate(path, size / 2), 0);
    err[0] = '\0';
    tex_texture *t = tex_open(path, err, sizeof err);
    if (t) {
        tex_destroy(&t);
        fail_msg("a truncated texture opened");
    }
    assert_non_null(strstr(err, path));
    tex_destroy(&mem);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stored_equals_built),
        cmocka_unit_test(test_tiny_budget_same_results),
        cmocka_unit_test(test_bad_files_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

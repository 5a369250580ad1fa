/*
 * test_trace_determinism.c: the determinism contract (DESIGN.md §2) inside
 * one process: different tile sizes, thread counts, tile orders and box
 * cache budgets (down to the paper's 40 KB and below) give identical
 * pixels, for a scene with displacement, shadows, several samples per
 * pixel and a filter wider than a pixel; and lazy children (issue 24) give
 * the pixels of children evaluated four at a time; the same for a layered
 * shader whose boxes' children take their node's decisions (tape pruning).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fixture.h"
#include "shaders.h"

static const char *RIB =
    "Format 40 30 1\nProjection \"perspective\" \"fov\" [45]\n"
    "PixelSamples 2 2\nPixelFilter \"gaussian\" 2 2\n"
    "Translate 0 -0.3 3\nRotate -30 1 0 0\n"
    "WorldBegin\n"
    "LightSource \"ambientlight\" 1 \"intensity\" [0.1]\n"
    "LightSource \"distantlight\" 2 \"from\" [1 2 -1] \"to\" [0 0 0]\n"
    "Surface \"mymatte\"\n"
    "AttributeBegin\n"
    "  Displacement \"ripple\" \"float Km\" [0.08]\n"
    "  Patch \"bilinear\" \"P\" [-1.5 0 -1.5  1.5 0 -1.5  -1.5 0 1.5  1.5 0 1.5]\n"
    "AttributeEnd\n"
    "AttributeBegin\n"
    "  Translate 0.3 0.35 0\n"
    "  Displacement \"constd\" \"float h\" [0.05]\n"
    "  Sphere 0.25 -0.25 0.25 360\n"
    "AttributeEnd\n"
    "WorldEnd\n";

typedef struct run { int tile, threads; size_t cache; } run;

/* The scene above with its shaders */
static void open_scene(fixture *f)
{
    fixture_shader sh[] = {{"ripple", SHADER_RIPPLE}, {"constd", SHADER_CONSTD},
                           {"mymatte", SHADER_MYMATTE}};
    assert_true(fixture_open(f, RIB, sh, 3, NULL, 0));
}

/* The stats of a render in 8x8 tiles on one thread (the world's cache
 * budget) */
static trace_stats tile_stats(fixture *f)
{
    trace_thread *th = trace_thread_new(&f->js->world);
    float rgba[4 * 64], z[64];
    for (int y = 0; y < 30; y += 8)
        for (int x = 0; x < 40; x += 8)
            assert_true(trace_render_tile(f->js->renderer, th, x, y, x + 8 <= 40 ? 8 : 40 - x,
                                          y + 8 <= 30 ? 8 : 30 - y, rgba, z));
    trace_thread_sync_stats(th);
    trace_stats st = th->stats;
    trace_thread_destroy(&th);
    return st;
}

static void test_pixels_identical_across_tilings_threads_caches(void **state)
{
    (void)state;
    fixture f;
    open_scene(&f);
    int W = f.js->world.camera.xres, H = f.js->world.camera.yres;
    size_t npx = (size_t)W * (size_t)H;
    const run runs[] = {{8, 1, 0}, {13, 3, 40 * 1024}, {40, 2, 4 * 1024}, {5, 2, 400 * 1024}, {32, 1, 2048}};
    float *ref_rgba = malloc(sizeof(float) * 4 * npx), *ref_z = malloc(sizeof(float) * npx);
    float *rgba = malloc(sizeof(float) * 4 * npx), *z = malloc(sizeof(float) * npx);
    assert_true(fixture_render(&f, runs[0].tile, runs[0].threads, runs[0].cache, ref_rgba, ref_z));
    /* the image is not trivial: some hits, some misses, some shade */
    int hits = 0;
    double lum_min = 1e9, lum_max = -1e9;
    for (size_t i = 0; i < npx; i++) {
        if (isfinite(ref_z[i])) hits++;
        double l = ref_rgba[4 * i] + ref_rgba[4 * i + 1] + ref_rgba[4 * i + 2];
        if (l < lum_min) lum_min = l;
        if (l > lum_max) lum_max = l;
    }
    assert_true(hits > (int)npx / 4 && hits < (int)npx);
    assert_true(lum_max > lum_min + 0.1);
    for (size_t r = 1; r < sizeof runs / sizeof runs[0]; r++) {
        memset(rgba, 0, sizeof(float) * 4 * npx);
        assert_true(fixture_render(&f, runs[r].tile, runs[r].threads, runs[r].cache, rgba, z));
        assert_memory_equal(rgba, ref_rgba, sizeof(float) * 4 * npx);
        assert_memory_equal(z, ref_z, sizeof(float) * npx);
        printf("tile %2d, %d thread(s), cache %7zu bytes: %dx%d pixels identical\n",
               runs[r].tile, runs[r].threads, runs[r].cache, W, H);
    }
    free(ref_rgba); free(ref_z); free(rgba); free(z);
    fixture_close(&f);
}

static void test_small_cache_evicts_and_respects_budget(void **state)
{
    (void)state;
    fixture f;
    open_scene(&f);
    size_t budget = 16 * 1024;
    f.js->world.options.cache_bytes = budget;
    trace_stats st = tile_stats(&f);
    printf("cache %zu bytes: hits %ld misses %ld evictions %ld peak %zu\n", budget,
           st.cache_hits, st.cache_misses, st.cache_evictions, st.cache_peak_bytes);
    assert_true(st.cache_evictions > 0);
    assert_true(st.cache_peak_bytes <= budget);
    assert_true(st.cache_hits > 0);
    fixture_close(&f);
}

/* Lazy children (issue 24): evaluating a child only where a walk reaches
 * its restricted bound gives the pixels of evaluating all four at once
 * (the same boxes, walked in the same order), with fewer box runs; a bound
 * that a ray meets beyond its hit (the sphere's far side, behind its near
 * side) is never evaluated for that ray */
static void test_lazy_children_change_no_pixel(void **state)
{
    (void)state;
    fixture f;
    open_scene(&f);
    int W = f.js->world.camera.xres, H = f.js->world.camera.yres;
    size_t npx = (size_t)W * (size_t)H;
    float *rgba[2], *z[2];
    trace_stats st[2];
    for (int lazy = 0; lazy < 2; lazy++) {
        f.js->world.options.lazy_children = lazy;
        rgba[lazy] = malloc(sizeof(float) * 4 * npx);
        z[lazy] = malloc(sizeof(float) * npx);
        assert_true(fixture_render(&f, 8, 2, 40 * 1024, rgba[lazy], z[lazy]));
        st[lazy] = tile_stats(&f);
    }
    printf("all four children: %ld boxes; lazy: %ld boxes, %ld bounds made, met %ld times, "
           "%ld evaluated\n",
           st[0].boxes, st[1].boxes, st[1].lazy_bounds, st[1].lazy_met, st[1].lazy_evals);
    assert_memory_equal(rgba[0], rgba[1], sizeof(float) * 4 * npx);
    assert_memory_equal(z[0], z[1], sizeof(float) * npx);
    assert_int_equal(st[0].lazy_bounds, 0);
    assert_true(st[1].lazy_evals > 0 && st[1].lazy_evals < st[1].lazy_bounds);
    /* each evaluation follows a meeting; some meetings lie beyond a hit */
    assert_true(st[1].lazy_evals < st[1].lazy_met);
    assert_int_equal(st[0].lazy_met, 0);
    assert_true(st[1].boxes < st[0].boxes);
    for (int i = 0; i < 2; i++) {
        free(rgba[i]);
        free(z[i]);
    }
    fixture_close(&f);
}

/* Tape pruning (issue 24): a patch under a layered shader (two noise
 * layers mixed by a mask that saturates) and the higher of two noise
 * fields; the children of boxes whose runs decided the mask or the max
 * take those decisions. The pixels are the same for every tiling, thread
 * count and cache budget (a box's tape, like the box, is a function of
 * its cell), and boxes did take tapes. (The pixels alone would not show a
 * tape that depended on the thread's history: a pruned run mostly gives
 * the whole program's box bits; test_corpus_containment makes each taped
 * box twice and compares them.) */
static const char *TAPE_RIB =
    "Format 40 30 1\nProjection \"perspective\" \"fov\" [45]\n"
    "PixelSamples 2 2\nPixelFilter \"gaussian\" 2 2\n"
    "Translate 0 -0.3 3\nRotate -30 1 0 0\n"
    "WorldBegin\n"
    "LightSource \"distantlight\" 1 \"from\" [1 2 -1] \"to\" [0 0 0]\n"
    "Surface \"mymatte\"\n"
    "AttributeBegin\n"
    "  Displacement \"layers\"\n"
    "  Patch \"bilinear\" \"P\" [-1.5 0 -1.5  1.5 0 -1.5  -1.5 0 1.5  1.5 0 1.5]\n"
    "AttributeEnd\n"
    "WorldEnd\n";

#define SHADER_LAYERS                                                             \
    "displacement layers(float Km = 0.06)\n"                                      \
    "{\n"                                                                         \
    "    point q = transform(\"shader\", P) * 4;\n"                               \
    "    float rock = noise(q) + 0.5 * noise(q * 2), sand = 0.4 * noise(q * 6);\n" \
    "    float m = smoothstep(0.45, 0.55, noise(q * 0.5 + 7));\n"                 \
    "    float h = max(mix(rock, sand, m), 0.3 * noise(q * 3));\n"                 \
    "    P += Km * h * normalize(N);\n"                                            \
    "    N = calculatenormal(P);\n"                                               \
    "}\n"

static void test_tape_pruning_same_pixels(void **state)
{
    (void)state;
    fixture f;
    fixture_shader sh[] = {{"layers", SHADER_LAYERS}, {"mymatte", SHADER_MYMATTE}};
    assert_true(fixture_open(&f, TAPE_RIB, sh, 2, NULL, 0));
    int W = f.js->world.camera.xres, H = f.js->world.camera.yres;
    size_t npx = (size_t)W * (size_t)H;
    const run runs[] = {{8, 1, 0}, {13, 3, 40 * 1024}, {40, 2, 4 * 1024}, {5, 2, 2048}};
    float *ref_rgba = malloc(sizeof(float) * 4 * npx), *ref_z = malloc(sizeof(float) * npx);
    float *rgba = malloc(sizeof(float) * 4 * npx), *z = malloc(sizeof(float) * npx);
    assert_true(fixture_render(&f, runs[0].tile, runs[0].threads, runs[0].cache, ref_rgba, ref_z));
    int hits = 0;
    for (size_t i = 0; i < npx; i++) hits += isfinite(ref_z[i]) != 0;
    assert_true(hits > (int)npx / 4);
    for (size_t r = 1; r < sizeof runs / sizeof runs[0]; r++) {
        assert_true(fixture_render(&f, runs[r].tile, runs[r].threads, runs[r].cache, rgba, z));
        assert_memory_equal(rgba, ref_rgba, sizeof(float) * 4 * npx);
        assert_memory_equal(z, ref_z, sizeof(float) * npx);
    }
    trace_stats st = tile_stats(&f);
    printf("tape pruning: %ld of %ld box runs took a tape (%ld plans made)\n", st.tape_runs,
           st.boxes, st.tape_plans);
    assert_true(st.tape_runs > 0 && st.tape_plans > 0);
    f.js->world.options.tape_pruning = false;
    st = tile_stats(&f);
    assert_int_equal(st.tape_runs, 0);
    free(ref_rgba); free(ref_z); free(rgba); free(z);
    fixture_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pixels_identical_across_tilings_threads_caches),
        cmocka_unit_test(test_tape_pruning_same_pixels),
        cmocka_unit_test(test_small_cache_evicts_and_respects_budget),
        cmocka_unit_test(test_lazy_children_change_no_pixel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

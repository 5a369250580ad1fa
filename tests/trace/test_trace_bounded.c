/*
 * test_trace_bounded.c: bounded work (issue 9, docs/renderer.md "Bounded
 * work"). Shaders whose result is NaN or unbounded everywhere used to make
 * every ray search the quadtree without end; now each walk stops at the
 * work limit, the ray is counted per object, and no hit is invented from a
 * surface point that is not on the ray. A cancelled thread stops a tile at
 * once. Counts are deterministic (nodes, not seconds).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "fixture.h"
#include "trace/render.h"

#define SPHERE_RIB(shader)                                         \
    "Format 12 8 1\nProjection \"perspective\" \"fov\" [40]\n"     \
    "Translate 0 0 5\n"                                            \
    "WorldBegin\n"                                                 \
    "Displacement \"" shader "\"\n"                                \
    "Sphere 1 -1 1 360\n"                                          \
    "WorldEnd\n"

static const char *NAN_SL =
    "displacement nanp(float Km = 0.1)\n"
    "{\n"
    "    P += (0/0) * N;\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *SQRTNEG_SL =
    "displacement sqrtneg(float Km = 0.1)\n"
    "{\n"
    "    P += Km * sqrt(-1 - s) * normalize(N);\n"
    "}\n";

/* Renders the whole small image with a low work limit; returns the
 * thread's statistics and the largest alpha. */
static void render_limited(const char *rib, const char *name, const char *src,
                           long limit, trace_stats *st, long *object_rays,
                           double *max_alpha)
{
    fixture f;
    fixture_shader sh[] = {{name, src}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    f.js->world.options.max_nodes_per_ray = limit;
    trace_thread *th = trace_thread_new(&f.js->world);
    int w = f.js->world.camera.xres, h = f.js->world.camera.yres;
    float *rgba = calloc((size_t)w * (size_t)h * 4, sizeof *rgba);
    float *z = calloc((size_t)w * (size_t)h, sizeof *z);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, w, h, rgba, z));
    *max_alpha = 0;
    for (int i = 0; i < w * h; i++)
        if (rgba[i * 4 + 3] > *max_alpha) *max_alpha = rgba[i * 4 + 3];
    *st = th->stats;
    *object_rays = th->work[0].limited_rays;
    free(rgba);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static void check_undefined_shader(const char *name, const char *src)
{
    trace_stats st;
    long object_rays;
    double max_alpha;
    const long limit = 300;
    char rib[512];
    snprintf(rib, sizeof rib, SPHERE_RIB("%s"), name);
    render_limited(rib, name, src, limit, &st, &object_rays, &max_alpha);
    printf("%s: %ld primary rays, %ld limited, %ld nodes, max %ld nodes/ray, "
           "%ld rejected leaves, max alpha %.3f\n", name, st.primary_rays,
           st.limited_rays, st.nodes, st.max_nodes_per_ray, st.rejected_leaves, max_alpha);
    /* every ray that meets the root box runs into the limit, and stops there */
    assert_true(st.limited_rays > 0);
    assert_int_equal(object_rays, st.limited_rays);
    assert_true(st.max_nodes_per_ray <= limit + 1);
    assert_true(st.nodes <= (limit + 1) * st.primary_rays);
    /* a surface that is nowhere defined is nowhere drawn */
    assert_true(st.rejected_leaves > 0);
    assert_true(max_alpha == 0.0);
}

static void test_nan_shader_is_bounded(void **state)
{
    (void)state;
    check_undefined_shader("nanp", NAN_SL);
}

static void test_sqrt_of_negative_is_bounded(void **state)
{
    (void)state;
    check_undefined_shader("sqrtneg", SQRTNEG_SL);
}

/* The limit is a pure function of the ray: two renders, one with a warm
 * cache, count the same nodes and limited rays. */
static void test_limit_is_deterministic(void **state)
{
    (void)state;
    trace_stats a, b;
    long ra, rb;
    double ma, mb;
    render_limited(SPHERE_RIB("nanp"), "nanp", NAN_SL, 200, &a, &ra, &ma);
    render_limited(SPHERE_RIB("nanp"), "nanp", NAN_SL, 200, &b, &rb, &mb);
    assert_int_equal(a.nodes, b.nodes);
    assert_int_equal(a.limited_rays, b.limited_rays);
}

/* A cancelled thread ends the tile at the next sample: false, "interrupted". */
static void test_cancel_stops_a_tile(void **state)
{
    (void)state;
    fixture f;
    fixture_shader sh[] = {{"nanp", NAN_SL}};
    assert_true(fixture_open(&f, SPHERE_RIB("nanp"), sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    atomic_int flag;
    atomic_init(&flag, 1);
    th->cancel = &flag;
    float rgba[12 * 8 * 4], z[12 * 8];
    assert_false(trace_render_tile(f.js->renderer, th, 0, 0, 12, 8, rgba, z));
    assert_string_equal(th->error, "interrupted");
    assert_true(th->stats.primary_rays == 0);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nan_shader_is_bounded),
        cmocka_unit_test(test_sqrt_of_negative_is_bounded),
        cmocka_unit_test(test_limit_is_deterministic),
        cmocka_unit_test(test_cancel_stops_a_tile),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

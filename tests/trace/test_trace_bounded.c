/*
 * test_trace_bounded.c: bounded work (issue 9, docs/renderer.md "Bounded
 * work"). Shaders whose result is NaN or unbounded everywhere, or with an
 * extreme parameter, used to make every ray search the quadtree without
 * end; now each walk stops at the work limit, and the first ray that
 * reaches it finds out whether the surface can converge at all (fail fast
 * with the cause) or is merely costly (the ray is counted per object). A
 * cancelled thread stops a tile at once. Counts are deterministic (nodes,
 * not seconds).
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

static const char *HUGEFREQ_SL =
    "displacement hugefreq(float Km = 0.5, frequency = -1e308)\n"
    "{\n"
    "    P += Km * sin(2 * PI * frequency * s) * normalize(N);\n"
    "}\n";

static const char *RIPPLE_SL =
    "displacement ripple(float Km = 0.05)\n"
    "{\n"
    "    P += Km * sin(20 * s) * sin(17 * t) * normalize(N);\n"
    "}\n";

typedef struct outcome {
    bool ok;                     /* the tile rendered */
    char error[ERR_LEN];
    trace_stats st;
    long object_rays;            /* limited rays counted on the object */
    double max_alpha;
} outcome;

/* Renders the whole small image with the given work limit. */
static void render_limited(const char *name, const char *src, long limit, outcome *out)
{
    char rib[512];
    snprintf(rib, sizeof rib, SPHERE_RIB("%s"), name);
    fixture f;
    fixture_shader sh[] = {{name, src}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    f.js->world.options.max_nodes_per_ray = limit;
    trace_thread *th = trace_thread_new(&f.js->world);
    int w = f.js->world.camera.xres, h = f.js->world.camera.yres;
    float *rgba = calloc((size_t)w * (size_t)h * 4, sizeof *rgba);
    float *z = calloc((size_t)w * (size_t)h, sizeof *z);
    out->ok = trace_render_tile(f.js->renderer, th, 0, 0, w, h, rgba, z);
    snprintf(out->error, sizeof out->error, "%s", th->error);
    out->max_alpha = 0;
    for (int i = 0; out->ok && i < w * h; i++)
        if (rgba[i * 4 + 3] > out->max_alpha) out->max_alpha = rgba[i * 4 + 3];
    out->st = th->stats;
    out->object_rays = th->work[0].limited_rays;
    printf("%s (limit %ld): %s; %ld primary rays, %ld limited, %ld nodes, max %ld nodes/ray\n",
           name, limit, out->ok ? "rendered" : out->error, out->st.primary_rays,
           out->st.limited_rays, out->st.nodes, out->st.max_nodes_per_ray);
    free(rgba);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* NaN or infinite everywhere: the first ray that reaches the work limit
 * finds the surface undefined (converge.h) and the tile fails at once,
 * naming the shader and the cause; no hit is invented. */
static void check_fails_fast(const char *name, const char *src, const char *cause)
{
    outcome o;
    const long limit = 300;
    render_limited(name, src, limit, &o);
    assert_false(o.ok);
    assert_non_null(strstr(o.error, name));
    assert_non_null(strstr(o.error, cause));
    assert_int_equal(o.st.limited_rays, 1);
    assert_true(o.st.max_nodes_per_ray <= limit + 1);
}

static void test_nan_shader_fails_fast(void **state)
{
    (void)state;
    check_fails_fast("nanp", NAN_SL, "gives no finite surface");
}

static void test_sqrt_of_negative_fails_fast(void **state)
{
    (void)state;
    check_fails_fast("sqrtneg", SQRTNEG_SL, "gives no finite surface");
}

static void test_extreme_frequency_fails_fast(void **state)
{
    (void)state;
    check_fails_fast("hugefreq", HUGEFREQ_SL, "does not converge");
}

/* A farm worker retries a failed tile on the same thread (its box cache
 * warm): the retry must fail as fast, not run every ray to the limit. */
static void test_retry_on_the_same_thread_fails_fast(void **state)
{
    (void)state;
    char rib[512];
    snprintf(rib, sizeof rib, SPHERE_RIB("%s"), "hugefreq");
    fixture f;
    fixture_shader sh[] = {{"hugefreq", HUGEFREQ_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    f.js->world.options.max_nodes_per_ray = 300;
    trace_thread *th = trace_thread_new(&f.js->world);
    float rgba[12 * 8 * 4], z[12 * 8];
    for (int attempt = 0; attempt < 3; attempt++) {
        long before = th->stats.limited_rays;
        assert_false(trace_render_tile(f.js->renderer, th, 0, 0, 12, 8, rgba, z));
        assert_non_null(strstr(th->error, "does not converge"));
        assert_int_equal(th->stats.limited_rays - before, 1);
        th->failed = false;               /* as the worker does after a failed tile */
        th->error[0] = '\0';
    }
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* A surface that converges but needs more nodes than the limit allows:
 * the rays that reach it are counted on the object and keep what they
 * found; the render goes on. The counts are a pure function of the rays:
 * the same in a second render. */
static void test_limited_rays_are_counted(void **state)
{
    (void)state;
    outcome a, b;
    render_limited("ripple", RIPPLE_SL, 5, &a);
    assert_true(a.ok);
    assert_true(a.st.limited_rays > 0);
    assert_int_equal(a.object_rays, a.st.limited_rays);
    assert_true(a.st.max_nodes_per_ray <= 6);
    assert_true(a.max_alpha > 0);
    render_limited("ripple", RIPPLE_SL, 5, &b);
    assert_int_equal(a.st.nodes, b.st.nodes);
    assert_int_equal(a.st.limited_rays, b.st.limited_rays);
    /* with the default limit no ray of this scene needs it */
    render_limited("ripple", RIPPLE_SL, TRACE_DEFAULT_MAX_NODES_PER_RAY, &a);
    assert_true(a.ok);
    assert_int_equal(a.st.limited_rays, 0);
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
        cmocka_unit_test(test_nan_shader_fails_fast),
        cmocka_unit_test(test_sqrt_of_negative_fails_fast),
        cmocka_unit_test(test_extreme_frequency_fails_fast),
        cmocka_unit_test(test_retry_on_the_same_thread_fails_fast),
        cmocka_unit_test(test_limited_rays_are_counted),
        cmocka_unit_test(test_cancel_stops_a_tile),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

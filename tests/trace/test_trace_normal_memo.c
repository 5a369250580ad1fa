/*
 * test_trace_normal_memo.c: the per-thread memo of a planar patch's
 * camera-space unit normal (trace/normal_memo.c) changes no box.
 *
 *   same boxes   18 planar patches (and 18 polygons) turned by quarter turns about the x
 *                axis (ids 0 and 16, 1 and 17 share a memo slot: 16 has
 *                0's Ng and another transform, 17 has 1's transform and
 *                another Ng), displaced by a shader that reads
 *                normalize(N): boxes of random cells computed on
 *                one thread, the objects interleaved, equal bit for bit
 *                the boxes of a fresh thread per box (an empty memo)
 *   answers      the memo answered (trace_stats.normal_hits) for most of
 *                the warm thread's boxes and never for a fresh thread's
 *                first box
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
#include "trace/displace.h"
#include "trace/thread.h"

enum { PATCHES = 18 };

static const char *BUMPS_SL =
    "displacement bumps(float Km = 0.05)\n"
    "{\n"
    "    P += Km * sin(9 * s) * cos(7 * t) * normalize(N);\n"
    "}\n";

/* Patch k: the square of side 2 turned by k quarter turns about the x
 * axis and moved (exact matrices: the objects' normal_scale and
 * normal_len2 are the same bits), except that patch 16 is patch 0's square
 * turned once (the same object-space Ng, another transform) and patch 17
 * is patch 1's transform over the square tilted to z = x (another Ng, the
 * same transform): the pairs that share a memo slot differ in one key
 * each, and so do their normals */
static char *patches_rib(bool polygons)
{
    static const char *const turn[4] = {
        "1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1", "1 0 0 0  0 0 1 0  0 -1 0 0  0 0 0 1",
        "1 0 0 0  0 -1 0 0  0 0 -1 0  0 0 0 1", "1 0 0 0  0 0 -1 0  0 1 0 0  0 0 0 1"};
    size_t size = 8192 + PATCHES * 256;
    char *rib = malloc(size);
    assert_non_null(rib);
    int n = snprintf(rib, size,
                     "Format 16 16 1\nProjection \"perspective\" \"fov\" [40]\n"
                     "Translate 0 0 6\nWorldBegin\nDisplacement \"bumps\"\n"
                     "Attribute \"displacementbound\" \"sphere\" [0.1]\n");
    for (int k = 0; k < PATCHES; k++) {
        int q = k == 16 ? 1 : k == 17 ? 1 : k % 4;
        double tilt = k == 17 ? 1 : 0, dx = k == 16 ? 0 : k == 17 ? 0.125 : 0.125 * k;
        n += snprintf(rib + n, size - (size_t)n,
                      polygons ? "AttributeBegin\nTranslate %g 0 0\nConcatTransform [%s]\n"
                                 "Polygon \"P\" [-1 -1 %g  1 -1 %g  1 1 %g  -1 1 %g]\n"
                                 "AttributeEnd\n"
                               : "AttributeBegin\nTranslate %g 0 0\nConcatTransform [%s]\n"
                                 "Patch \"bilinear\" \"P\" [-1 -1 %g  1 -1 %g  -1 1 %g  "
                                 "1 1 %g]\nAttributeEnd\n",
                      dx, turn[q], -tilt, tilt, polygons ? tilt : -tilt, polygons ? -tilt : tilt);
    }
    snprintf(rib + n, size - (size_t)n, "WorldEnd\n");
    return rib;
}

static uint64_t rng = 0x2545f4914f6cdd1dull;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1p-53;
}

static void check_same_boxes(bool polygons)
{
    fixture f;
    fixture_shader sh[] = {{"bumps", BUMPS_SL}};
    char *rib = patches_rib(polygons);
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    free(rib);
    const trace_world *world = &f.js->world;
    assert_int_equal(world->nobjects, PATCHES);
    trace_thread *warm = trace_thread_new(world);
    int cases = 0, differ = 0;
    for (int round = 0; round < 6; round++)
        for (int k = 0; k < PATCHES; k++) {
            /* the objects in a different order each round */
            const trace_object *obj = &world->objects[(k * 7 + round * 5) % PATCHES];
            double w = ldexp(1.0, -(int)(rnd() * 8)), u0 = rnd() * (1 - w), v0 = rnd() * (1 - w);
            trace_box a, b;
            trace_surface_box(warm, obj, u0, u0 + w, v0, v0 + w, &a);
            trace_thread *cold = trace_thread_new(world);
            trace_surface_box(cold, obj, u0, u0 + w, v0, v0 + w, &b);
            assert_int_equal(cold->stats.normal_hits, 0);
            trace_thread_destroy(&cold);
            cases++;
            if (memcmp(&a, &b, sizeof a) != 0) {
                if (differ++ < 3)
                    printf("  patch %d, cell %g+%g x %g+%g: x [%.17g, %.17g] warm, [%.17g, "
                           "%.17g] cold\n", obj->id, u0, w, v0, w, a.lo.x, a.hi.x, b.lo.x, b.hi.x);
            }
        }
    printf("%s: %d boxes, %d differ; the memo answered %ld times\n",
           polygons ? "polygons" : "patches", cases, differ, warm->stats.normal_hits);
    assert_int_equal(differ, 0);
    /* the first round fills the 16 slots, the two pairs that share one
     * evict each other; most of the rest are answers */
    assert_true(warm->stats.normal_hits > cases / 2);
    trace_thread_destroy(&warm);
    fixture_close(&f);
}

static void test_same_boxes(void **state)
{
    (void)state;
    check_same_boxes(false);
    check_same_boxes(true);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_boxes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

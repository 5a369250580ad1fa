/*
 * test_trace_leaf_start.c: where a leaf's Newton steps start
 * (common/trace/intersect.c, leaf_start; issue 24, session 29). A leaf
 * whose box has a linear bound and bends little starts its steps where
 * the ray meets the bound's plane instead of at the cell's centre: one
 * evaluation of the surface fewer a leaf, the same hits.
 *
 * Every primary ray of a small image of a wall displaced by three octaves
 * of noise is traced twice, with leaf_start on and off (hit proofs off:
 * every hit is a leaf's). The start at the centre is the reference:
 *   - the same rays hit, and where both hit, at the same distance within
 *     the leaf tolerance (a pixel footprint along the ray);
 *   - every hit's surface point lies within a footprint of its ray, and
 *     the hit's (u,v) are its point's;
 *   - on, the leaves take at most 1.3 evaluations each (measured 1.0x);
 *     off, at least 1.8 (measured 2.0: the centre, then a step): a start
 *     that lands off the surface's hit (the plane solved wrongly) costs
 *     the steps it saves.
 * A height map read by texture() (the corpus's tex_heightmap on its
 * plane) starts no leaf on the plane: a lookup over several texels is a
 * bound, whose linear part says nothing of where the ray meets the map
 * (the peer terrain: 353 -> 379 pixels off its 1/16-pixel reference with
 * starts on the plane, back to 353 without).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "corpus.h"
#include "fixture.h"
#include "trace/camera.h"
#include "trace/intersect.h"
#include "trace/render.h"

static const char *FBM_SL =
    "displacement fbm3(float Km = 0.05)\n"
    "{\n"
    "    point p = point(s * 1.5, t * 1.5, 0);\n"
    "    float h = 0, amp = 1, i;\n"
    "    for (i = 0; i < 3; i += 1) {\n"
    "        h += amp * (2 * noise(p) - 1);\n"
    "        amp *= 0.5;\n"
    "        p *= 2;\n"
    "    }\n"
    "    P += Km * h * normalize(N);\n"
    "}\n";

/* a wall facing the camera (%s: the shader) */
static const char *FACING_RIB =
    "Format 48 36 1\nProjection \"perspective\" \"fov\" [30]\n"
    "WorldBegin\nTranslate 0 0 2.5\nDisplacement \"%s\"\n"
    "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"st\" [0 0  1 0  1 1  0 1]\nWorldEnd\n";

/* the same octaves folded at their middle: a crease wherever a noise
 * crosses 0.5 (ridged noise) */
static const char *RIDGED_SL =
    "displacement ridged3(float Km = 0.05)\n"
    "{\n"
    "    point p = point(s * 1.5, t * 1.5, 0);\n"
    "    float h = 0, amp = 1, i;\n"
    "    for (i = 0; i < 3; i += 1) {\n"
    "        h += amp * (1 - abs(2 * noise(p) - 1));\n"
    "        amp *= 0.5;\n"
    "        p *= 2;\n"
    "    }\n"
    "    P += Km * h * normalize(N);\n"
    "}\n";

/* a tilted wall under a perspective camera (%s: the shader) */
static const char *WALL_RIB =
    "Format 48 36 1\nProjection \"perspective\" \"fov\" [30]\n"
    "WorldBegin\nTranslate 0 0 3\nRotate -50 1 0 0\nDisplacement \"%s\"\n"
    "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"st\" [0 0  1 0  1 1  0 1]\nWorldEnd\n";


typedef struct pass {
    bool hit[48 * 36];
    trace_hit h[48 * 36];
    long leaves, evals, starts;
    double worst;                /* the largest distance of a hit's point from
                                    its ray, in pixel footprints */
} pass;

static void trace_pass(fixture *f, bool leaf_start, pass *p)
{
    trace_world *world = &f->js->world;
    world->options.prove_hits = false;
    world->options.leaf_start = leaf_start;
    trace_thread *th = trace_thread_new(world);
    const trace_object *obj = &world->objects[0];
    const trace_camera *cam = &world->camera;
    trace_tolerance tol = f->js->renderer->primary_tol;
    assert_int_equal(cam->xres * cam->yres, 48 * 36);
    p->worst = 0;
    for (int y = 0; y < cam->yres; y++)
        for (int x = 0; x < cam->xres; x++) {
            int i = y * cam->xres + x;
            trace_ray ray;
            trace_camera_ray(cam, x + 0.5, y + 0.5, &ray);
            p->h[i] = (trace_hit){.t = ray.tmax};
            p->hit[i] = trace_intersect_object(th, obj, &ray, &tol, false, &p->h[i]);
            if (!p->hit[i]) continue;
            /* the hit's (u,v) are its point's */
            assert_true(p->h[i].has_point);
            assert_true(p->h[i].u == p->h[i].point.u && p->h[i].v == p->h[i].point.v);
            vec3 off = v3_sub(p->h[i].point.P, trace_ray_at(&ray, p->h[i].t));
            p->worst = fmax(p->worst, v3_length(off) / (tol.a + tol.b * p->h[i].t));
        }
    p->leaves = th->stats.leaves;
    p->evals = th->stats.evals_dual;
    p->starts = th->stats.leaf_starts;
    trace_thread_destroy(&th);
}

/* Traces the scene (rib_format with the shader's name) both ways and
 * checks the hits agree; the passes in *on and *off */
static void check_hits_agree(const char *rib_format, const char *name, const char *source,
                             pass *on, pass *off)
{
    char rib[512];
    snprintf(rib, sizeof rib, rib_format, name);
    fixture f;
    fixture_shader sh[] = {{name, source}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_pass(&f, true, on);
    trace_pass(&f, false, off);
    trace_tolerance tol = f.js->renderer->primary_tol;
    const trace_camera *cam = &f.js->world.camera;
    int hits = 0, differ = 0, far = 0;
    for (int y = 0; y < cam->yres; y++)
        for (int x = 0; x < cam->xres; x++) {
            int i = y * cam->xres + x;
            if (on->hit[i] != off->hit[i]) {
                differ++;
                continue;
            }
            if (!on->hit[i]) continue;
            hits++;
            trace_ray ray;
            trace_camera_ray(cam, x + 0.5, y + 0.5, &ray);
            double t_tol = (tol.a + tol.b * off->h[i].t) / v3_length(ray.d);
            if (!(fabs(on->h[i].t - off->h[i].t) <= t_tol)) {
                if (far++ < 5)
                    printf("  pixel (%d, %d): t %.9f from the plane, %.9f from the centre\n", x,
                           y, on->h[i].t, off->h[i].t);
            }
        }
    printf("%s: %d rays hit; leaves %ld and %ld (%ld started on the plane), evaluations a "
           "leaf %.3f from the plane, %.3f from the centre; hits' points at most %.3g and "
           "%.3g footprints off their ray\n",
           name, hits, on->leaves, off->leaves, on->starts, (double)on->evals / (double)on->leaves,
           (double)off->evals / (double)off->leaves, on->worst, off->worst);
    assert_true(hits > 48 * 36 / 2);
    assert_int_equal(differ, 0);
    assert_int_equal(far, 0);
    assert_true(on->worst <= 1.0);
    assert_true(off->worst <= 1.0);
    assert_true(on->leaves > 0 && off->leaves > 0);
    assert_int_equal(off->starts, 0);
    fixture_close(&f);
}

static void test_leaves_start_on_their_plane(void **state)
{
    (void)state;
    static pass on, off;
    check_hits_agree(WALL_RIB, "fbm3", FBM_SL, &on, &off);
    assert_true(on.starts > on.leaves / 2);
    assert_true((double)on.evals <= 1.3 * (double)on.leaves);
    assert_true((double)off.evals >= 1.8 * (double)off.leaves);
}

/* A wall facing the camera: its normal is (0, 0, -1) up to rounding,
 * which normalize()'s clamps to [-1, 1] cut without a crease (with the
 * clamps taken for creases, no leaf starts on the plane) */
static void test_normalize_is_no_crease(void **state)
{
    (void)state;
    static pass on, off;
    check_hits_agree(FACING_RIB, "fbm3", FBM_SL, &on, &off);
    assert_true(on.starts > on.leaves / 2);
}

/* Where the run saw a crease (abs across 0: AA_KINK) the leaf starts at
 * its centre: a start on the plane settles at once beside a crease where
 * the steps from the centre would not, and the leaf goes untested */
static void test_creases_start_at_the_centre(void **state)
{
    (void)state;
    static pass on, off;
    check_hits_agree(WALL_RIB, "ridged3", RIDGED_SL, &on, &off);
    assert_true(on.starts > 0);
    assert_true(on.starts < on.leaves - on.leaves / 8);
}

static void test_height_maps_start_at_the_centre(void **state)
{
    (void)state;
    corpus C;
    assert_true(corpus_load(&C));
    const corpus_file *sh = NULL;
    for (int i = 0; i < C.nshaders; i++)
        if (strcmp(C.shaders[i].name, "tex_heightmap") == 0) sh = &C.shaders[i];
    assert_non_null(sh);
    fixture f;
    assert_true(corpus_open(&f, &C, sh, CORPUS_PLANE, TRACE_ARITH_AFFINE, 48, 36, true));
    static pass on;
    trace_pass(&f, true, &on);
    printf("tex_heightmap: %ld leaves, %ld started on the plane\n", on.leaves, on.starts);
    assert_true(on.leaves > 100);
    assert_int_equal(on.starts, 0);
    fixture_close(&f);
    corpus_free(&C);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_leaves_start_on_their_plane),
        cmocka_unit_test(test_normalize_is_no_crease),
        cmocka_unit_test(test_creases_start_at_the_centre),
        cmocka_unit_test(test_height_maps_start_at_the_centre),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

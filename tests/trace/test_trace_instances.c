/*
 * test_trace_instances.c: instances share one box cache per object in
 * object space (issue 14, "no copy per instance"; trace/instance.c).
 *
 * A displaced sphere (bumps from "object"-space P along normalize(N))
 * placed four times by ObjectInstance, each moved and turned differently,
 * against the same four spheres written out as separate copies:
 *   - the instances share their prototype (box_proto) and its cache
 *     entries: after a render no instance but the first has a root brood of
 *     its own, and the cache holds under half the bytes of the copies'
 *     (which have a root brood each);
 *   - the two images agree (alpha in the same pixels but for 1 % on
 *     silhouettes, colours within a small tolerance: the instances' hits
 *     come from other boxes of the same surface);
 *   - containment: for the instances, random (u,v) ranges' boxes (from the
 *     prototype) hold the instance's own surface points, mapped to object
 *     space, up to a few ulps: 0 violations;
 *   - the fall-backs: a shader of camera-space P, or a scaled instance,
 *     keeps its own boxes.
 */
#include <float.h>
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
#include "trace/render.h"

static const char *BUMPS_SL =
    "displacement bumps(float Km = 0.08)\n"
    "{\n"
    "    point Po = transform(\"object\", P);\n"
    "    P += Km * sin(7 * xcomp(Po)) * sin(6 * ycomp(Po)) * cos(5 * zcomp(Po)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* the same bumps from camera-space P: depends on where the instance is */
static const char *CAMBUMPS_SL =
    "displacement cambumps(float Km = 0.08)\n"
    "{\n"
    "    P += Km * sin(7 * xcomp(P)) * sin(6 * ycomp(P)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

enum { W = 128, H = 40, N = 4 };

/* The four placements; `scale` stretches the last one (not rigid). */
static char *scene_rib(bool instanced, const char *shader, bool scale)
{
    size_t cap = 8192;
    char *s = malloc(cap);
    size_t len = (size_t)snprintf(s, cap,
        "Format %d %d 1\nPixelSamples 2 2\nProjection \"perspective\" \"fov\" [30]\n"
        "Translate 0 0 6\nWorldBegin\n"
        "LightSource \"distantlight\" 1 \"from\" [1 1 -2] \"to\" [0 0 0]\n"
        "Surface \"plastic\"\nDisplacement \"%s\" \"float Km\" [0.08]\n", W, H, shader);
    if (instanced)
        len += (size_t)snprintf(s + len, cap - len,
                                "ObjectBegin 1\n  Sphere 0.8 -0.8 0.8 360\nObjectEnd\n");
    for (int i = 0; i < N; i++)
        len += (size_t)snprintf(s + len, cap - len,
            "AttributeBegin\n  Translate %g %g 0\n  Rotate %d 0.3 1 0.2\n%s  %s\nAttributeEnd\n",
            -3.3 + 2.2 * i, 0.1 * i, 35 * i, scale && i == N - 1 ? "  Scale 1 1.3 1\n" : "",
            instanced ? "ObjectInstance 1" : "Sphere 0.8 -0.8 0.8 360");
    snprintf(s + len, cap - len, "WorldEnd\n");
    return s;
}

static const char *PLASTIC_SL =
    "surface plastic(float Ka = 1, Kd = 0.6, Ks = 0.4, roughness = 0.1)\n"
    "{\n"
    "    normal Nf = faceforward(normalize(N), I);\n"
    "    Oi = Os;\n"
    "    Ci = Os * Cs * (Ka * ambient() + Kd * diffuse(Nf)) +\n"
    "         Ks * specular(Nf, -normalize(I), roughness);\n"
    "}\n";

typedef struct shot {
    float *rgba;
    size_t peak_bytes;
    int own_roots;                 /* objects with a root brood of their own */
    int shared;                    /* objects with a box_proto */
} shot;

static void render(const char *rib, shot *out)
{
    fixture f;
    fixture_shader sh[] = {{"bumps", BUMPS_SL}, {"cambumps", CAMBUMPS_SL},
                           {"plastic", PLASTIC_SL}};
    assert_true(fixture_open(&f, rib, sh, 3, NULL, 0));
    const trace_world *w = &f.js->world;
    assert_int_equal(w->nobjects, N);
    trace_thread *th = trace_thread_new(w);
    out->rgba = calloc((size_t)W * H * 4, sizeof *out->rgba);
    float *z = calloc((size_t)W * H, sizeof *z);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, W, H, out->rgba, z));
    out->peak_bytes = trace_boxcache_stats_get(th->cache)->peak_bytes;
    out->own_roots = out->shared = 0;
    for (int i = 0; i < N; i++) {
        trace_box kids[4];
        if (trace_boxcache_lookup(th->cache, i, TRACE_BROOD_NONE, 0, kids) != TRACE_BROOD_NONE)
            out->own_roots++;
        if (w->objects[i].box_proto) out->shared++;
    }
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static void test_instances_share_the_prototypes_cache(void **state)
{
    (void)state;
    char *a = scene_rib(true, "bumps", false), *b = scene_rib(false, "bumps", false);
    shot inst, copies;
    render(a, &inst);
    render(b, &copies);
    free(a);
    free(b);
    printf("box cache: %d instances %zu bytes (%d root broods), %d copies %zu bytes "
           "(%d root broods)\n", N, inst.peak_bytes, inst.own_roots, N, copies.peak_bytes,
           copies.own_roots);
    assert_int_equal(inst.shared, N - 1);
    assert_int_equal(copies.shared, 0);
    assert_int_equal(inst.own_roots, 1);
    assert_int_equal(copies.own_roots, N);
    assert_true(inst.peak_bytes > 0);
    assert_true(2 * inst.peak_bytes < copies.peak_bytes);

    /* the same picture: coverage in the same pixels, colours close */
    int alpha_diff = 0, covered = 0;
    double worst = 0, sum = 0;
    for (size_t k = 0; k < (size_t)W * H; k++) {
        float ai = inst.rgba[k * 4 + 3], ac = copies.rgba[k * 4 + 3];
        if (ac > 0) covered++;
        if (fabsf(ai - ac) > 0.3f) alpha_diff++;
        for (int c = 0; c < 4; c++) {
            double d = fabs((double)inst.rgba[k * 4 + c] - copies.rgba[k * 4 + c]);
            worst = fmax(worst, d);
            sum += d;
        }
    }
    double mean = sum / ((double)W * H * 4);
    printf("instances vs copies: %d covered pixels, %d differ in alpha by > 0.3, "
           "mean |diff| %.2e, worst %.3f\n", covered, alpha_diff, mean, worst);
    assert_true(covered > W * H / 5);
    /* at most 1 % of the covered pixels, all on silhouettes: a grazing ray
     * is settled exactly by a hit proof (trace/prove.c) in one walk and by
     * a leaf, which takes a near miss within its tolerance for a hit, in
     * the other (the boxes of the prototype and of a copy differ) */
    assert_true(alpha_diff <= covered / 100);
    assert_true(mean < 2e-3);
    free(inst.rgba);
    free(copies.rgba);
}

static double vmax_abs(vec3 a)
{
    return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

/* boxes from the prototype, points of each instance: 0 violations */
static void test_shared_boxes_contain_every_instance(void **state)
{
    (void)state;
    char *rib = scene_rib(true, "bumps", false);
    fixture f;
    fixture_shader sh[] = {{"bumps", BUMPS_SL}, {"plastic", PLASTIC_SL}};
    assert_true(fixture_open(&f, rib, sh, 2, NULL, 0));
    free(rib);
    const trace_world *w = &f.js->world;
    trace_thread *th = trace_thread_new(w);
    unsigned seed = 12345;
    long points = 0, violations = 0;
    for (int i = 1; i < N; i++) {
        const trace_object *obj = &w->objects[i];
        assert_non_null(obj->box_proto);
        for (int c = 0; c < 300; c++) {
            double side = ldexp(1.0, -(int)(c % 10));
            seed = seed * 1103515245u + 12345u;
            double u0 = (1 - side) * (seed >> 8) / (double)(1u << 24);
            seed = seed * 1103515245u + 12345u;
            double v0 = (1 - side) * (seed >> 8) / (double)(1u << 24);
            trace_box b;
            trace_surface_box(th, obj, u0, u0 + side, v0, v0 + side, &b);
            for (int k = 0; k < 25; k++) {
                double u = u0 + side * (k % 5) / 4.0, v = v0 + side * (k / 5) / 4.0;
                trace_surface_point sp;
                trace_surface_point_eval(th, obj, u, v, &sp);
                vec3 p = mat4_xform_point(&obj->from_camera, sp.P);
                double slack = 8 * DBL_EPSILON * (vmax_abs(sp.P) + vmax_abs(p));
                points++;
                if (p.x < b.lo.x - slack || p.x > b.hi.x + slack || p.y < b.lo.y - slack ||
                    p.y > b.hi.y + slack || p.z < b.lo.z - slack || p.z > b.hi.z + slack)
                    violations++;
            }
        }
    }
    assert_false(th->failed);
    printf("instances: %ld points in shared boxes, %ld violations\n", points, violations);
    assert_int_equal(violations, 0);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* camera-space P, or a scaled instance: each keeps its own boxes */
static void test_fall_back_to_own_boxes(void **state)
{
    (void)state;
    char *a = scene_rib(true, "cambumps", false), *b = scene_rib(true, "bumps", true);
    shot cam, scaled;
    render(a, &cam);
    render(b, &scaled);
    free(a);
    free(b);
    assert_int_equal(cam.shared, 0);
    assert_int_equal(cam.own_roots, N);
    assert_int_equal(scaled.shared, N - 2);        /* all but the stretched one */
    assert_int_equal(scaled.own_roots, 2);
    free(cam.rgba);
    free(scaled.rgba);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_instances_share_the_prototypes_cache),
        cmocka_unit_test(test_shared_boxes_contain_every_instance),
        cmocka_unit_test(test_fall_back_to_own_boxes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_trace_mesh_instances.c: instances of a displaced mesh are
 * references (issue 23; trace/group.h): a placement that moves the
 * prototype rigidly, whose shader moves with it, is the prototype's
 * displaced mesh moved (walked in the prototype's camera space, every box
 * the prototype's); any other placement gets a mesh of its own over the
 * prototype's pieces.
 *
 * A Catmull-Clark cube (24 limit pieces, 8 extraordinary points) bumped
 * by an "object"-space shader, placed N times by ObjectInstance, each
 * moved and turned, against the same cubes written out as N copies:
 *   - the instances are the prototype and one group of N - 1 placements,
 *     all moved: the world holds the prototype's pieces alone, the box
 *     cache far fewer root broods than the copies', and the two images
 *     agree (alpha in the same pixels but for 1 % on silhouettes, colours
 *     close: the placements' hits come from other boxes of the same
 *     surface), with plastic, with a surface of du and dv (a placement's
 *     own), and with the cubes' shadows on a wall (shadow rays);
 *   - points: at random pieces and (u,v) off the probe's grid, each moved
 *     placement's point (the prototype's moved) equals its own shader's
 *     within 1e-9, and lies in the prototype's boxes over random ranges
 *     and in its root box (mapped to object space): 0 violations;
 *   - the fall-backs: a shader of camera-space P, or a placement scaled
 *     against the prototype, gives meshes of their own, whose image is
 *     the copies' to the bit;
 *   - bytes: 2,000 moved placements cost a few hundred bytes each with
 *     the allocator (the mesh's pieces and BVH are held once).
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
#include "trace/group.h"
#include "trace/instance.h"
#include "trace/mesh.h"
#include "trace/render.h"

static const char *BUMPS_SL =
    "displacement bumps(float Km = 0.06)\n"
    "{\n"
    "    point Po = transform(\"object\", P);\n"
    "    P += Km * sin(7 * xcomp(Po)) * sin(6 * ycomp(Po)) * cos(5 * zcomp(Po)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* bumps from camera-space P: not the same surface where the cube moves */
static const char *CAMBUMPS_SL =
    "displacement cambumps(float Km = 0.06)\n"
    "{\n"
    "    P += Km * (2 + xcomp(P)) * (1 + sin(7 * xcomp(P)) * sin(6 * ycomp(P))) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *PLASTIC_SL =
    "surface plastic(float Ka = 1, Kd = 0.6, Ks = 0.4, roughness = 0.1)\n"
    "{\n"
    "    normal Nf = faceforward(normalize(N), I);\n"
    "    Oi = Os;\n"
    "    Ci = Os * Cs * (Ka * ambient() + Kd * diffuse(Nf)) +\n"
    "         Ks * specular(Nf, -normalize(I), roughness);\n"
    "}\n";

/* a surface of the placement's du and dv (its size on the screen) */
static const char *SHOWDU_SL =
    "surface showdu()\n"
    "{\n"
    "    Oi = Os;\n"
    "    Ci = color(5 * du, 5 * dv, 0.5);\n"
    "}\n";

enum { NSHADERS = 4 };

static void shaders(fixture_shader sh[NSHADERS])
{
    sh[0] = (fixture_shader){"bumps", BUMPS_SL};
    sh[1] = (fixture_shader){"cambumps", CAMBUMPS_SL};
    sh[2] = (fixture_shader){"plastic", PLASTIC_SL};
    sh[3] = (fixture_shader){"showdu", SHOWDU_SL};
}

static const char *CUBE =
    "SubdivisionMesh \"catmull-clark\" [4 4 4 4 4 4] "
    "[0 1 3 2 2 3 5 4 4 5 7 6 6 7 1 0 1 7 5 3 6 0 2 4] [] [] [] [] "
    "\"P\" [-0.6 -0.6 0.6  0.6 -0.6 0.6  -0.6 0.6 0.6  0.6 0.6 0.6  -0.6 0.6 -0.6  "
    "0.6 0.6 -0.6  -0.6 -0.6 -0.6  0.6 -0.6 -0.6]";

enum { W = 128, H = 40, N = 4, CUBE_PIECES = 24 };

/* The N placements; `scale`: the first (the prototype) stretched, so no
 * other moves it rigidly */
static const char *surface = "plastic";
static bool shadows;               /* on, with a wall behind the cubes to take them */

static char *scene_rib(bool instanced, const char *shader, bool scale)
{
    size_t cap = 8192;
    char *s = malloc(cap);
    assert_non_null(s);
    size_t len = (size_t)snprintf(s, cap,
        "Format %d %d 1\nPixelSamples 1 1\nProjection \"perspective\" \"fov\" [30]\n"
        "Translate 0 0 6\nWorldBegin\n%s"
        "LightSource \"distantlight\" 1 \"from\" [%s] \"to\" [0 0 0]\n"
        "Surface \"%s\"\n%sDisplacement \"%s\" \"float Km\" [0.06]\n", W, H,
        shadows ? "Attribute \"light\" \"shadows\" [\"on\"]\n" : "",
        shadows ? "-3 1 -1" : "1 1 -2",   /* shadows: long ones, beside the cubes */
        surface, shadows ? "Polygon \"P\" [-8 -3 1.5  8 -3 1.5  8 3 1.5  -8 3 1.5]\n" : "",
        shader);
    if (instanced)
        len += (size_t)snprintf(s + len, cap - len, "ObjectBegin 1\n  %s\nObjectEnd\n", CUBE);
    for (int i = 0; i < N; i++)
        len += (size_t)snprintf(s + len, cap - len,
            "AttributeBegin\n  Translate %g %g 0\n  Rotate %d 0.3 1 0.2\n%s  %s\nAttributeEnd\n",
            -3.3 + 2.2 * i, 0.1 * i, 35 * i + 10, scale && i == 0 ? "  Scale 1 1.3 1\n" : "",
            instanced ? "ObjectInstance 1" : CUBE);
    snprintf(s + len, cap - len, "WorldEnd\n");
    return s;
}

typedef struct shot {
    float *rgba;
    int root_broods;               /* ids with a root brood in the box cache */
    trace_world_counts counts;
} shot;

static void render(const char *rib, shot *out)
{
    fixture f;
    fixture_shader sh[NSHADERS];
    shaders(sh);
    assert_true(fixture_open(&f, rib, sh, NSHADERS, NULL, 0));
    const trace_world *w = &f.js->world;
    trace_thread *th = trace_thread_new(w);
    out->rgba = calloc((size_t)W * H * 4, sizeof *out->rgba);
    float *z = calloc((size_t)W * H, sizeof *z);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, W, H, out->rgba, z));
    out->root_broods = 0;
    for (int i = 0; i < w->nids; i++) {
        trace_box kids[4];
        if (trace_boxcache_lookup(th->cache, i, TRACE_BROOD_NONE, 0, kids) != TRACE_BROOD_NONE)
            out->root_broods++;
    }
    trace_world_count(w, &out->counts);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* the instances' image against the copies', with surface shader `surf`
 * (and shadows: walks that ask only whether) */
static void compare_with_copies(const char *surf, bool with_shadows)
{
    surface = surf;
    shadows = with_shadows;
    char *a = scene_rib(true, "bumps", false), *b = scene_rib(false, "bumps", false);
    surface = "plastic";
    shadows = false;
    shot inst, copies;
    render(a, &inst);
    render(b, &copies);
    free(a);
    free(b);
    printf("%d cubes: instances %ld pieces, %d root broods; copies %ld pieces, %d root broods\n",
           N, inst.counts.pieces, inst.root_broods, copies.counts.pieces, copies.root_broods);
    assert_int_equal(inst.counts.groups, 1);
    assert_int_equal(inst.counts.placements, N - 1);
    assert_int_equal(inst.counts.moved, N - 1);
    assert_int_equal(inst.counts.own, 0);
    assert_int_equal(inst.counts.pieces, CUBE_PIECES);
    assert_int_equal(copies.counts.pieces, N * CUBE_PIECES);
    /* the copies' pieces each have theirs, the placements use the
     * prototype's */
    assert_true(inst.root_broods > 0);
    assert_true(2 * inst.root_broods < copies.root_broods);

    int alpha_diff = 0, covered = 0, colour_diff = 0;
    double worst = 0, sum = 0;
    for (size_t k = 0; k < (size_t)W * H; k++) {
        float ai = inst.rgba[k * 4 + 3], ac = copies.rgba[k * 4 + 3];
        if (ac > 0) covered++;
        if (fabsf(ai - ac) > 0.3f) alpha_diff++;
        double pixel = 0;
        for (int c = 0; c < 4; c++) {
            double d = fabs((double)inst.rgba[k * 4 + c] - copies.rgba[k * 4 + c]);
            worst = fmax(worst, d);
            pixel = fmax(pixel, d);
            sum += d;
        }
        colour_diff += pixel > 0.05;
    }
    double mean = sum / ((double)W * H * 4);
    printf("%s%s: instances vs copies: %d covered pixels, %d differ in alpha by > 0.3, "
           "%d by > 0.05 in a channel, mean |diff| %.2e, worst %.3f\n", surf,
           with_shadows ? " (shadows)" : "", covered, alpha_diff, colour_diff, mean, worst);
    assert_true(covered > W * H / 10);
    assert_true(alpha_diff <= covered / 100);
    assert_true(colour_diff <= covered / 25);
    assert_true(mean < 2e-3);
    free(inst.rgba);
    free(copies.rgba);
}

/* plastic; a surface of du, dv: a moved placement's are its own, not
 * the prototype's (the displacement's are the prototype's); and the cubes'
 * shadows on a wall behind them */
static void test_moved_placements_render_as_copies(void **state)
{
    (void)state;
    compare_with_copies("plastic", false);
    compare_with_copies("showdu", false);
    compare_with_copies("plastic", true);
}

static double vmax_abs(vec3 a)
{
    return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

static unsigned next(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return *seed >> 8;
}

static double uniform(unsigned *seed)
{
    return next(seed) / (double)(1u << 24);
}

static bool outside(vec3 p, const trace_box *b, double slack)
{
    return p.x < b->lo.x - slack || p.x > b->hi.x + slack || p.y < b->lo.y - slack ||
           p.y > b->hi.y + slack || p.z < b->lo.z - slack || p.z > b->hi.z + slack;
}

/* Each moved placement at random pieces and points: its own surface is
 * the prototype's moved, and the prototype's boxes hold it */
static void test_moved_points_are_own_and_contained(void **state)
{
    (void)state;
    char *rib = scene_rib(true, "bumps", false);
    fixture f;
    fixture_shader sh[NSHADERS];
    shaders(sh);
    assert_true(fixture_open(&f, rib, sh, NSHADERS, NULL, 0));
    free(rib);
    const trace_world *w = &f.js->world;
    const trace_object *proto = &w->objects[0], *g = &w->objects[1];
    assert_non_null(proto->mesh);
    assert_non_null(g->group);
    trace_thread *th = trace_thread_new(w);
    trace_view *tv = malloc(4 * sizeof *tv);
    trace_view *place = tv, *own = tv + 1, *pp = tv + 2, *moved = tv + 3;
    unsigned seed = 4321;
    long points = 0, differ = 0, violations = 0;
    double worst = 0;
    for (int i = 0; i < g->group->n; i++) {
        assert_true(trace_group_view_make(th, g, i, place));
        /* a moved placement: the prototype's mesh, its box_proto */
        assert_ptr_equal(place->obj.box_proto, proto);
        assert_ptr_equal(place->obj.mesh, proto->mesh);
        trace_object pobj = place->obj;
        pobj.box_proto = NULL;
        for (int c = 0; c < 40; c++) {
            int k = (int)(next(&seed) % CUBE_PIECES);
            /* the placement's piece by its own shader, the prototype's
             * piece, and the placement's as the prototype's moved */
            assert_true(trace_mesh_view_make(th, &pobj, k, false, own));
            assert_true(trace_mesh_view_make(th, proto, k, true, pp));
            trace_view_copy(moved, own);
            moved->obj.box_proto = &pp->obj;
            trace_instance_set_motion(&moved->obj, &pp->obj);
            double side = ldexp(1.0, -(int)(c % 8));
            double u0 = (1 - side) * uniform(&seed), v0 = (1 - side) * uniform(&seed);
            trace_box b;
            trace_surface_box(th, &moved->obj, u0, u0 + side, v0, v0 + side, &b);
            for (int q = 0; q < 12; q++) {
                double u = u0 + side * uniform(&seed), v = v0 + side * uniform(&seed);
                trace_surface_point a, m;
                trace_surface_point_eval(th, &own->obj, u, v, &a);
                trace_surface_point_eval(th, &moved->obj, u, v, &m);
                double d = vmax_abs(v3_sub(a.P, m.P)) / (1.0 + vmax_abs(a.P));
                worst = fmax(worst, d);
                differ += !(d <= 1e-9) || !(vmax_abs(v3_sub(a.N, m.N)) <= 1e-7);
                vec3 p = mat4_xform_point(&own->obj.from_camera, a.P);
                double slack = 8 * DBL_EPSILON * (vmax_abs(a.P) + vmax_abs(p)) +
                               2e-9 * (1.0 + vmax_abs(a.P));
                points++;
                violations += outside(p, &b, slack) + outside(p, &pp->obj.root, slack) +
                              outside(p, &proto->root, slack);
            }
        }
    }
    assert_false(th->failed);
    printf("moved cube placements: %ld points, %ld differ from their own shader's (worst %.2e), "
           "%ld outside the prototype's boxes\n", points, differ, worst, violations);
    assert_true(points > 0);
    assert_int_equal(differ, 0);
    assert_int_equal(violations, 0);
    free(tv);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* camera-space P, or placements that do not move the prototype rigidly:
 * meshes of their own, the copies' image to the bit */
static void check_own(const char *shader, bool scale)
{
    char *a = scene_rib(true, shader, scale), *b = scene_rib(false, shader, scale);
    shot inst, copies;
    render(a, &inst);
    render(b, &copies);
    free(a);
    free(b);
    assert_int_equal(inst.counts.placements, N - 1);
    assert_int_equal(inst.counts.moved, 0);
    assert_int_equal(inst.counts.own, N - 1);
    assert_int_equal(inst.counts.pieces, N * CUBE_PIECES);
    assert_int_equal(inst.root_broods, copies.root_broods);
    long differ = 0;
    for (size_t k = 0; k < (size_t)W * H * 4; k++) differ += inst.rgba[k] != copies.rgba[k];
    printf("%s%s: %d own placements, %ld values differ from the copies'\n", shader,
           scale ? " (stretched prototype)" : "", (int)inst.counts.own, differ);
    assert_int_equal(differ, 0);
    free(inst.rgba);
    free(copies.rgba);
}

static void test_own_meshes_are_the_copies(void **state)
{
    (void)state;
    check_own("cambumps", false);
    check_own("bumps", true);
}

/* the budget per moved placement of a displaced mesh, everything
 * included (the scene's object, the RIB text, the group's BVH share and
 * per-placement word): as a displaced surface's (test_trace_instances);
 * 351 measured (2026-11-28) */
enum { MESH_INSTANCE_BYTES = 390, MANY = 2001 };

static size_t world_bytes(int n, trace_world_counts *wc)
{
    char def[1024];
    snprintf(def, sizeof def, "Scale 0.5 0.5 0.5\n  %s", CUBE);
    char *rib = fixture_instances_rib(n, def, "bumps", 0.06);
    fixture_shader sh[NSHADERS];
    shaders(sh);
    size_t before = fixture_heap_bytes();
    fixture f;
    assert_true(fixture_open(&f, rib, sh, NSHADERS, NULL, 0));
    size_t after = fixture_heap_bytes();
    trace_world_count(&f.js->world, wc);
    fixture_close(&f);
    free(rib);
    return after - before;
}

static void test_moved_placements_are_references(void **state)
{
    (void)state;
    trace_world_counts one, many;
    size_t b1 = world_bytes(1, &one), bn = world_bytes(MANY, &many);
    double per = ((double)bn - (double)b1) / (MANY - 1);
    printf("%d placements of a displaced cube: %zu bytes held, %zu for one: %.0f bytes per "
           "placement (budget %d); %ld moved, %ld own, %ld pieces\n", MANY, bn, b1, per,
           MESH_INSTANCE_BYTES, many.moved, many.own, many.pieces);
    assert_int_equal(many.placements, MANY - 1);
    assert_int_equal(many.moved, MANY - 1);
    assert_int_equal(many.pieces, CUBE_PIECES);
    if (b1 > 0) assert_true(per <= MESH_INSTANCE_BYTES);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_moved_placements_render_as_copies),
        cmocka_unit_test(test_moved_points_are_own_and_contained),
        cmocka_unit_test(test_own_meshes_are_the_copies),
        cmocka_unit_test(test_moved_placements_are_references),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_corpus_instances.c: displaced instances against the shader corpus
 * (issue 23: instances are references; trace/group.h, trace/instance.c).
 *
 * Every corpus shader displaces a sphere recorded once (ObjectBegin) and
 * placed five times by ObjectInstance: the first is the prototype, an
 * object of its own; the other four are one group, three of them moved
 * and turned rigidly, one scaled. When the world is built the group
 * decides, per placement, whether it is the prototype's displaced surface
 * moved (its boxes the prototype's) or a surface of its own, from a probe
 * of the shader on a 5 x 5 grid of (u,v). This test checks that decision
 * where the probe does not look, and the guarantee either way:
 *   - a placement that is the prototype moved has the surface RenderMan
 *     describes: its own displaced points and normals (the shader run on
 *     the placement itself, box_proto cleared) equal the moved ones at 64
 *     random (u,v) off the probe's grid (P within 1e-9 of the coordinates'
 *     size, unit N within 1e-7, the probe's own tolerances): 0 wrong;
 *   - the scaled placement has its own surface, and the three rigid ones
 *     are decided alike (the probe speaks for the group);
 *   - containment: on random (u,v) ranges the placement's boxes (the
 *     prototype's, or its own) hold its points in its object space, up to
 *     a few ulps: 0 violations.
 * It prints, per shader, how many placements are the prototype moved.
 *
 *   AAFARM_CORPUS_ONLY   comma-separated shader names (default: all)
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

#include "corpus.h"
#include "trace/displace.h"
#include "trace/group.h"
#include "trace/render.h"

enum { PLACED = 4, SCALED = 3, POINTS = 64, RANGES = 40 };

static double vmax_abs(vec3 a)
{
    return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

/* the shader's surface on the prototype and its four placements */
static void world_text(const corpus_file *sh, char *out, size_t cap)
{
    snprintf(out, cap,
             "Displacement \"%s\"\n"
             "ObjectBegin 1\nSphere 0.5 -0.5 0.5 360\nObjectEnd\n"
             "AttributeBegin\nTranslate -1.1 -0.5 5\nRotate 30 1 0 0\nObjectInstance 1\n"
             "AttributeEnd\n"
             "AttributeBegin\nTranslate 0 -0.5 5.5\nRotate 100 0 1 0\nObjectInstance 1\n"
             "AttributeEnd\n"
             "AttributeBegin\nTranslate 1.1 -0.5 5\nRotate 200 1 1 0\nObjectInstance 1\n"
             "AttributeEnd\n"
             "AttributeBegin\nTranslate -0.6 0.6 6\nRotate -70 0 0 1\nObjectInstance 1\n"
             "AttributeEnd\n"
             "AttributeBegin\nTranslate 0.6 0.6 5\nScale 1.2 1.2 1.2\nObjectInstance 1\n"
             "AttributeEnd\n", sh->name);
}

typedef struct tally {
    long points, wrong, boxes_points, violations;
    int moved;
} tally;

/* moved placement v: its own surface against the moved one, off the grid */
static void check_moves(trace_thread *th, const trace_view *v, corpus_rng *rng, tally *t)
{
    trace_view *own = malloc(sizeof *own);
    assert_non_null(own);
    trace_view_copy(own, v);
    own->obj.box_proto = NULL;
    for (int i = 0; i < POINTS; i++) {
        double u = corpus_rng_uniform(rng), w = corpus_rng_uniform(rng);
        if (!geom_uv_inside(&v->obj.surf, u, w)) continue;
        trace_surface_point a, b;
        trace_surface_point_eval(th, &own->obj, u, w, &a);
        trace_surface_point_eval(th, &v->obj, u, w, &b);
        assert_false(th->failed);
        double scale = 1.0 + fmax(vmax_abs(a.P), vmax_abs(b.P));
        t->points++;
        if (!(vmax_abs(v3_sub(a.P, b.P)) <= 1e-9 * scale) || !(vmax_abs(v3_sub(a.N, b.N)) <= 1e-7))
            t->wrong++;
    }
    free(own);
}

/* the placement's boxes hold its points (object space) */
static void check_boxes(trace_thread *th, const trace_object *v, corpus_rng *rng, tally *t)
{
    for (int c = 0; c < RANGES; c++) {
        double side = ldexp(1.0, -(c % 8));
        double u0 = (1 - side) * corpus_rng_uniform(rng), v0 = (1 - side) * corpus_rng_uniform(rng);
        trace_box b;
        trace_surface_box(th, v, u0, u0 + side, v0, v0 + side, &b);
        assert_false(th->failed);
        if (b.flags & AA_UNBOUNDED) continue;
        for (int k = 0; k < 9; k++) {
            double u = u0 + side * (k % 3) / 2.0, w = v0 + side * (k / 3) / 2.0;
            if (!geom_uv_inside(&v->surf, u, w)) continue;
            trace_surface_point sp;
            trace_surface_point_eval(th, v, u, w, &sp);
            vec3 p = mat4_xform_point(&v->from_camera, sp.P);
            if (!isfinite(p.x + p.y + p.z)) continue;
            double slack = 8 * DBL_EPSILON * (vmax_abs(sp.P) + vmax_abs(p));
            t->boxes_points++;
            if (p.x < b.lo.x - slack || p.x > b.hi.x + slack || p.y < b.lo.y - slack ||
                p.y > b.hi.y + slack || p.z < b.lo.z - slack || p.z > b.hi.z + slack)
                t->violations++;
        }
    }
}

static void test_instances_over_the_corpus(void **state)
{
    (void)state;
    corpus c;
    assert_true(corpus_load(&c));
    tally all = {0};
    int shaders = 0, groups_moved = 0;
    for (int s = 0; s < c.nshaders; s++) {
        const corpus_file *sh = &c.shaders[s];
        char world[2048];
        world_text(sh, world, sizeof world);
        fixture f;
        assert_true(corpus_open_world(&f, &c, sh, "instanced sphere", world, TRACE_ARITH_AFFINE,
                                      24, 24, true));
        const trace_world *w = &f.js->world;
        const trace_object *g = NULL;
        for (int i = 0; i < w->nobjects; i++)
            if (w->objects[i].group) g = &w->objects[i];
        assert_non_null(g);
        assert_int_equal(g->group->n, PLACED);
        assert_true(g->group->first_id >= 0);
        trace_thread *th = trace_thread_new(w);
        trace_view *v = malloc(sizeof *v);
        assert_non_null(v);
        corpus_rng rng = {0x9e3779b97f4a7c15ull * (uint64_t)(s + 1)};
        tally t = {0};
        bool rigid_moved[PLACED];
        for (int k = 0; k < PLACED; k++) {
            assert_true(trace_group_view_make(th, g, k, v));
            bool moved = v->obj.box_proto != NULL;
            assert_true(moved == (g->group->own[k] < 0));
            rigid_moved[k] = moved;
            t.moved += moved;
            if (moved) check_moves(th, v, &rng, &t);
            check_boxes(th, &v->obj, &rng, &t);
        }
        printf("%-20s %d of %d placements the prototype moved; %ld points off the probe's "
               "grid, %ld differ; %ld points in boxes, %ld outside\n", sh->name, t.moved,
               PLACED, t.points, t.wrong, t.boxes_points, t.violations);
        /* the scaled one is its own; the rigid ones decided alike */
        assert_false(rigid_moved[SCALED]);
        for (int k = 1; k < SCALED; k++) assert_true(rigid_moved[k] == rigid_moved[0]);
        groups_moved += rigid_moved[0];
        all.points += t.points;
        all.wrong += t.wrong;
        all.boxes_points += t.boxes_points;
        all.violations += t.violations;
        shaders++;
        free(v);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
    printf("corpus instances: %d shaders, %d of them move the prototype; %ld points off the "
           "grid, %ld differ; %ld points in boxes, %ld outside\n", shaders, groups_moved,
           all.points, all.wrong, all.boxes_points, all.violations);
    assert_true(shaders > 0);
    assert_int_equal(all.wrong, 0);
    assert_int_equal(all.violations, 0);
    assert_true(all.boxes_points > 1000L * shaders);
    corpus_free(&c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_instances_over_the_corpus),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

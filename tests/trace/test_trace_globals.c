/*
 * test_trace_globals.c: one meaning of every shader global in every
 * arithmetic (issue 9, common/trace/globals.inc). The regressions of the
 * issue's finding 1: a shader that displaces along the raw N (not
 * normalised) on an ellipsoid (non-uniform Scale), and one that uses du in
 * a filter width, used to displace different surfaces in box and point
 * mode. Here boxes of random (u,v) ranges, from the renderer's own path
 * (trace_surface_box), must contain the points the renderer's hit path
 * (trace_surface_point_eval) gives inside them, in affine and interval
 * arithmetic; and du/dv are per-object constants, the same in every mode.
 * Mesh triangles with vertex normals (issue 14: N interpolated from the
 * corners, geom_vertex_normal) hold the same containment.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "fixture.h"
#include "trace/mesh.h"
#include "trace/displace.h"

static const char *RAWN_SL =
    "displacement rawn(float Km = 0.1)\n"
    "{\n"
    "    float h = sin(s * 12) * cos(t * 9);\n"
    "    P += Km * h * N;\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *DUFILTER_SL =
    "displacement dufilter(float Km = 0.05)\n"
    "{\n"
    "    float fw = 4 * du;\n"
    "    float fv = 4 * dv;\n"
    "    float m = smoothstep(0.5 - fw, 0.5 + fw, s) * smoothstep(0.3 - fv, 0.3 + fv, t);\n"
    "    P += Km * m * normalize(N);\n"
    "}\n";

/* the antialiasing idiom of production shaders: a filter width from Du/Dv
 * and du/dv, a box-filtered pulse, and a normal taken before moving P */
static const char *FILTERED_SL =
    "#define MINFILTWIDTH 1.0e-6\n"
    "#define filterwidth(x) max(abs(Du(x)*du) + abs(Dv(x)*dv), MINFILTWIDTH)\n"
    "#define boxpulse(a, b, x, w) (max(0, min((x) + (w)/2, b) - max((x) - (w)/2, a)) / (w))\n"
    "displacement filtered(float Km = 0.03, freq = 6)\n"
    "{\n"
    "    float ss = s * freq;\n"
    "    float fw = filterwidth(ss);\n"
    "    float m = boxpulse(0.3, 0.7, mod(ss, 1), fw);\n"
    "    normal Nn = normalize(calculatenormal(P));\n"
    "    float bump = noise(P * 3);\n"
    "    float fn = filterwidth(bump);\n"
    "    float oct = 0, amp = 1, sum = 0;\n"
    "    while (oct < 4 && amp * fn < 0.5) {\n"
    "        sum += amp * (noise(P * 3 / amp) - 0.5);\n"
    "        amp *= 0.5;\n"
    "        oct += 1;\n"
    "    }\n"
    "    P += Km * (m + 0.3 * sum + 0.1 * area(P) + 0.01 * Deriv(ss, s)) * Nn;\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* writes du and dv into the displacement, so points show their values */
static const char *DUVALUE_SL =
    "displacement duvalue()\n"
    "{\n"
    "    P += point(du, dv, 0);\n"
    "}\n";

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1p-53;
}

typedef struct tally { long cases, points, violations, unbounded; double worst; } tally;

static void check_ranges(fixture *f, int cases, tally *t)
{
    trace_thread *th = trace_thread_new(&f->js->world);
    /* the first object, or each piece of a mesh in turn */
    const trace_object *first = &f->js->world.objects[0];
    trace_view *view = malloc(sizeof *view);
    for (int c = 0; c < cases; c++) {
        const trace_object *obj =
            trace_object_piece(th, first, c % trace_object_npieces(first), view);
        assert_non_null(obj);
        double w = pow(2.0, -10.0 * rnd()), h = pow(2.0, -10.0 * rnd());
        double u0 = rnd() * (1 - w), v0 = rnd() * (1 - h);
        trace_box b;
        trace_surface_box(th, obj, u0, u0 + w, v0, v0 + h, &b);
        t->cases++;
        if (b.flags & AA_UNBOUNDED) {
            t->unbounded++;
            continue;
        }
        double scale = fmax(fmax(fabs(b.lo.x), fabs(b.hi.x)),
                            fmax(fmax(fabs(b.lo.y), fabs(b.hi.y)), fmax(fabs(b.lo.z), fabs(b.hi.z))));
        double slack = 1e-12 * (1.0 + scale);
        for (int k = 0; k < 9; k++) {
            double u = u0 + w * (k < 4 ? (k & 1) : rnd()), v = v0 + h * (k < 4 ? (k >> 1) : rnd());
            trace_surface_point sp;
            trace_surface_point_eval(th, obj, u, v, &sp);
            vec3 p = mat4_xform_point(&obj->from_camera, sp.P);
            const double *lo = &b.lo.x, *hi = &b.hi.x, *x = &p.x;
            double excess = 0;
            for (int i = 0; i < 3; i++) {
                excess = fmax(excess, lo[i] - slack - x[i]);
                excess = fmax(excess, x[i] - hi[i] - slack);
            }
            t->points++;
            if (excess > 0 || !isfinite(x[0] + x[1] + x[2])) {
                t->violations++;
                if (excess > t->worst) t->worst = excess;
            }
        }
    }
    assert_false(th->failed);
    free(view);
    trace_thread_destroy(&th);
}

static void containment(const char *what, const char *rib, const char *name, const char *src)
{
    for (int a = 0; a < 2; a++) {
        job_options opt;
        job_options_default(&opt);
        opt.arith = a == 0 ? TRACE_ARITH_AFFINE : TRACE_ARITH_INTERVAL;
        fixture f;
        fixture_shader sh[] = {{name, src}};
        assert_true(fixture_open(&f, rib, sh, 1, &opt, 0));
        tally t = {0};
        check_ranges(&f, 1000, &t);
        printf("%-28s %-8s cases %ld points %ld violations %ld (worst %.2e) unbounded %ld\n",
               what, trace_arith_name(opt.arith), t.cases, t.points, t.violations, t.worst,
               t.unbounded);
        assert_int_equal(t.violations, 0);
        assert_int_equal(t.unbounded, 0);
        fixture_close(&f);
    }
}

#define SCENE(shader, xform, prim)                                      \
    "Format 64 48 1\nProjection \"perspective\" \"fov\" [40]\n"         \
    "WorldBegin\nTranslate 0 0 6\n" xform "\n"                          \
    "Displacement \"" shader "\"\n" prim "\nWorldEnd\n"

static void test_raw_n_on_an_ellipsoid(void **state)
{
    (void)state;
    containment("raw N, ellipsoid", SCENE("rawn", "Rotate 30 1 1 0 Scale 1 0.5 2",
                                          "Sphere 1 -1 1 360"), "rawn", RAWN_SL);
    containment("raw N, sphere", SCENE("rawn", "Rotate 30 1 1 0 Scale 1.5 1.5 1.5",
                                       "Sphere 1 -1 1 360"), "rawn", RAWN_SL);
}

static void test_du_in_a_filter_width(void **state)
{
    (void)state;
    containment("du filter, plane", SCENE("dufilter", "",
                "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]"), "dufilter", DUFILTER_SL);
    containment("du filter, ellipsoid", SCENE("dufilter", "Scale 1 0.5 2",
                "Sphere 1 -1 1 360"), "dufilter", DUFILTER_SL);
}

/* Issue 9 finding 2: filter widths from Du/Dv, normalize(calculatenormal(P))
 * before moving P, noise-driven octave loops: bounded boxes that contain
 * the surface (derivative bounds, common/sl/vm_deriv.inc). */
static void test_filterwidth_idioms(void **state)
{
    (void)state;
    containment("filterwidth, plane", SCENE("filtered", "",
                "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]"), "filtered", FILTERED_SL);
    containment("filterwidth, sphere", SCENE("filtered", "", "Sphere 1 -1 1 360"),
                "filtered", FILTERED_SL);
    containment("filterwidth, ellipsoid", SCENE("filtered", "Rotate 20 0 1 1 Scale 1 0.5 2",
                "Sphere 1 -1 1 360"), "filtered", FILTERED_SL);
    containment("filterwidth, patch", SCENE("filtered", "",
                "Patch \"bilinear\" \"P\" [-1 -1 0  1 -1 0.3  -1 1 0.2  1 1 -0.4]"),
                "filtered", FILTERED_SL);
}

/* A mesh triangle whose corners carry different normals: the shader's N
 * is their interpolation in every mode (box and point agree). */
#define VN_TRIANGLE "PointsPolygons [3] [0 1 2] \"P\" [-1 -1 0  1 -1 0.3  0 1 -0.2]\n" \
    "  \"N\" [0.3 0 1  0 0.3 1  -0.2 -0.2 1]"

static void test_vertex_normals_on_a_mesh(void **state)
{
    (void)state;
    containment("raw N, vertex normals", SCENE("rawn", "Rotate 30 1 1 0 Scale 1 0.5 2",
                VN_TRIANGLE), "rawn", RAWN_SL);
    containment("filterwidth, vertex normals", SCENE("filtered", "Rotate 20 0 1 1",
                VN_TRIANGLE), "filtered", FILTERED_SL);
}

/* du and dv: what the shader sees equals the object's constants, in a box
 * (a point range) and at a point, and they follow the projected size. */
static void test_du_dv_are_per_object_constants(void **state)
{
    (void)state;
    const char *rib =
        "Format 64 48 1\nProjection \"perspective\" \"fov\" [40]\nShadingRate 4\n"
        "WorldBegin\nTranslate 0 0 6\nDisplacement \"duvalue\"\n"
        "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\n"
        "Translate 0 0 6\n"
        "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\nWorldEnd\n";
    fixture f;
    fixture_shader sh[] = {{"duvalue", DUVALUE_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_object *near = &f.js->world.objects[0], *far = &f.js->world.objects[1];
    /* the far square projects to half the size: twice the spacing */
    assert_true(fabs(far->du / near->du - 2.0) < 1e-6);
    assert_true(fabs(far->dv / near->dv - 2.0) < 1e-6);
    /* the screen window is [-4/3, 4/3] x [-1, 1] at distance 1 / tan(20 deg):
     * the near square (2 units at z = 6) spans 2/6 / (8/3/64 tan 20deg)
     * pixels; du = sqrt(ShadingRate 4) / that */
    double span = (2.0 / 6.0) / ((8.0 / 3.0) / 64.0 * tan(20 * M_PI / 180));
    printf("near square: %.3f px, du %.6f dv %.6f\n", span, near->du, near->dv);
    assert_true(fabs(near->du - 2.0 / span) < 1e-9);
    for (int i = 0; i < 2; i++) {
        const trace_object *obj = &f.js->world.objects[i];
        trace_surface_point sp;
        trace_surface_point_eval(th, obj, 0.3, 0.7, &sp);
        geom_sample g;
        geom_eval(&obj->surf, 0.3, 0.7, &g);
        vec3 base = mat4_xform_point(&obj->to_camera, g.P);
        assert_true(fabs(sp.P.x - base.x - obj->du) < 1e-12);
        assert_true(fabs(sp.P.y - base.y - obj->dv) < 1e-12);
    }
    trace_thread_destroy(&th);
    fixture_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_raw_n_on_an_ellipsoid),
        cmocka_unit_test(test_du_in_a_filter_width),
        cmocka_unit_test(test_filterwidth_idioms),
        cmocka_unit_test(test_vertex_normals_on_a_mesh),
        cmocka_unit_test(test_du_dv_are_per_object_constants),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

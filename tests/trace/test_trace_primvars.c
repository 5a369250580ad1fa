/*
 * test_trace_primvars.c: primitive variables of every class handed to
 * shaders (RI Spec 3.2 §5.1; common/scene/rib_primvar.c, trace/primvar.c).
 *
 * A square [-0.8, 0.8]^2 at world z = 0, seen face on by an orthographic
 * camera from z = -5 (x right, y up), RES x RES pixels over [-1, 1]^2:
 *   - Cs of each class through the default surface to the image: constant
 *     (every pixel), uniform (one colour per face), vertex and varying
 *     (a colour linear in x and y: every interior pixel shows the
 *     function at its centre, whatever the triangles; on a Polygon too),
 *     facevarying (the two faces differ along their shared edge);
 *   - "st" (facevarying), and "s" alone, through a surface shader that
 *     shows them as its colour;
 *   - a bicubic patch's vertex-class Cs, interpolated with the basis (a
 *     quadratic in u that its corners alone cannot give);
 *   - a subdivision mesh: varying Cs linear in the control points' x, y
 *     (the flat, evenly spaced mesh's limit surface shows that function),
 *     uniform Cs per control face;
 *   - a user variable ("vertex float height") read by a displacement
 *     shader's parameter of that name: the depth image follows it; the
 *     same on a bilinear Patch ("varying float height", 4 values);
 *   - containment: boxes of the displacement by a primitive variable over
 *     random (u,v) ranges, affine and interval, on a mesh, a bilinear
 *     patch, a subdivision mesh and a b-spline patch (vertex class,
 *     bicubic), hold the points: 0 violations.
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
#include "trace/mesh.h"
#include "trace/displace.h"
#include "trace/render.h"

enum { RES = 40 };

static const char *LIFT_SL =
    "displacement lift(float height = 0)\n"
    "{\n"
    "    P += height * height * 4 * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *SHOWST_SL =
    "surface showst()\n"
    "{\n"
    "    Oi = 1;\n"
    "    Ci = color(s, t, 0.5);\n"
    "}\n";

#define CAMERA "Format 40 40 1\nPixelSamples 2 2\nPixelFilter \"box\" 1 1\n" \
               "Projection \"orthographic\"\nScreenWindow -1 1 -1 1\nTranslate 0 0 5\n" \
               "WorldBegin\n"

typedef struct image { float rgba[RES * RES * 4], z[RES * RES]; } image;

static void render(const char *rib, image *im)
{
    fixture f;
    fixture_shader sh[] = {{"lift", LIFT_SL}, {"showst", SHOWST_SL}};
    assert_true(fixture_open(&f, rib, sh, 2, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, RES, RES, im->rgba, im->z));
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* world x, y of a pixel's centre */
static double wx(int x) { return -1 + (x + 0.5) * 2.0 / RES; }
static double wy(int y) { return 1 - (y + 0.5) * 2.0 / RES; }

/* pixels whose footprint lies inside the square by a margin */
static bool interior(int x, int y)
{
    return fabs(wx(x)) < 0.7 && fabs(wy(y)) < 0.7;
}

typedef void (*expect_fn)(double x, double y, double rgb[3]);

/* every interior pixel's colour against expect within tol; returns the
 * worst difference */
static double worst_colour(const image *im, expect_fn expect, double tol)
{
    double worst = 0;
    int n = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            if (!interior(x, y)) continue;
            double e[3];
            expect(wx(x), wy(y), e);
            const float *px = &im->rgba[((size_t)y * RES + x) * 4];
            assert_true(px[3] == 1.0f);
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(px[k] - e[k]));
            n++;
        }
    assert_true(n > 300);
    assert_true(worst <= tol);
    return worst;
}

/* the default surface face on: Cs (Os 1) */
static void lin(double x, double y, double rgb[3])
{
    rgb[0] = 0.5 + 0.5 * x;
    rgb[1] = 0.5 + 0.5 * y;
    rgb[2] = 0.25;
}

static const char *QUAD2 =      /* two faces sharing the edge x = 0 */
    "PointsPolygons [4 4] [0 1 4 3  1 2 5 4]\n"
    "  \"P\" [-0.8 -0.8 0  0 -0.8 0  0.8 -0.8 0  -0.8 0.8 0  0 0.8 0  0.8 0.8 0]\n";

static void test_cs_constant_and_uniform(void **state)
{
    (void)state;
    static image im;
    char rib[2048];
    snprintf(rib, sizeof rib, CAMERA "%s  \"constant color Cs\" [0.2 0.4 0.6]\nWorldEnd\n", QUAD2);
    render(rib, &im);
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++)
            if (interior(x, y)) {
                const float *px = &im.rgba[((size_t)y * RES + x) * 4];
                assert_true(fabs(px[0] - 0.2) < 1e-3 && fabs(px[1] - 0.4) < 1e-3 &&
                            fabs(px[2] - 0.6) < 1e-3);
            }
    /* uniform: one colour per face (told by the count: two faces) */
    snprintf(rib, sizeof rib, CAMERA "%s  \"Cs\" [1 0 0  0 0 1]\nWorldEnd\n", QUAD2);
    render(rib, &im);
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++)
            if (interior(x, y) && fabs(wx(x)) > 0.1) {
                const float *px = &im.rgba[((size_t)y * RES + x) * 4];
                bool left = wx(x) < 0;
                assert_true(fabs(px[0] - (left ? 1 : 0)) < 1e-3 && fabs(px[2] - (left ? 0 : 1)) < 1e-3);
            }
}

/* Cs at the six points of QUAD2 from lin() */
static void lin_values(char *out, size_t size)
{
    static const double P[6][2] = {{-0.8, -0.8}, {0, -0.8}, {0.8, -0.8},
                                   {-0.8, 0.8}, {0, 0.8}, {0.8, 0.8}};
    size_t n = 0;
    for (int i = 0; i < 6; i++) {
        double c[3];
        lin(P[i][0], P[i][1], c);
        n += (size_t)snprintf(out + n, size - n, "%.17g %.17g %.17g ", c[0], c[1], c[2]);
    }
}

static void test_cs_vertex_and_varying(void **state)
{
    (void)state;
    static image im;
    char rib[4096], vals[512];
    lin_values(vals, sizeof vals);
    const char *decl[] = {"vertex color Cs", "varying color Cs", "Cs"};
    for (int i = 0; i < 3; i++) {
        snprintf(rib, sizeof rib, CAMERA "%s  \"%s\" [%s]\nWorldEnd\n", QUAD2, decl[i], vals);
        render(rib, &im);
        /* jittered samples of a linear function: within its change over half a pixel */
        double w = worst_colour(&im, lin, 0.5 * 2.0 / RES);
        printf("Cs \"%s\": worst |pixel - Cs(centre)| %.4f\n", decl[i], w);
    }
    /* a Polygon (one face of four corners) the same */
    double c[4][3];
    lin(-0.8, -0.8, c[0]), lin(0.8, -0.8, c[1]), lin(0.8, 0.8, c[2]), lin(-0.8, 0.8, c[3]);
    snprintf(rib, sizeof rib, CAMERA "Polygon \"P\" [-0.8 -0.8 0  0.8 -0.8 0  0.8 0.8 0  -0.8 0.8 0] "
             "\"varying color Cs\" [%g %g %g  %g %g %g  %g %g %g  %g %g %g]\nWorldEnd\n",
             c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2],
             c[3][0], c[3][1], c[3][2]);
    render(rib, &im);
    printf("Polygon, varying Cs: worst %.4f\n", worst_colour(&im, lin, 0.5 * 2.0 / RES));
}

static void test_cs_facevarying(void **state)
{
    (void)state;
    static image im;
    /* the left face's corners red, the right face's blue, also at the two
     * points they share */
    char rib[2048];
    snprintf(rib, sizeof rib, CAMERA "%s  \"facevarying color Cs\" [1 0 0  1 0 0  1 0 0  "
             "1 0 0  0 0 1  0 0 1  0 0 1  0 0 1]\nWorldEnd\n", QUAD2);
    render(rib, &im);
    int red = 0, blue = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++)
            if (interior(x, y) && fabs(wx(x)) > 0.1) {
                const float *px = &im.rgba[((size_t)y * RES + x) * 4];
                bool left = wx(x) < 0;
                assert_true(fabs(px[0] - (left ? 1 : 0)) < 1e-3 && fabs(px[2] - (left ? 0 : 1)) < 1e-3);
                red += left;
                blue += !left;
            }
    assert_true(red > 100 && blue > 100);
}

static void st_expect(double x, double y, double rgb[3])
{
    rgb[0] = (x + 0.8) / 1.6;        /* s = 0 at the left, 1 at the right */
    rgb[1] = (0.8 - y) / 1.6;        /* t = 0 at the top */
    rgb[2] = 0.5;
}

static void test_st_and_s(void **state)
{
    (void)state;
    static image im;
    char rib[2048];
    /* facevarying st: per face corner, in each face's corner order */
    snprintf(rib, sizeof rib, CAMERA "Surface \"showst\"\n%s  \"facevarying float[2] st\" "
             "[0 1  0.5 1  0.5 0  0 0   0.5 1  1 1  1 0  0.5 0]\nWorldEnd\n", QUAD2);
    render(rib, &im);
    double w = worst_colour(&im, st_expect, 0.5 * 2.0 / RES / 1.6 * 1.01);
    printf("st (facevarying): worst %.4f\n", w);
    /* s alone (vertex), t stays the surface's v: only the red channel checked */
    snprintf(rib, sizeof rib, CAMERA "Surface \"showst\"\n%s  \"s\" [0 0.5 1  0 0.5 1]\nWorldEnd\n",
             QUAD2);
    render(rib, &im);
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++)
            if (interior(x, y)) {
                double e[3];
                st_expect(wx(x), wy(y), e);
                assert_true(fabs(im.rgba[((size_t)y * RES + x) * 4] - e[0]) <= 0.5 * 2.0 / RES / 1.6 * 1.01);
            }
}

/* a flat 3 x 3-face subdivision mesh over the square (evenly spaced, so
 * its limit surface is the square, linear in each refined face's (u,v)) */
static void subdiv_rib(char *rib, size_t size, const char *pre, const char *var)
{
    size_t n = (size_t)snprintf(rib, size, CAMERA "%sSubdivisionMesh \"catmull-clark\" "
                                "[4 4 4 4 4 4 4 4 4] [", pre);
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            n += (size_t)snprintf(rib + n, size - n, "%d %d %d %d  ", 4 * j + i, 4 * j + i + 1,
                                  4 * (j + 1) + i + 1, 4 * (j + 1) + i);
    n += (size_t)snprintf(rib + n, size - n, "] [\"interpolateboundary\"] [0 0] [] [] \"P\" [");
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            n += (size_t)snprintf(rib + n, size - n, "%g %g 0  ", -0.8 + 1.6 * i / 3,
                                  -0.8 + 1.6 * j / 3);
    snprintf(rib + n, size - n, "] %s\nWorldEnd\n", var);
}

static void test_subdivision_mesh(void **state)
{
    (void)state;
    static image im;
    static char rib[8192];
    char vals[2048];
    size_t n = 0;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            double c[3];
            lin(-0.8 + 1.6 * i / 3, -0.8 + 1.6 * j / 3, c);
            n += (size_t)snprintf(vals + n, sizeof vals - n, "%.17g %.17g %.17g ", c[0], c[1], c[2]);
        }
    char var[2200];
    snprintf(var, sizeof var, "\"varying color Cs\" [%s]", vals);
    subdiv_rib(rib, sizeof rib, "", var);
    render(rib, &im);
    double w = worst_colour(&im, lin, 0.5 * 2.0 / RES + 1e-3);
    printf("subdivision mesh, varying Cs: worst %.4f\n", w);
    /* uniform: one colour per control face (the middle column red) */
    char uni[1024];
    n = (size_t)snprintf(uni, sizeof uni, "\"uniform color Cs\" [");
    for (int f = 0; f < 9; f++)
        n += (size_t)snprintf(uni + n, sizeof uni - n, "%s", f % 3 == 1 ? "1 0 0 " : "0 0 1 ");
    snprintf(uni + n, sizeof uni - n, "]");
    subdiv_rib(rib, sizeof rib, "", uni);
    render(rib, &im);
    int red = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            if (!interior(x, y) || fabs(fabs(wx(x)) - 0.8 / 3) < 0.12) continue;
            const float *px = &im.rgba[((size_t)y * RES + x) * 4];
            bool middle = fabs(wx(x)) < 0.8 / 3;
            assert_true(fabs(px[0] - (middle ? 1 : 0)) < 1e-3 && fabs(px[2] - (middle ? 0 : 1)) < 1e-3);
            red += middle;
        }
    assert_true(red > 50);
}

/* the depth of a displacement by a user variable: |z - 5| = 4 h^2, with h
 * linear in x (vertex class on the mesh, varying on a bilinear patch) */
static double height_at(double x) { return 0.1 * (x + 0.8) / 1.6; }

static void check_lift(const image *im, const char *what)
{
    double worst = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            if (!interior(x, y)) continue;
            double h = height_at(wx(x));
            worst = fmax(worst, fabs(fabs(im->z[(size_t)y * RES + x] - 5.0) - 4 * h * h));
        }
    printf("%s: worst |depth - 4 h^2| %.5f\n", what, worst);
    /* 4 h^2 changes by at most 0.8 h' per unit x over half a pixel, plus
     * the hit tolerance */
    assert_true(worst < 0.01);
}

/* a flat Bezier patch over the square (evenly spaced control points: P is
 * linear in u, v); vertex-class Cs.r with the Bernstein coefficients of
 * u^2 (0, 0, 1/3, 1 along u) shows u^2, which a bilinear reading of the
 * corners (u) would not */
static void bezier_expect(double x, double y, double rgb[3])
{
    double u = (x + 0.8) / 1.6;
    rgb[0] = u * u;
    rgb[1] = 0.5 + 0.5 * y;
    rgb[2] = 0.25;
}

static void test_bicubic_vertex_class(void **state)
{
    (void)state;
    static image im;
    static char rib[8192];
    size_t n = (size_t)snprintf(rib, sizeof rib, CAMERA "Patch \"bicubic\" \"P\" [");
    for (int l = 0; l < 4; l++)
        for (int k = 0; k < 4; k++)
            n += (size_t)snprintf(rib + n, sizeof rib - n, "%.17g %.17g 0  ", -0.8 + 1.6 * k / 3,
                                  -0.8 + 1.6 * l / 3);
    n += (size_t)snprintf(rib + n, sizeof rib - n, "] \"vertex color Cs\" [");
    static const double bern[4] = {0, 0, 1 / 3.0, 1};
    for (int l = 0; l < 4; l++)
        for (int k = 0; k < 4; k++)
            n += (size_t)snprintf(rib + n, sizeof rib - n, "%.17g %.17g 0.25  ", bern[k],
                                  0.5 + 0.5 * (-0.8 + 1.6 * l / 3));
    snprintf(rib + n, sizeof rib - n, "]\nWorldEnd\n");
    render(rib, &im);
    /* u^2 changes by at most 2 * (half a pixel) / 1.6 per half pixel */
    double w = worst_colour(&im, bezier_expect, 2.0 / RES / 1.6 + 1e-3);
    printf("bicubic Patch, vertex Cs: worst %.4f\n", w);
}

static void test_user_variable_displaces(void **state)
{
    (void)state;
    static image im;
    char rib[2048];
    snprintf(rib, sizeof rib, CAMERA "Displacement \"lift\"\n%s  \"vertex float height\" "
             "[0 0.05 0.1  0 0.05 0.1]\nWorldEnd\n", QUAD2);
    render(rib, &im);
    check_lift(&im, "PointsPolygons, vertex float height");
    /* a bilinear patch: corners P00 P10 P01 P11, varying: one per corner */
    snprintf(rib, sizeof rib, CAMERA "Displacement \"lift\"\nPatch \"bilinear\" \"P\" "
             "[-0.8 -0.8 0  0.8 -0.8 0  -0.8 0.8 0  0.8 0.8 0] \"varying float height\" "
             "[0 0.1 0 0.1]\nWorldEnd\n");
    render(rib, &im);
    check_lift(&im, "Patch bilinear, varying float height");
}

static double vmax_abs(vec3 a)
{
    return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

/* boxes of the primitive-variable displacement hold its points */
static void test_containment(void **state)
{
    (void)state;
    static char sub[8192];
    subdiv_rib(sub, sizeof sub, "Displacement \"lift\"\n", "\"varying float height\" "
               "[0 0.1 0.2 0.3  0.1 0.3 -0.2 0  0 0 0.2 0.1  -0.1 0 0.1 0.2]");
    const char *ribs[] = {
        CAMERA "Displacement \"lift\"\nPointsPolygons [4] [0 1 2 3] \"P\" [-0.8 -0.8 0  0.8 -0.8 0  "
        "0.8 0.8 0.3  -0.8 0.8 0] \"vertex float height\" [0 0.3 -0.2 0.1]\nWorldEnd\n",
        CAMERA "Displacement \"lift\"\nPatch \"bilinear\" \"P\" [-0.8 -0.8 0  0.8 -0.8 0.2  "
        "-0.8 0.8 0  0.8 0.8 0] \"varying float height\" [0 0.3 -0.2 0.1]\nWorldEnd\n",
        sub,
        CAMERA "Displacement \"lift\"\nBasis \"b-spline\" 1 \"b-spline\" 1\nPatch \"bicubic\" "
        "\"P\" [-1 -1 0  -0.3 -1 0.2  0.3 -1 0  1 -1 0.1  -1 -0.3 0  -0.3 -0.3 0.4  0.3 -0.3 0  "
        "1 -0.3 0  -1 0.3 0.2  -0.3 0.3 0  0.3 0.3 -0.3  1 0.3 0  -1 1 0  -0.3 1 0  0.3 1 0.2  "
        "1 1 0] \"vertex float height\" [0 0.1 0.2 0.3  0.1 0.3 -0.2 0  0 0 0.2 0.1  -0.1 0 0.1 "
        "0.2]\nWorldEnd\n",
    };
    for (int r = 0; r < 4; r++)
        for (int arith = 0; arith < 2; arith++) {
            job_options opt;
            job_options_default(&opt);
            opt.arith = arith ? TRACE_ARITH_INTERVAL : TRACE_ARITH_AFFINE;
            fixture f;
            fixture_shader sh[] = {{"lift", LIFT_SL}};
            assert_true(fixture_open(&f, ribs[r], sh, 1, &opt, 0));
            const trace_world *w = &f.js->world;
            trace_thread *th = trace_thread_new(w);
            unsigned seed = 777;
            long points = 0, violations = 0;
            double spread = 0;
            trace_view *view = malloc(sizeof *view);
            for (int o = 0; o < w->nobjects; o++)
              for (int pc = 0; pc < trace_object_npieces(&w->objects[o]); pc++) {
                const trace_object *obj = trace_object_piece(th, &w->objects[o], pc, view);
                assert_non_null(obj);
                assert_int_equal(obj->nprimvars, 1);
                for (int c = 0; c < 400; c++) {
                    double side = ldexp(1.0, -(int)(c % 12));
                    seed = seed * 1103515245u + 12345u;
                    double u0 = (1 - side) * (seed >> 8) / (double)(1u << 24);
                    seed = seed * 1103515245u + 12345u;
                    double v0 = (1 - side) * (seed >> 8) / (double)(1u << 24);
                    trace_box b;
                    trace_surface_box(th, obj, u0, u0 + side, v0, v0 + side, &b);
                    for (int k = 0; k < 25; k++) {
                        double u = u0 + side * (k % 5) / 4.0, v = v0 + side * (k / 5) / 4.0;
                        if (!geom_uv_inside(&obj->surf, u, v)) continue;
                        trace_surface_point sp;
                        trace_surface_point_eval(th, obj, u, v, &sp);
                        vec3 p = mat4_xform_point(&obj->from_camera, sp.P);
                        double slack = 8 * DBL_EPSILON * (vmax_abs(sp.P) + vmax_abs(p));
                        points++;
                        spread = fmax(spread, fabs(p.z));
                        if (p.x < b.lo.x - slack || p.x > b.hi.x + slack || p.y < b.lo.y - slack ||
                            p.y > b.hi.y + slack || p.z < b.lo.z - slack || p.z > b.hi.z + slack)
                            violations++;
                    }
                }
            }
            free(view);
            assert_false(th->failed);
            printf("%s, %s: %ld points, %ld violations\n",
                   r == 0 ? "mesh" : r == 1 ? "patch" : r == 2 ? "subdivision mesh"
                                                             : "bicubic b-spline patch",
                   arith ? "interval" : "affine", points, violations);
            assert_true(points > 1000);
            assert_true(spread > 0.05);     /* the variable did displace */
            assert_int_equal(violations, 0);
            trace_thread_destroy(&th);
            fixture_close(&f);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cs_constant_and_uniform),
        cmocka_unit_test(test_cs_vertex_and_varying),
        cmocka_unit_test(test_cs_facevarying),
        cmocka_unit_test(test_st_and_s),
        cmocka_unit_test(test_subdivision_mesh),
        cmocka_unit_test(test_bicubic_vertex_class),
        cmocka_unit_test(test_user_variable_displaces),
        cmocka_unit_test(test_containment),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_trace_pinholes.c: closed displaced objects render without pinholes
 * (issue 14): a pixel that is not opaque although its eight neighbours are
 * (pinholes.h) is a ray that slipped through the surface. Two closed
 * objects, displaced by a shader that is continuous across faces (noise of
 * the world position, along normalize(N)), rendered small in affine
 * arithmetic (and the subdivision surface in interval arithmetic too):
 *
 * - a Catmull-Clark box (SubdivisionMesh, 24 quads, 8 extraordinary points
 *   of valence 3, an infinitely sharp crease around the top, a semi-sharp
 *   vertical edge, a corner tag): 0 pinholes;
 * - a torus of 64 x 32 shared-point quads (PointsPolygons, 2048 faces,
 *   vertex normals): 0 pinholes.
 *
 * The count itself is checked on small synthetic images first.
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
#include "pinholes.h"
#include "trace/render.h"

static const char *BUMPY_SL =
    "displacement bumpy(float Km = 0)\n"
    "{\n"
    "    P += Km * (noise(3 * transform(\"world\", P)) - 0.5) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

enum { RES = 64 };

static void test_count(void **state)
{
    (void)state;
    enum { W = 8, H = 6 };
    float img[W * H * 4];
    for (int i = 0; i < W * H; i++) img[4 * i + 3] = 1.0f;
    assert_int_equal(count_pinholes(img, W, H), 0);
    img[4 * (2 * W + 3) + 3] = 0.5f;            /* an isolated hole */
    assert_int_equal(count_pinholes(img, W, H), 1);
    img[4 * (2 * W + 4) + 3] = 0.0f;            /* now two side by side: */
    assert_int_equal(count_pinholes(img, W, H), 0);   /* a crack, not a pinhole */
    img[4 * (2 * W + 3) + 3] = img[4 * (2 * W + 4) + 3] = 1.0f;
    img[4 * (0 * W + 3) + 3] = 0.0f;            /* on the border: no neighbours */
    assert_int_equal(count_pinholes(img, W, H), 0);
    assert_int_equal(count_opaque(img, W, H), W * H - 1);
}

static int render_pinholes(const char *rib, trace_arith arith, const char *what)
{
    fixture f;
    fixture_shader sh[] = {{"bumpy", BUMPY_SL}};
    job_options opt;
    job_options_default(&opt);
    opt.arith = arith;
    assert_true(fixture_open(&f, rib, sh, 1, &opt, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    float *rgba = calloc((size_t)RES * RES * 4, sizeof *rgba);
    float *z = calloc((size_t)RES * RES, sizeof *z);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, RES, RES, rgba, z));
    int holes = count_pinholes(rgba, RES, RES), opaque = count_opaque(rgba, RES, RES);
    printf("%s (%s): %d opaque pixels, %d pinholes\n", what,
           arith == TRACE_ARITH_AFFINE ? "affine" : "interval", opaque, holes);
    assert_true(opaque > RES * RES / 5);      /* the object fills the image */
    free(rgba);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
    return holes;
}

static const char *HEAD =
    "Format %d %d 1\nPixelSamples 2 2\nProjection \"perspective\" \"fov\" [40]\n"
    "Translate 0 0 %g\nRotate -50 1 0 0\nRotate 30 0 0 1\nWorldBegin\n"
    "Attribute \"displacementbound\" \"sphere\" [%g]\n"
    "Displacement \"bumpy\" \"float Km\" [%g]\n";

static void test_subdivision_box(void **state)
{
    (void)state;
    char rib[8192];
    int n = snprintf(rib, sizeof rib, HEAD, RES, RES, 4.5, 0.08, 0.15);
    snprintf(rib + n, sizeof rib - (size_t)n,
        "SubdivisionMesh \"catmull-clark\" [4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4]\n"
        "  [0 1 2 3  3 2 4 5  1 6 7 2  2 7 8 4  12 11 10 9  14 13 11 12  11 16 15 10  "
        "13 17 16 11  15 16 18 19  19 18 7 6  16 17 20 18  18 20 8 7  22 21 12 9  "
        "0 3 21 22  21 23 14 12  3 5 23 21  14 23 24 13  13 24 20 17  23 5 4 24  "
        "24 4 8 20  10 25 22 9  15 19 25 10  25 1 0 22  19 6 1 25]\n"
        "  [\"crease\" \"crease\" \"corner\"] [9 1 3 1 1 1]\n"
        "  [14 23 5 4 8 20 17 13 14  6 7 8  9] [10 2.5 10]\n"
        "  \"P\" [1 -1 -1  1 0 -1  1 0 0  1 -1 0  1 0 1  1 -1 1  1 1 -1  1 1 0  1 1 1  "
        "-1 -1 -1  -1 0 -1  -1 0 0  -1 -1 0  -1 0 1  -1 -1 1  -1 1 -1  -1 1 0  -1 1 1  "
        "0 1 0  0 1 -1  0 1 1  0 -1 0  0 -1 -1  0 -1 1  0 0 1  0 0 -1]\n"
        "WorldEnd\n");
    assert_int_equal(render_pinholes(rib, TRACE_ARITH_AFFINE, "subdivision box"), 0);
    assert_int_equal(render_pinholes(rib, TRACE_ARITH_INTERVAL, "subdivision box"), 0);
}

enum { TU = 64, TV = 32 };

static void test_closed_mesh(void **state)
{
    (void)state;
    size_t cap = 400000, len = 0;
    char *rib = malloc(cap);
    assert_non_null(rib);
    len += (size_t)snprintf(rib, cap, HEAD, RES, RES, 4.0, 0.05, 0.1);
    len += (size_t)snprintf(rib + len, cap - len, "PointsPolygons [");
    for (int i = 0; i < TU * TV; i++) len += (size_t)snprintf(rib + len, cap - len, " 4");
    len += (size_t)snprintf(rib + len, cap - len, "]\n[");
    for (int j = 0; j < TV; j++)
        for (int i = 0; i < TU; i++) {
            int i1 = (i + 1) % TU, j1 = (j + 1) % TV;
            len += (size_t)snprintf(rib + len, cap - len, " %d %d %d %d", j * TU + i,
                                    j * TU + i1, j1 * TU + i1, j1 * TU + i);
        }
    len += (size_t)snprintf(rib + len, cap - len, "]\n\"P\" [");
    for (int j = 0; j < TV; j++)
        for (int i = 0; i < TU; i++) {
            double a = 2 * M_PI * i / TU, b = 2 * M_PI * j / TV;
            double rho = 1 + 0.4 * cos(b);
            len += (size_t)snprintf(rib + len, cap - len, " %.9g %.9g %.9g", rho * cos(a),
                                    rho * sin(a), 0.4 * sin(b));
        }
    snprintf(rib + len, cap - len, "]\nWorldEnd\n");
    assert_int_equal(render_pinholes(rib, TRACE_ARITH_AFFINE, "torus mesh, 2048 quads"), 0);
    free(rib);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_count),
        cmocka_unit_test(test_subdivision_box),
        cmocka_unit_test(test_closed_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_trace_mesh.c: watertight meshes (issue 9, finding 4). Adjacent
 * Polygons (triangles and quads) and bilinear Patches that share edges,
 * displaced by zero or by a shader that is continuous across the edges,
 * must leave no gap: every pixel whose samples all fall well inside the
 * mesh's outline has alpha exactly 1. (The subdivision used to keep a leaf
 * only when the centre of its (u,v) cell was on the polygon, so along a
 * shared edge both neighbours could drop the ray.)
 *
 * Curved meshes (issue 14): a dome (one face of a cube, subdivided and
 * pushed onto the unit sphere) from PointsPolygons, displaced by
 * Km * noise(P) along normalize(N), seen face on. With the mesh's vertex
 * normals N is continuous across the faces' edges and no pixel inside the
 * (eroded) outline of the undisplaced dome has alpha < 1; the same dome
 * given one flat normal per face ("uniform" N) opens cracks there, which
 * shows the check sees them. Affine and interval arithmetic both.
 *
 * Outlines (issue 27): a flat mesh tiling a square draws the square's
 * alpha, pixel for pixel.
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

static const char *WAVY_SL =
    "displacement wavy(float Km = 0)\n"
    "{\n"
    "    point Pw = transform(\"world\", P);\n"
    "    P += Km * sin(5 * xcomp(Pw)) * cos(4 * ycomp(Pw)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

enum { RES = 64 };

/* An n x n grid over [-1,1]^2 at z = 0 in world space, seen from z = -4:
 * quads as two triangles (kind 0), as quads (1) or as bilinear patches (2). */
static char *mesh_rib(int n, int kind, double km)
{
    size_t cap = 65536;
    char *s = malloc(cap);
    size_t len = (size_t)snprintf(s, cap,
        "Format %d %d 1\nPixelSamples 3 3\nProjection \"perspective\" \"fov\" [40]\n"
        "Translate 0 0 4\nWorldBegin\nDisplacement \"wavy\" \"float Km\" [%g]\n",
        RES, RES, km);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x0 = -1 + 2.0 * i / n, x1 = -1 + 2.0 * (i + 1) / n;
            double y0 = -1 + 2.0 * j / n, y1 = -1 + 2.0 * (j + 1) / n;
            if (kind == 0)
                len += (size_t)snprintf(s + len, cap - len,
                    "Polygon \"P\" [%.17g %.17g 0  %.17g %.17g 0  %.17g %.17g 0]\n"
                    "Polygon \"P\" [%.17g %.17g 0  %.17g %.17g 0  %.17g %.17g 0]\n",
                    x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1);
            else if (kind == 1)
                len += (size_t)snprintf(s + len, cap - len,
                    "Polygon \"P\" [%.17g %.17g 0  %.17g %.17g 0  %.17g %.17g 0  %.17g %.17g 0]\n",
                    x0, y0, x1, y0, x1, y1, x0, y1);
            else
                len += (size_t)snprintf(s + len, cap - len,
                    "Patch \"bilinear\" \"P\" [%.17g %.17g 0  %.17g %.17g 0  %.17g %.17g 0  "
                    "%.17g %.17g 0]\n", x0, y0, x1, y0, x0, y1, x1, y1);
        }
    snprintf(s + len, cap - len, "WorldEnd\n");
    return s;
}

/* Renders the mesh; counts pixels well inside the outline (every sample
 * and the filter's reach at least 2 pixels from it) whose alpha is not 1. */
static int gaps_in(int n, int kind, double km, int *inside)
{
    char *rib = mesh_rib(n, kind, km);
    fixture f;
    fixture_shader sh[] = {{"wavy", WAVY_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    free(rib);
    trace_thread *th = trace_thread_new(&f.js->world);
    float *rgba = calloc((size_t)RES * RES * 4, sizeof *rgba), *z = calloc((size_t)RES * RES, sizeof *z);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, RES, RES, rgba, z));
    /* the outline at z = 4 spans tan(20 deg) * 4 per half screen */
    double half = 1.0 / (4.0 * tan(20 * M_PI / 180)) * RES / 2;
    int gaps = 0;
    *inside = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            double dx = fabs(x + 0.5 - RES / 2.0), dy = fabs(y + 0.5 - RES / 2.0);
            if (dx > half - 3 || dy > half - 3) continue;
            (*inside)++;
            if (rgba[((size_t)y * RES + x) * 4 + 3] != 1.0f) gaps++;
        }
    printf("mesh %dx%d %s, Km %g: %d of %d inside pixels with alpha < 1\n", n, n,
           kind == 0 ? "triangles" : kind == 1 ? "quads" : "bilinear patches", km, gaps,
           *inside);
    free(rgba);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
    return gaps;
}

static void test_flat_meshes_are_watertight(void **state)
{
    (void)state;
    int inside;
    for (int kind = 0; kind < 3; kind++) {
        assert_int_equal(gaps_in(8, kind, 0.0, &inside), 0);
        assert_true(inside > 1000);
    }
}

static void test_displaced_meshes_are_watertight(void **state)
{
    (void)state;
    int inside;
    for (int kind = 0; kind < 3; kind++)
        assert_int_equal(gaps_in(8, kind, 0.05, &inside), 0);
}

/* The outer boundary of a flat mesh is the polygon it tiles: 128 triangles
 * tiling a tilted square (an 8 x 8 grid of quads, each split in two), as
 * Polygons or as one PointsPolygons, displaced by zero (so drawn by the
 * walk of boxes, not the exact intersection), draw the alpha of the square
 * drawn exactly (one Polygon, no displacement) at every pixel. Issue 27,
 * item 6: near the vertices where a shared edge meets the outline, a leaf
 * took a ray beyond the outline (its point clamped into the cell): 20
 * pixels at 512 x 512 drawn up to 0.159 more opaque than the square. */
enum { MESH_SQUARE, MESH_POLYGONS, MESH_POINTSPOLYGONS };

static float *square_alpha(int res, int n, int kind, bool displaced)
{
    size_t cap = 1 << 16;
    char *s = malloc(cap);
    size_t len = (size_t)snprintf(s, cap,
                                  "Format %d %d 1\nProjection \"perspective\" \"fov\" [40]\n"
                                  "Translate 0 0 4\nWorldBegin\nRotate 30 1 1 0\n%s", res, res,
                                  displaced ? "Displacement \"wavy\" \"float Km\" [0]\n" : "");
    if (kind == MESH_SQUARE) {
        len += (size_t)snprintf(s + len, cap - len,
                                "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\n");
    } else if (kind == MESH_POINTSPOLYGONS) {
        len += (size_t)snprintf(s + len, cap - len, "PointsPolygons [");
        for (int k = 0; k < 2 * n * n; k++) len += (size_t)snprintf(s + len, cap - len, "3 ");
        len += (size_t)snprintf(s + len, cap - len, "] [");
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
                len += (size_t)snprintf(s + len, cap - len, "%d %d %d %d %d %d ", a, b, c, a, c,
                                        d);
            }
        len += (size_t)snprintf(s + len, cap - len, "] \"P\" [");
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++)
                len += (size_t)snprintf(s + len, cap - len, "%.17g %.17g 0 ", -1 + 2.0 * i / n,
                                        -1 + 2.0 * j / n);
        len += (size_t)snprintf(s + len, cap - len, "]\n");
    } else {
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                double x0 = -1 + 2.0 * i / n, x1 = -1 + 2.0 * (i + 1) / n;
                double y0 = -1 + 2.0 * j / n, y1 = -1 + 2.0 * (j + 1) / n;
                len += (size_t)snprintf(s + len, cap - len,
                    "Polygon \"P\" [%.17g %.17g 0  %.17g %.17g 0  %.17g %.17g 0]\n"
                    "Polygon \"P\" [%.17g %.17g 0  %.17g %.17g 0  %.17g %.17g 0]\n",
                    x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1);
            }
    }
    snprintf(s + len, cap - len, "WorldEnd\n");
    fixture f;
    fixture_shader sh[] = {{"wavy", WAVY_SL}};
    assert_true(fixture_open(&f, s, sh, 1, NULL, 0));
    free(s);
    trace_thread *th = trace_thread_new(&f.js->world);
    float *rgba = calloc((size_t)res * res * 4, sizeof *rgba), *z = calloc((size_t)res * res, sizeof *z);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, res, res, rgba, z));
    float *alpha = calloc((size_t)res * res, sizeof *alpha);
    for (int i = 0; i < res * res; i++) alpha[i] = rgba[(size_t)i * 4 + 3];
    free(rgba);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
    return alpha;
}

static void test_mesh_outline_is_its_polygon(void **state)
{
    (void)state;
    enum { SQ_RES = 512 };
    float *ref = square_alpha(SQ_RES, 0, MESH_SQUARE, false);
    static const char *names[] = {"one displaced Polygon", "128 Polygons", "PointsPolygons"};
    for (int kind = MESH_SQUARE; kind <= MESH_POINTSPOLYGONS; kind++) {
        float *mesh = square_alpha(SQ_RES, 8, kind, true);
        int off = 0, covered = 0;
        double worst = 0;
        for (int i = 0; i < SQ_RES * SQ_RES; i++) {
            double d = fabs((double)mesh[i] - ref[i]);
            if (d > 1e-3 && off++ < 4)
                printf("  pixel (%d, %d): alpha %.4f, the square's %.4f\n", i % SQ_RES,
                       i / SQ_RES, mesh[i], ref[i]);
            worst = fmax(worst, d);
            covered += ref[i] > 0;
        }
        printf("%s against the exact square, %dx%d: %d of %d pixels off by more than 1e-3, "
               "at most %.4f\n", names[kind], SQ_RES, SQ_RES, off, covered, worst);
        assert_int_equal(off, 0);
        assert_true(covered > 50000);
        free(mesh);
    }
    free(ref);
}

static const char *LUMPY_SL =
    "displacement lumpy(float Km = 0)\n"
    "{\n"
    "    P += Km * noise(4 * transform(\"world\", P)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

enum { DOME_N = 4 };

/* The dome: grid point (i, j) of the cube face z = -1 on the unit sphere. */
static vec3 dome_point(int i, int j)
{
    return v3_normalize(v3(-1 + 2.0 * i / DOME_N, -1 + 2.0 * j / DOME_N, -1));
}

/* The dome as one PointsPolygons of quads wound outward (towards the
 * camera at z = -4); flat: with "uniform" N, each quad's own normal. */
static char *dome_rib(double km, bool flat)
{
    size_t cap = 65536;
    char *s = malloc(cap);
    size_t len = (size_t)snprintf(s, cap,
        "Format %d %d 1\nPixelSamples 3 3\nProjection \"perspective\" \"fov\" [40]\n"
        "Translate 0 0 4\nWorldBegin\nDisplacement \"lumpy\" \"float Km\" [%g]\n"
        "PointsPolygons [", RES, RES, km);
    for (int f = 0; f < DOME_N * DOME_N; f++)
        len += (size_t)snprintf(s + len, cap - len, " 4");
    len += (size_t)snprintf(s + len, cap - len, "] [");
    for (int j = 0; j < DOME_N; j++)
        for (int i = 0; i < DOME_N; i++) {
            int a = j * (DOME_N + 1) + i;
            len += (size_t)snprintf(s + len, cap - len, " %d %d %d %d", a, a + DOME_N + 1,
                                    a + DOME_N + 2, a + 1);
        }
    len += (size_t)snprintf(s + len, cap - len, "]\n  \"P\" [");
    for (int j = 0; j <= DOME_N; j++)
        for (int i = 0; i <= DOME_N; i++) {
            vec3 p = dome_point(i, j);
            len += (size_t)snprintf(s + len, cap - len, " %.17g %.17g %.17g", p.x, p.y, p.z);
        }
    len += (size_t)snprintf(s + len, cap - len, "]\n");
    if (flat) {
        len += (size_t)snprintf(s + len, cap - len, "  \"uniform normal N\" [");
        for (int j = 0; j < DOME_N; j++)
            for (int i = 0; i < DOME_N; i++) {
                vec3 c = v3_add(v3_add(dome_point(i, j), dome_point(i + 1, j)),
                                v3_add(dome_point(i, j + 1), dome_point(i + 1, j + 1)));
                len += (size_t)snprintf(s + len, cap - len, " %.17g %.17g %.17g", c.x, c.y,
                                        c.z);
            }
        len += (size_t)snprintf(s + len, cap - len, "]\n");
    }
    snprintf(s + len, cap - len, "WorldEnd\n");
    return s;
}

/* The alpha channel of the dome rendered at RES x RES (caller frees). */
static float *dome_alpha(double km, bool flat, int arith)
{
    char *rib = dome_rib(km, flat);
    job_options opt;
    job_options_default(&opt);
    opt.arith = arith;
    fixture f;
    fixture_shader sh[] = {{"lumpy", LUMPY_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, &opt, 0));
    free(rib);
    trace_thread *th = trace_thread_new(&f.js->world);
    float *rgba = calloc((size_t)RES * RES * 4, sizeof *rgba), *z = calloc((size_t)RES * RES, sizeof *z);
    float *alpha = calloc((size_t)RES * RES, sizeof *alpha);
    assert_true(trace_render_tile(f.js->renderer, th, 0, 0, RES, RES, rgba, z));
    for (int i = 0; i < RES * RES; i++)
        alpha[i] = rgba[(size_t)i * 4 + 3];
    free(rgba);
    free(z);
    trace_thread_destroy(&th);
    fixture_close(&f);
    return alpha;
}

/* Pixels of the undisplaced dome (alpha 1 within 3 pixels all round)
 * whose alpha in `alpha` is below 1. */
static int dome_gaps(const float *base, const float *alpha, int *inside)
{
    int gaps = 0;
    *inside = 0;
    for (int y = 3; y < RES - 3; y++)
        for (int x = 3; x < RES - 3; x++) {
            bool in = true;
            for (int dy = -3; dy <= 3 && in; dy++)
                for (int dx = -3; dx <= 3 && in; dx++)
                    in = base[(y + dy) * RES + x + dx] == 1.0f;
            if (!in) continue;
            (*inside)++;
            gaps += alpha[y * RES + x] != 1.0f;
        }
    return gaps;
}

static void test_displaced_curved_mesh_is_watertight(void **state)
{
    (void)state;
    for (int a = 0; a < 2; a++) {
        int arith = a == 0 ? TRACE_ARITH_AFFINE : TRACE_ARITH_INTERVAL;
        float *base = dome_alpha(0, false, arith);
        float *smooth = dome_alpha(0.3, false, arith);
        float *flat = dome_alpha(0.3, true, arith);
        int inside, inside_flat;
        int gaps = dome_gaps(base, smooth, &inside);
        int gaps_flat = dome_gaps(base, flat, &inside_flat);
        printf("dome of %d quads, Km 0.3, %s: vertex normals %d, flat normals %d of %d "
               "inside pixels with alpha < 1\n", DOME_N * DOME_N, trace_arith_name(arith),
               gaps, gaps_flat, inside);
        assert_true(inside > 500);
        assert_int_equal(gaps, 0);
        assert_true(gaps_flat > 0);
        free(base);
        free(smooth);
        free(flat);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mesh_outline_is_its_polygon),
        cmocka_unit_test(test_flat_meshes_are_watertight),
        cmocka_unit_test(test_displaced_meshes_are_watertight),
        cmocka_unit_test(test_displaced_curved_mesh_is_watertight),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

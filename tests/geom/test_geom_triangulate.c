/*
 * tests/geom/test_geom_triangulate.c: geom_triangulate (common/geom/
 * triangulate.c). For hand-made faces (a square, an L, a square with a
 * hole, a comb, clockwise input) and random star-shaped polygons with
 * random holes in tilted planes: the triangles' areas add up to the
 * polygon's area less its holes', every triangle winds like the polygon
 * (its normal points the polygon's way), no triangle's centroid lies in a
 * hole or outside the boundary, and the count is n + 2h - 2 (at most that
 * for the random ones, where slivers may be dropped). Degenerate
 * input is refused with a reason.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "geom/triangulate.h"

enum { MAXP = 256 };

/* Newell normal of a loop (twice its vector area). */
static vec3 newell(const vec3 *p, int n)
{
    vec3 r = v3(0, 0, 0);
    for (int i = 0; i < n; i++) {
        vec3 a = p[i], b = p[(i + 1) % n];
        r.x += (a.y - b.y) * (a.z + b.z);
        r.y += (a.z - b.z) * (a.x + b.x);
        r.z += (a.x - b.x) * (a.y + b.y);
    }
    return r;
}

/* Point in loop (2D, in the plane spanned by e1, e2), even-odd. */
static bool in_loop(vec3 q, const vec3 *p, int n, vec3 e1, vec3 e2)
{
    bool in = false;
    double qx = v3_dot(q, e1), qy = v3_dot(q, e2);
    for (int i = 0, j = n - 1; i < n; j = i++) {
        double xi = v3_dot(p[i], e1), yi = v3_dot(p[i], e2);
        double xj = v3_dot(p[j], e1), yj = v3_dot(p[j], e2);
        if ((yi > qy) != (yj > qy) && qx < (xj - xi) * (qy - yi) / (yj - yi) + xi)
            in = !in;
    }
    return in;
}

/* Checks a triangulation of loops in pts against the properties above. */
static void check(const vec3 *pts, const int *sizes, int nloops, bool straight_free)
{
    int (*tris)[3] = malloc(sizeof(int[3]) * 4 * MAXP);
    char why[200];
    int count = geom_triangulate(pts, sizes, nloops, tris, 4 * MAXP, why, sizeof why);
    if (count < 0)
        fprintf(stderr, "refused: %s\n", why);
    int npts = 0;
    for (int l = 0; l < nloops; l++)
        npts += sizes[l];
    assert_true(count > 0);
    assert_true(count <= npts + 2 * (nloops - 1) - 2);
    if (straight_free)
        assert_int_equal(count, npts + 2 * (nloops - 1) - 2);
    vec3 N = newell(pts, sizes[0]);
    double want = v3_length(N) / 2;
    int first = sizes[0];
    for (int l = 1; l < nloops; l++) {
        want -= v3_length(newell(pts + first, sizes[l])) / 2;
        first += sizes[l];
    }
    vec3 nz = v3_normalize(N);
    vec3 e1 = v3_normalize(v3_sub(pts[1], pts[0]));
    vec3 e2 = v3_cross(nz, e1);
    double got = 0;
    for (int t = 0; t < count; t++) {
        vec3 a = pts[tris[t][0]], b = pts[tris[t][1]], c = pts[tris[t][2]];
        vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
        if (!(v3_dot(n, nz) > 0))
            fprintf(stderr, "tri %d of %d: dot %g area %g\n", t, count, v3_dot(n, nz), v3_length(n));
        assert_true(v3_dot(n, nz) > 0);         /* winds like the polygon */
        got += v3_length(n) / 2;
        vec3 centroid = v3_scale(v3_add(v3_add(a, b), c), 1.0 / 3);
        assert_true(in_loop(centroid, pts, sizes[0], e1, e2));
        first = sizes[0];
        for (int l = 1; l < nloops; l++) {
            assert_false(in_loop(centroid, pts + first, sizes[l], e1, e2));
            first += sizes[l];
        }
    }
    assert_true(fabs(got - want) <= 1e-9 * want);
    free(tris);
}

static void test_hand_made(void **state)
{
    (void)state;
    vec3 square[] = { v3(0, 0, 0), v3(1, 0, 0), v3(1, 1, 0), v3(0, 1, 0) };
    check(square, (int[]){ 4 }, 1, true);
    vec3 square_cw[] = { v3(0, 0, 0), v3(0, 1, 0), v3(1, 1, 0), v3(1, 0, 0) };
    check(square_cw, (int[]){ 4 }, 1, true);
    vec3 ell[] = { v3(0, 0, 0), v3(2, 0, 0), v3(2, 1, 0), v3(1, 1, 0), v3(1, 2, 0),
                   v3(0, 2, 0) };
    check(ell, (int[]){ 6 }, 1, true);
    /* a square with a square hole, in the x = 3 plane, hole wound either way */
    vec3 holed[] = { v3(3, 0, 0), v3(3, 4, 0), v3(3, 4, 4), v3(3, 0, 4),
                     v3(3, 1, 1), v3(3, 3, 1), v3(3, 3, 3), v3(3, 1, 3) };
    check(holed, (int[]){ 4, 4 }, 2, true);
    vec3 holed2[] = { v3(3, 0, 0), v3(3, 4, 0), v3(3, 4, 4), v3(3, 0, 4),
                      v3(3, 1, 3), v3(3, 3, 3), v3(3, 3, 1), v3(3, 1, 1) };
    check(holed2, (int[]){ 4, 4 }, 2, true);
    /* a comb: many reflex corners */
    vec3 comb[2 * 8 + 2];
    int n = 0;
    for (int i = 0; i < 8; i++) {
        comb[n++] = v3(i, 0, 0);
        comb[n++] = v3(i + 0.5, 0, 3);
    }
    comb[n++] = v3(8, 0, -1);
    comb[n++] = v3(0, 0, -1);
    check(comb, (int[]){ n }, 1, true);
}

static void test_degenerate(void **state)
{
    (void)state;
    int tris[8][3];
    char why[200];
    vec3 line[] = { v3(0, 0, 0), v3(1, 1, 1), v3(2, 2, 2), v3(3, 3, 3) };
    assert_int_equal(geom_triangulate(line, (int[]){ 4 }, 1, tris, 8, why, sizeof why), -1);
    assert_string_equal(why, "the polygon has no area");
    vec3 two[] = { v3(0, 0, 0), v3(1, 0, 0), v3(1, 1, 0), v3(0, 0, 0), v3(1, 0, 0) };
    assert_int_equal(geom_triangulate(two, (int[]){ 3, 2 }, 2, tris, 8, why, sizeof why), -1);
    assert_string_equal(why, "loop 1 has 2 points, at least 3 are needed");
}

static double rnd(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (*s >> 8) / 16777216.0;
}

/* Star-shaped polygons with up to three small holes near the centre, in
 * random tilted planes, either winding. */
static void test_random(void **state)
{
    (void)state;
    unsigned seed = 12345;
    for (int k = 0; k < 300; k++) {
        vec3 pts[MAXP];
        int sizes[4], nloops = 1, n = 5 + (int)(rnd(&seed) * 60);
        vec3 ax = v3_normalize(v3(rnd(&seed) - 0.5, rnd(&seed) - 0.5, rnd(&seed) - 0.5));
        vec3 tmp = fabs(ax.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
        vec3 e1 = v3_normalize(v3_cross(ax, tmp)), e2 = v3_cross(ax, e1);
        vec3 o = v3(rnd(&seed) * 10, rnd(&seed) * 10, rnd(&seed) * 10);
        bool cw = rnd(&seed) < 0.5;
        for (int i = 0; i < n; i++) {
            double a = 2 * M_PI * (cw ? n - i : i) / n, r = 2 + 2 * rnd(&seed);
            pts[i] = v3_add(o, v3_add(v3_scale(e1, r * cos(a)), v3_scale(e2, r * sin(a))));
        }
        sizes[0] = n;
        int total = n, holes = (int)(rnd(&seed) * 4);
        for (int h = 0; h < holes; h++) {
            /* small triangles or squares around points on a circle of radius 1 */
            int m = 3 + (int)(rnd(&seed) * 2);
            double c = 2 * M_PI * h / 3, size = 0.3;
            for (int i = 0; i < m; i++) {
                double a = 2 * M_PI * i / m;
                double x = cos(c) + size * cos(a), y = sin(c) + size * sin(a);
                pts[total + i] = v3_add(o, v3_add(v3_scale(e1, x), v3_scale(e2, y)));
            }
            sizes[nloops++] = m;
            total += m;
        }
        check(pts, sizes, nloops, false);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_made),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_random),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

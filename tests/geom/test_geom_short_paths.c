/*
 * tests/geom/test_geom_short_paths.c: the P-only paths of the patch kinds
 * (issues 23 and 24: a displaced Catmull-Clark mesh's world build wants
 * each piece's base box and 81 points of its grid spacing, not its
 * derivatives) give the very bits of the general paths they replace, so
 * no box and no image moves:
 *
 *   range_P  geom_eval_aa_range_P (the hull of the piece's Bezier net met
 *            with its float net's box) against aa_range of geom_eval_aa's
 *            P, bit for bit, on subdivision faces (a bumpy grid: regular
 *            faces; a cube: valence 3; a fan of 5 with a boundary; a cube
 *            with creases and a corner tag) and bicubic patches, over the
 *            whole square, dyadic boxes down to 2^-14 (below 2^-12 the
 *            tensor form's path) and arbitrary boxes; and float samples lie
 *            inside (1e-11 of slack)
 *   in_bounds  a subdivision face's P over its whole square (the range
 *            above) lies inside its geom_bounds (the 1-ring's hull), so
 *            their hull, a mesh piece's base box (trace_region_base), is
 *            geom_bounds bit for bit, on the same meshes and on rings
 *            moved far from the origin (1e6) and shrunk (1e-6)
 *   point    geom_eval_point against geom_eval's P, bit for bit, at random
 *            points, the square's corners and edges (irregular corners:
 *            the limit masks) on the same surfaces
 *   cubic    geom_bezier_piece's cubic written out against its loops (the
 *            blossoms' de Casteljau levels, spelled here as bezier_net.c
 *            had them), bit for bit, on random cubics and pieces
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "geom/subdiv.h"
#include "geom/surface.h"
#include "geom/surface_internal.h"
#include "geom_fixtures.h"

static unsigned long long rng_state = 0x2545f4914f6cdd1dULL;
static double urand(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

static uint64_t bits_of(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

/* ---- surfaces ---- */

enum { G = 9 };
static double grid_P[3 * G * G];
static int grid_NV[(G - 1) * (G - 1)], grid_V[4 * (G - 1) * (G - 1)];

/* a bumpy G x G grid of quads: its inner faces are regular */
static geom_subdiv *grid(void)
{
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            double *p = grid_P + 3 * (j * G + i);
            p[0] = i + 0.2 * urand(), p[1] = j + 0.2 * urand(), p[2] = 2 * urand() - 1;
        }
    for (int j = 0; j < G - 1; j++)
        for (int i = 0; i < G - 1; i++) {
            int f = j * (G - 1) + i, *q = grid_V + 4 * f;
            grid_NV[f] = 4;
            q[0] = j * G + i, q[1] = j * G + i + 1, q[2] = (j + 1) * G + i + 1;
            q[3] = (j + 1) * G + i;
        }
    geom_subdiv_desc d = { (G - 1) * (G - 1), grid_NV, grid_V, G * G, grid_P, 0, NULL, NULL,
                           NULL, 0, NULL, NULL, 0, NULL, false };
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    if (!sd) fprintf(stderr, "grid: %s\n", why);
    assert_non_null(sd);
    return sd;
}

static geom_subdiv *cube(bool creased)
{
    static const int clen[] = { 5, 2 }, cv[] = { 0, 1, 2, 3, 0,  4, 5 }, corner[] = { 6 };
    static const double cs[] = { 10, 1.5 }, corner_s[] = { 10 };
    geom_subdiv *sd = creased ? fx_subdiv_cube(2, clen, cv, cs, 1, corner, corner_s)
                              : fx_subdiv_cube(0, NULL, NULL, NULL, 0, NULL, NULL);
    assert_non_null(sd);
    return sd;
}

/* 5 quads around a point of valence 5, a boundary outside */
static geom_subdiv *fan(void)
{
    geom_subdiv *sd = fx_subdiv_fan(5, NULL);
    assert_non_null(sd);
    return sd;
}

static geom_surface bicubic(double scale)
{
    geom_surface s;
    memset(&s, 0, sizeof s);
    s.kind = GEOM_BICUBIC;
    s.nverts = 16;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            s.verts[4 * j + i] = v3(scale * (i + 0.4 * urand()), scale * (j + 0.4 * urand()),
                                    scale * (2 * urand() - 1));
    char why[200];
    if (!geom_surface_prepare(&s, why, sizeof why)) fprintf(stderr, "bicubic: %s\n", why);
    return s;
}

/* ---- range_P ---- */

typedef struct count { long boxes, points, differ, outside; } count;

static void box_same(const geom_surface *s, double u0, double u1, double v0, double v1,
                     count *c)
{
    aa_context ctx;
    aa_context_init(&ctx, 2);          /* as a mesh's world pass (trace/world.c) */
    aa_form U, V;
    aa_input(&ctx, &U, u0, u1);
    aa_input(&ctx, &V, v0, v1);
    geom_aa g;
    geom_eval_aa(&ctx, s, &U, &V, &g);
    ia_interval want[3], got[3];
    for (int i = 0; i < 3; i++) want[i] = aa_range(&g.P[i]);
    aa_context_reset(&ctx);
    aa_input(&ctx, &U, u0, u1);
    aa_input(&ctx, &V, v0, v1);
    geom_eval_aa_range_P(&ctx, s, &U, &V, got);
    c->boxes++;
    for (int i = 0; i < 3; i++)
        if (bits_of(got[i].lo) != bits_of(want[i].lo) ||
            bits_of(got[i].hi) != bits_of(want[i].hi) || got[i].flags != want[i].flags) {
            if (c->differ++ < 5)
                printf("box [%.17g %.17g] x [%.17g %.17g] axis %d: [%a %a] want [%a %a]\n", u0,
                       u1, v0, v1, i, got[i].lo, got[i].hi, want[i].lo, want[i].hi);
        }
    for (int k = 0; k < 9; k++) {
        double u = k < 4 ? (k & 1 ? u1 : u0) : u0 + (u1 - u0) * urand();
        double v = k < 4 ? (k & 2 ? v1 : v0) : v0 + (v1 - v0) * urand();
        geom_sample p;
        geom_eval(s, u, v, &p);
        for (int i = 0; i < 3; i++) {
            double x = v3_comp(p.P, i), slack = 1e-11 * (1 + fabs(x));
            if (!(x >= got[i].lo - slack && x <= got[i].hi + slack)) c->outside++;
        }
        c->points++;
    }
}

static void boxes_same(const geom_surface *s, int n, count *c)
{
    box_same(s, 0, 1, 0, 1, c);
    for (int b = 0; b < n; b++) {
        double u0, u1, v0, v1;
        if (b % 3 != 2) {              /* dyadic, as the renderer's quadtree */
            double side = ldexp(1, -(int)(urand() * 15));
            u0 = floor(urand() / side) * side, v0 = floor(urand() / side) * side;
            u1 = u0 + side, v1 = v0 + side;
        } else {
            double su = pow(10, -4 * urand()), sv = pow(10, -4 * urand());
            u0 = (1 - su) * urand(), v0 = (1 - sv) * urand();
            u1 = u0 + su, v1 = v0 + sv;
        }
        box_same(s, u0, u1, v0, v1, c);
    }
}

static void mesh_same(const char *name, geom_subdiv *sd, int n)
{
    count c = { 0, 0, 0, 0 };
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        boxes_same(&s, n, &c);
    }
    printf("%-13s %6ld boxes, %ld differ; %6ld points, %ld outside\n", name, c.boxes, c.differ,
           c.points, c.outside);
    assert_true(c.boxes > 100);
    assert_int_equal(c.differ, 0);
    assert_int_equal(c.outside, 0);
}

static void test_range_P(void **state)
{
    (void)state;
    geom_subdiv *sd = grid();
    mesh_same("bumpy grid", sd, 30);
    geom_subdiv_destroy(&sd);
    sd = cube(false);
    mesh_same("cube", sd, 60);
    geom_subdiv_destroy(&sd);
    sd = fan();
    mesh_same("fan 5", sd, 60);
    geom_subdiv_destroy(&sd);
    sd = cube(true);
    mesh_same("creased cube", sd, 60);
    geom_subdiv_destroy(&sd);
    count c = { 0, 0, 0, 0 };
    for (int k = 0; k < 40; k++) {
        geom_surface s = bicubic(k % 4 == 0 ? 1e6 : k % 4 == 1 ? 1e-5 : 1);
        boxes_same(&s, 30, &c);
    }
    printf("%-13s %6ld boxes, %ld differ; %6ld points, %ld outside\n", "bicubic", c.boxes,
           c.differ, c.points, c.outside);
    assert_int_equal(c.differ, 0);
    assert_int_equal(c.outside, 0);
}

/* ---- in_bounds ---- */

static geom_subdiv *moved(const geom_subdiv_desc *d0, double *P, int np, double scale,
                          double shift)
{
    for (int i = 0; i < 3 * np; i++) P[i] = P[i] * scale + shift;
    geom_subdiv_desc d = *d0;
    d.P = P;
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    if (!sd) fprintf(stderr, "moved: %s\n", why);
    assert_non_null(sd);
    return sd;
}

static long outside_bounds(geom_subdiv *sd, long *faces)
{
    long out = 0;
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        if (!geom_subdiv_face_drawn(sd, f)) continue;
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        aa_context ctx;
        aa_context_init(&ctx, 2);
        aa_form U, V;
        aa_input(&ctx, &U, 0, 1);
        aa_input(&ctx, &V, 0, 1);
        ia_interval P[3];
        geom_eval_aa_range_P(&ctx, &s, &U, &V, P);
        vec3 lo, hi;
        geom_bounds(&s, &lo, &hi);
        (*faces)++;
        for (int i = 0; i < 3; i++)
            if (!(P[i].lo >= v3_comp(lo, i) && P[i].hi <= v3_comp(hi, i)) && out++ < 5)
                printf("face %d axis %d: P [%a %a], bounds [%a %a]\n", f, i, P[i].lo, P[i].hi,
                       v3_comp(lo, i), v3_comp(hi, i));
    }
    return out;
}

static void test_in_bounds(void **state)
{
    (void)state;
    long faces = 0, out = 0;
    geom_subdiv *sd = grid();
    out += outside_bounds(sd, &faces);
    geom_subdiv_destroy(&sd);
    static double P[3 * G * G];
    geom_subdiv_desc d = { (G - 1) * (G - 1), grid_NV, grid_V, G * G, NULL, 0, NULL, NULL,
                           NULL, 0, NULL, NULL, 0, NULL, false };
    for (int k = 0; k < 12; k++) {
        if (k % 4 == 0) {              /* a fresh grid */
            sd = grid();
            geom_subdiv_destroy(&sd);
        }
        memcpy(P, grid_P, sizeof P);
        sd = moved(&d, P, G * G, k & 1 ? 1e-6 : 1, k & 2 ? 1e6 : 0.3);
        out += outside_bounds(sd, &faces);
        geom_subdiv_destroy(&sd);
    }
    geom_subdiv *meshes[3] = { cube(false), fan(), cube(true) };
    for (int m = 0; m < 3; m++) {
        out += outside_bounds(meshes[m], &faces);
        geom_subdiv_destroy(&meshes[m]);
    }
    printf("whole faces: %ld, %ld with P outside their bounds\n", faces, out);
    assert_true(faces > 1500);
    assert_int_equal(out, 0);
}

/* ---- point ---- */

static long point_differ(const geom_surface *s, int n, long *points)
{
    long differ = 0;
    for (int k = 0; k < n; k++) {
        double u, v;
        if (k < 81) {                  /* the grid spacing's 9 x 9 (corners, edges) */
            u = (k % 9) / 8.0, v = (k / 9) / 8.0;
        } else {
            u = urand(), v = urand();
        }
        geom_sample g;
        geom_eval(s, u, v, &g);
        vec3 p = geom_eval_point(s, u, v);
        (*points)++;
        for (int i = 0; i < 3; i++)
            if (bits_of(v3_comp(p, i)) != bits_of(v3_comp(g.P, i)) && differ++ < 5)
                printf("point (%.17g, %.17g) axis %d: %a, geom_eval %a\n", u, v, i,
                       v3_comp(p, i), v3_comp(g.P, i));
    }
    return differ;
}

static void test_point(void **state)
{
    (void)state;
    geom_subdiv *meshes[4] = { grid(), cube(false), fan(), cube(true) };
    long points = 0, differ = 0;
    for (int m = 0; m < 4; m++) {
        for (int f = 0; f < geom_subdiv_nfaces(meshes[m]); f++) {
            if (!geom_subdiv_face_drawn(meshes[m], f)) continue;
            geom_surface s;
            geom_subdiv_surface(meshes[m], f, &s);
            differ += point_differ(&s, 120, &points);
        }
        geom_subdiv_destroy(&meshes[m]);
    }
    for (int k = 0; k < 20; k++) {
        geom_surface s = bicubic(1);
        differ += point_differ(&s, 120, &points);
    }
    printf("points %ld, %ld differ\n", points, differ);
    assert_true(points > 10000);
    assert_int_equal(differ, 0);
}

/* ---- cubic ---- */

/* the loops of geom_bezier_piece for any n: n - 1 levels, a at the first
 * n - 1 - k, b at the last k; the levels at a shared */
static void loops_piece(const double *p, int n, double a, double b, double *q)
{
    double r[8];
    for (int i = 0; i < n; i++) r[i] = p[i];
    for (int m = 0; m < n; m++) {
        double t[8];
        for (int i = 0; i < n - m; i++) t[i] = r[i];
        for (int l = m; l < n - 1; l++)
            for (int i = 0; i < n - 1 - l; i++) t[i] = t[i] + (t[i + 1] - t[i]) * b;
        q[n - 1 - m] = t[0];
        for (int i = 0; i < n - 1 - m; i++) r[i] = r[i] + (r[i + 1] - r[i]) * a;
    }
}

static void test_cubic(void **state)
{
    (void)state;
    long differ = 0, n = 0;
    for (int k = 0; k < 200000; k++) {
        double p[12], want[4], got[8];
        double scale = ldexp(1, (int)(urand() * 80) - 40);
        for (int i = 0; i < 4; i++) p[3 * i] = scale * (2 * urand() - 1);
        double a = urand(), b = urand();
        if (k % 4 == 0) a = 0, b = 1;
        if (k % 4 == 1 && a > b) { double t = a; a = b; b = t; }
        double row[4] = { p[0], p[3], p[6], p[9] };
        loops_piece(row, 4, a, b, want);
        geom_bezier_piece(p, 3, 4, a, b, got, 2);     /* strides as the nets' */
        for (int i = 0; i < 4; i++, n++)
            if (bits_of(got[2 * i]) != bits_of(want[i]) && differ++ < 5)
                printf("cubic %a %a %a %a over [%a, %a]: q%d %a, loops %a\n", row[0], row[1],
                       row[2], row[3], a, b, i, got[2 * i], want[i]);
    }
    printf("cubic pieces: %ld points, %ld differ\n", n, differ);
    assert_int_equal(differ, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_range_P),
        cmocka_unit_test(test_in_bounds),
        cmocka_unit_test(test_point),
        cmocka_unit_test(test_cubic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

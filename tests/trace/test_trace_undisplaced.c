/*
 * test_trace_undisplaced.c: undisplaced cells (issue 24; docs/renderer.md
 * "Undisplaced cells"). Where a displacement run leaves P's affine form as
 * the base surface gave it (a decided step's branch that adds an exact 0),
 * the cell's box says so (TRACE_BOX_UNDISPLACED) and, on a flat base, the
 * walk intersects the base surface there exactly instead of subdividing.
 *
 * The scene: a disk seen from straight above, with a sunken wedge (the
 * points with u, the angle's fraction, in [0.13, 0.25) pushed away from
 * the eye by h). The other cells are undisplaced; the disk's cells are
 * sectors, whose boxes reach beyond their angles (the box of u in [0,
 * 0.125] covers points at 60 degrees), so a ray into the wedge crosses the
 * base plane inside such a box: the exact test must take a hit only inside
 * its own cell, or the wedge would be drawn filled at the plane's depth.
 * And a displacement too small to see (1e-20 along N) changes the forms,
 * so no cell of it may be taken for undisplaced. On a quadric (a sphere
 * whose shader only bends N) every cell is undisplaced, and every hit is
 * the sphere's own point; the same on a planar bilinear patch (its closed
 * form), and on instances that share their prototype's boxes.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "fixture.h"
#include "trace/camera.h"
#include "trace/render.h"

#define WEDGE_U0 0.13
#define WEDGE_U1 0.25
#define WEDGE_H 0.25
#define DEPTH 3.0

static const char *WEDGE_SL =
    "displacement wedge(float u0 = 0.13, u1 = 0.25, h = 0.25)\n"
    "{\n"
    "    P += h * step(u0, u) * (1 - step(u1, u)) * normalize(I);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *TINY_SL =
    "displacement tiny(float Km = 1e-20)\n"
    "{\n"
    "    P += Km * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* the unit disk at depth 3, facing the eye */
#define DISK_RIB(shader)                                                   \
    "Format 64 64 1\nProjection \"perspective\" \"fov\" [45]\n"            \
    "Translate 0 0 3\nWorldBegin\nDisplacement \"" shader "\"\n"           \
    "Disk 0 1 360\nWorldEnd\n"

typedef struct disk_scan {
    int flat, flat_hits, flat_exact;   /* rays onto the undisplaced part */
    int sunk, sunk_hits, sunk_deep;    /* rays into the sunken wedge */
    trace_stats st;
} disk_scan;

/* One ray through every pixel centre; the ray's point on the base plane
 * (camera z = 3) says where it should land */
static void scan_disk(const char *name, const char *src, disk_scan *out)
{
    fixture f;
    assert_true(fixture_open_named(&f, DISK_RIB("%s"), name, src));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_camera *cam = &f.js->world.camera;
    *out = (disk_scan){0};
    const double margin = 0.03, umargin = 0.01;
    for (int y = 0; y < cam->yres; y++)
        for (int x = 0; x < cam->xres; x++) {
            trace_ray ray;
            trace_camera_ray(cam, x + 0.5, y + 0.5, &ray);
            vec3 at = trace_ray_at(&ray, DEPTH / ray.d.z);
            double r = sqrt(at.x * at.x + at.y * at.y);
            double u = atan2(at.y, at.x) / (2 * M_PI);
            if (u < 0) u += 1;
            double rgb[3], a, z;
            trace_render_sample(f.js->renderer, th, x + 0.5, y + 0.5, rgb, &a, &z);
            bool hit = a > 0;
            if (r < margin || r > 1 - margin) continue;
            if (u > WEDGE_U0 + umargin && u < WEDGE_U1 - umargin) {
                out->sunk++;
                out->sunk_hits += hit;
                /* pushed back along the ray by h: at least h cos(22.5 deg) */
                out->sunk_deep += hit && z > DEPTH + 0.9 * WEDGE_H;
            } else if (u < WEDGE_U0 - umargin || u > WEDGE_U1 + umargin) {
                out->flat++;
                out->flat_hits += hit;
                out->flat_exact += hit && fabs(z - DEPTH) <= 1e-12 * DEPTH;
            }
        }
    trace_thread_sync_stats(th);
    out->st = th->stats;
    printf("%-5s flat %d/%d hit (%d at the plane's depth), sunken %d/%d hit (%d deep); "
           "exact cells %ld, boxes %ld, proofs %ld\n", name, out->flat_hits, out->flat,
           out->flat_exact, out->sunk_hits, out->sunk, out->sunk_deep, out->st.exact_cells,
           out->st.boxes, out->st.proofs);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static void test_flat_exact_and_wedge_open(void **state)
{
    (void)state;
    disk_scan s;
    scan_disk("wedge", WEDGE_SL, &s);
    assert_true(s.flat > 1000 && s.sunk > 100);
    /* the undisplaced part is intersected exactly */
    assert_true(s.st.exact_cells > 0);
    assert_int_equal(s.flat_hits, s.flat);
    assert_int_equal(s.flat_exact, s.flat);
    /* and no exact test takes the plane's hit for a cell it is not in */
    assert_int_equal(s.sunk_hits, s.sunk);
    assert_int_equal(s.sunk_deep, s.sunk);
}

/* Where a ray through a pixel centre should land (o = 0): EXPECT_HIT
 * with the camera depth *zexp, EXPECT_MISS, or EXPECT_SKIP near a
 * silhouette or an edge */
typedef enum { EXPECT_SKIP, EXPECT_HIT, EXPECT_MISS } expect;
typedef expect (*expect_fn)(vec3 d, double *zexp);

typedef struct exact_scan {
    int inside, hits, exact, outside_hits;
    trace_stats st;
} exact_scan;

/* One ray through every pixel centre against what expect says: how many
 * of the rays that must hit do, how many at the expected depth to 1e-9,
 * how many that must miss hit */
static void scan_exact(fixture *f, expect_fn fn, exact_scan *out)
{
    trace_thread *th = trace_thread_new(&f->js->world);
    const trace_camera *cam = &f->js->world.camera;
    *out = (exact_scan){0};
    for (int y = 0; y < cam->yres; y++)
        for (int x = 0; x < cam->xres; x++) {
            trace_ray ray;
            trace_camera_ray(cam, x + 0.5, y + 0.5, &ray);
            double zexp = 0, rgb[3], al, z;
            expect e = fn(ray.d, &zexp);
            trace_render_sample(f->js->renderer, th, x + 0.5, y + 0.5, rgb, &al, &z);
            if (e == EXPECT_MISS) out->outside_hits += al > 0;
            if (e != EXPECT_HIT) continue;
            out->inside++;
            out->hits += al > 0;
            out->exact += al > 0 && fabs(z - zexp) <= 1e-9 * zexp;
        }
    trace_thread_sync_stats(th);
    out->st = th->stats;
    trace_thread_destroy(&th);
}

static void assert_all_exact(const exact_scan *s)
{
    assert_true(s->inside > 500);
    assert_true(s->st.exact_cells > 0);
    assert_int_equal(s->hits, s->inside);
    assert_int_equal(s->exact, s->inside);
    assert_int_equal(s->outside_hits, 0);
}

static void test_any_displacement_is_not_undisplaced(void **state)
{
    (void)state;
    disk_scan s;
    scan_disk("tiny", TINY_SL, &s);
    /* 1e-20 is below every rounding of the plane, but the forms change:
     * no cell is undisplaced; the move is a constant, so every exact cell
     * is an offset cell (the base moved by 1e-20, at the plane's depth) */
    assert_true(s.st.offset_cells > 0);
    assert_int_equal(s.st.exact_cells, s.st.offset_cells);
    assert_int_equal(s.flat_hits, s.flat);
    assert_int_equal(s.flat_exact, s.flat);
    assert_int_equal(s.sunk_hits, s.sunk);
}

static const char *SLOPE_SL =
    "displacement slope(float Km = 1e-6)\n"
    "{\n"
    "    P += Km * u * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* A displacement that varies over every cell, however little (1e-6 u
 * along N), moves no cell by a constant: no exact cell at all */
static void test_varying_displacement_is_not_offset(void **state)
{
    (void)state;
    disk_scan s;
    scan_disk("slope", SLOPE_SL, &s);
    assert_int_equal(s.st.exact_cells, 0);
    assert_int_equal(s.flat_hits, s.flat);
}

static const char *RAISED_SL =
    "displacement raised(float u0 = 0.13, u1 = 0.25, h = 0.25)\n"
    "{\n"
    "    P += h * step(u0, u) * (1 - step(u1, u)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* The disk with a wedge moved by h along its normal (object +z, away
 * from the eye): the wedge's cells are the base moved by a constant
 * (offset cells), the rest undisplaced; every hit exactly at its plane's
 * depth, 3 or 3 + h (along a ray from the eye the angle u is the same at
 * both depths) */
static expect raised_wedge(vec3 d, double *zexp)
{
    double t = DEPTH / d.z, x = t * d.x, y = t * d.y, r = sqrt(x * x + y * y);
    double u = atan2(y, x) / (2 * M_PI);
    if (u < 0) u += 1;
    const double m = 0.03, um = 0.01;
    if (r < m || r > 1 - m) return r > 1 + m ? EXPECT_MISS : EXPECT_SKIP;
    if (u > WEDGE_U0 + um && u < WEDGE_U1 - um) {
        if (r * (DEPTH + WEDGE_H) / DEPTH > 1 - m) return EXPECT_SKIP;
        *zexp = DEPTH + WEDGE_H;
        return EXPECT_HIT;
    }
    if (u < WEDGE_U0 - um || u > WEDGE_U1 + um) {
        *zexp = DEPTH;
        return EXPECT_HIT;
    }
    return EXPECT_SKIP;
}

/* The disk with the raised wedge of shader src: every hit exactly at its
 * plane's depth, the wedge's cells offset cells */
static void assert_raised_wedge_exact(const char *name, const char *src)
{
    fixture f;
    assert_true(fixture_open_named(&f, DISK_RIB("%s"), name, src));
    exact_scan s;
    scan_exact(&f, raised_wedge, &s);
    printf("%s wedge: %d/%d hit, %d at their plane's depth, %d hits off the disk; exact "
           "cells %ld (offset %ld), boxes %ld, proofs %ld\n", name, s.hits, s.inside, s.exact,
           s.outside_hits, s.st.exact_cells, s.st.offset_cells, s.st.boxes, s.st.proofs);
    assert_all_exact(&s);
    assert_true(s.st.offset_cells > 0);
    fixture_close(&f);
}

static void test_raised_wedge_offset_exact(void **state)
{
    (void)state;
    assert_raised_wedge_exact("raised", RAISED_SL);
}

/* The raised wedge with its height made as a box-filtered pulse makes it
 * inside a brick (bricks_filtered's idiom): (hi - lo) / w is 1 up to
 * rounding, and the product of two such factors carries its rounding on a
 * fresh noise symbol, which the base's forms lack */
static const char *FILTERED_SL =
    "displacement filtered(float u0 = 0.13, u1 = 0.25, h = 0.25, w = 0.01)\n"
    "{\n"
    "    float x = u * 7.3, y = v * 3.1;\n"
    "    float lo = x - 0.5 * w, hi = lo + w, a = (hi - lo) / w;\n"
    "    float lo2 = y - 0.5 * w, hi2 = lo2 + w, b = (hi2 - lo2) / w;\n"
    "    P += h * (a * b) * step(u0, u) * (1 - step(u1, u)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* A move that is constant up to rounding, some of it on a fresh symbol,
 * is still a move by a constant: every hit at its plane's depth */
static void test_rounded_constant_is_offset(void **state)
{
    (void)state;
    assert_raised_wedge_exact("filtered", FILTERED_SL);
}

/* 1e-6 sin(1e6 u): over any cell a range of [-1e-6, 1e-6] with no u term
 * (the whole of sin's range), all of it on a fresh symbol or the error
 * term: a real variation, so no cell is moved by a constant */
static const char *WIGGLE_SL =
    "displacement wiggle(float h = 0.25)\n"
    "{\n"
    "    P += h * (1 + 1e-6 * sin(1e6 * u)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static void test_fresh_symbol_variation_is_not_offset(void **state)
{
    (void)state;
    disk_scan s;
    scan_disk("wiggle", WIGGLE_SL, &s);
    assert_int_equal(s.st.offset_cells, 0);
    assert_int_equal(s.st.exact_cells, 0);
}

/* A ramp: the unit square facing the eye (s = (x + 1) / 2 across it),
 * pushed away from the eye by h s in camera space: over every cell the
 * displaced surface is one tilted plane (its forms affine in u and v:
 * TRACE_BOX_PLANAR), intersected in closed form. RAMP_CURVED_SL bends it
 * (h s^2): no cell is one plane */
#define RAMP_H 0.5
static const char *RAMP_SL =
    "displacement ramp(float h = 0.5)\n"
    "{\n"
    "    P += vector(0, 0, h * s);\n"
    "    N = calculatenormal(P);\n"
    "}\n";
static const char *RAMP_CURVED_SL =
    "displacement rampcurved(float h = 0.5)\n"
    "{\n"
    "    P += vector(0, 0, h * s * s);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

#define SQUARE_RIB(shader)                                                 \
    "Format 64 64 1\nProjection \"perspective\" \"fov\" [45]\n"            \
    "Translate 0 0 3\nWorldBegin\nDisplacement \"" shader "\"\n"           \
    "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"st\" [0 0  1 0  1 1  0 1]\n" \
    "WorldEnd\n"

/* The ray t d meets z = 3 + h (x + 1) / 2 at t (3 + h/2) / (d.z - h d.x / 2) */
static expect ramp(vec3 d, double *zexp)
{
    double t = (DEPTH + 0.5 * RAMP_H) / (d.z - 0.5 * RAMP_H * d.x);
    double x = t * d.x, y = t * d.y;
    const double m = 0.03;
    if (fabs(x) > 1 + m || fabs(y) > 1 + m) return EXPECT_MISS;
    if (fabs(x) > 1 - m || fabs(y) > 1 - m) return EXPECT_SKIP;
    *zexp = t * d.z;
    return EXPECT_HIT;
}

/* Every ray through a pixel centre against the ramp: hits where it must,
 * at the plane's depth, and its shading point (the displaced surface
 * evaluated at the hit's (u,v)) on the ray at the hit's t: the (u,v) the
 * closed form gives are the hit's own */
static void test_ramp_planar_exact(void **state)
{
    (void)state;
    fixture f;
    assert_true(fixture_open_named(&f, SQUARE_RIB("%s"), "ramp", RAMP_SL));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_camera *cam = &f.js->world.camera;
    int inside = 0, hits = 0, exact = 0, on_ray = 0, outside_hits = 0;
    for (int y = 0; y < cam->yres; y++)
        for (int x = 0; x < cam->xres; x++) {
            trace_ray ray;
            trace_camera_ray(cam, x + 0.5, y + 0.5, &ray);
            double zexp = 0;
            expect e = ramp(ray.d, &zexp);
            trace_hit hit = {.t = ray.tmax, .obj = NULL};
            bool found = trace_bvh_intersect(f.js->renderer->bvh, th, &ray,
                                             &f.js->renderer->primary_tol, false, &hit);
            if (e == EXPECT_MISS) outside_hits += found;
            if (e != EXPECT_HIT) continue;
            inside++;
            if (!found) continue;
            hits++;
            vec3 at = trace_ray_at(&ray, hit.t);
            exact += fabs(at.z - zexp) <= 1e-9 * zexp;
            on_ray += hit.has_point && v3_length(v3_sub(hit.point.P, at)) <= 1e-9 * zexp;
        }
    trace_thread_sync_stats(th);
    trace_stats st = th->stats;
    printf("ramp: %d/%d hit, %d at the plane's depth, %d shading points on the ray, %d hits "
           "off the square; planar cells %ld, boxes %ld, proofs %ld\n", hits, inside, exact,
           on_ray, outside_hits, st.planar_cells, st.boxes, st.proofs);
    assert_true(inside > 500);
    assert_true(st.planar_cells > 0);
    assert_int_equal(hits, inside);
    assert_int_equal(exact, inside);
    assert_int_equal(on_ray, inside);
    assert_int_equal(outside_hits, 0);
    trace_thread_destroy(&th);
    fixture_close(&f);

    assert_true(fixture_open_named(&f, SQUARE_RIB("%s"), "rampcurved", RAMP_CURVED_SL));
    exact_scan s;
    scan_exact(&f, ramp, &s);
    printf("curved ramp: planar cells %ld, boxes %ld\n", s.st.planar_cells, s.st.boxes);
    assert_int_equal(s.st.planar_cells, 0);
    fixture_close(&f);
}

static const char *BUMP_SL =
    "displacement bumponly(float Kb = 0.02)\n"
    "{\n"
    "    N = calculatenormal(P + Kb * noise(P * 4) * normalize(N));\n"
    "}\n";

/* A sphere (radius 1, at depth 3) whose displacement only bends N: every
 * cell is undisplaced, and on a quadric the walk intersects its base
 * exactly too (the nearer root first, then the farther where the nearer
 * falls outside the cell) */
static expect unit_sphere(vec3 d, double *zexp)
{
    /* |p - (0, 0, 3)| = 1 along t d */
    double a = v3_dot(d, d), b = -6.0 * d.z, cc = 9.0 - 1.0, disc = b * b - 4 * a * cc;
    if (disc < 0.05 * b * b)             /* off the sphere, or near its silhouette */
        return disc < 0 ? EXPECT_MISS : EXPECT_SKIP;
    *zexp = (-b - sqrt(disc)) / (2 * a) * d.z;
    return EXPECT_HIT;
}

static void test_sphere_bent_normals_exact(void **state)
{
    (void)state;
    fixture f;
    assert_true(fixture_open_named(&f,
                                   "Format 48 48 1\nProjection \"perspective\" \"fov\" [45]\n"
                                   "Translate 0 0 3\nWorldBegin\nDisplacement \"%s\"\n"
                                   "Sphere 1 -1 1 360\nWorldEnd\n",
                                   "bumponly", BUMP_SL));
    exact_scan s;
    scan_exact(&f, unit_sphere, &s);
    printf("bent normals: %d/%d hit, %d at the sphere's depth, %d hits off it; exact cells %ld, "
           "boxes %ld\n", s.hits, s.inside, s.exact, s.outside_hits, s.st.exact_cells,
           s.st.boxes);
    assert_all_exact(&s);
    fixture_close(&f);
}

/* A planar bilinear patch (four corners on the plane z = 3 + 0.2 x +
 * 0.1 y, not a parallelogram, so its (u,v) are not affine in the plane's
 * points) whose shader only bends N: every cell is undisplaced, and the
 * patch's closed form (a quadratic) intersects it exactly; every hit at
 * the plane's depth */
static const double QUAD[4][2] = {{-1.0, -1.0}, {1.0, -0.8}, {1.1, 0.9}, {-0.7, 1.0}};

static double plane_z(double x, double y) { return DEPTH + 0.2 * x + 0.1 * y; }

/* (x, y) inside the convex quad QUAD (counter-clockwise), at least m from
 * its edges */
static bool in_quad(double x, double y, double m)
{
    for (int i = 0; i < 4; i++) {
        const double *a = QUAD[i], *b = QUAD[(i + 1) % 4];
        double ex = b[0] - a[0], ey = b[1] - a[1], len = sqrt(ex * ex + ey * ey);
        if ((ex * (y - a[1]) - ey * (x - a[0])) / len < m) return false;
    }
    return true;
}

static expect planar_quad(vec3 d, double *zexp)
{
    /* t d.z = 3 + 0.2 t d.x + 0.1 t d.y */
    double t = DEPTH / (d.z - 0.2 * d.x - 0.1 * d.y);
    if (!in_quad(t * d.x, t * d.y, 0.03))
        return in_quad(t * d.x, t * d.y, -0.03) ? EXPECT_SKIP : EXPECT_MISS;
    *zexp = t * d.z;
    return EXPECT_HIT;
}

static void test_patch_bent_normals_exact(void **state)
{
    (void)state;
    char rib[1024];
    /* RIB order: (u, v) = (0, 0), (1, 0), (0, 1), (1, 1) */
    const int order[4] = {0, 1, 3, 2};
    int len = snprintf(rib, sizeof rib,
                       "Format 48 48 1\nProjection \"perspective\" \"fov\" [45]\n"
                       "WorldBegin\nDisplacement \"%%s\"\nPatch \"bilinear\" \"P\" [");
    for (int k = 0; k < 4; k++) {
        const double *q = QUAD[order[k]];
        len += snprintf(rib + len, sizeof rib - (size_t)len, " %.17g %.17g %.17g", q[0], q[1],
                        plane_z(q[0], q[1]));
    }
    snprintf(rib + len, sizeof rib - (size_t)len, "]\nWorldEnd\n");
    fixture f;
    assert_true(fixture_open_named(&f, rib, "bumponly", BUMP_SL));
    exact_scan s;
    scan_exact(&f, planar_quad, &s);
    printf("bilinear patch, bent normals: %d/%d hit, %d at the plane's depth, %d hits off it; "
           "exact cells %ld, boxes %ld, proofs %ld\n", s.hits, s.inside, s.exact, s.outside_hits,
           s.st.exact_cells, s.st.boxes, s.st.proofs);
    assert_all_exact(&s);
    fixture_close(&f);
}

static const char *OBJBUMP_SL =
    "displacement objbump(float Kb = 0.02)\n"
    "{\n"
    "    point Po = transform(\"object\", P);\n"
    "    N = calculatenormal(P + Kb * noise(Po * 4) * normalize(N));\n"
    "}\n";

/* Three instances of a sphere whose shader only bends N (from object-space
 * noise, so the placements share the prototype's boxes: trace/instance.c),
 * moved and turned: every cell of every instance is undisplaced and each
 * is intersected exactly on its own base (the walk's ray is in the
 * object space the shared boxes are in); every hit at the nearest
 * sphere's depth */
#define NINST 3
static const double INST_X[NINST] = {-1.9, 0.0, 1.9};

static expect sphere_instances(vec3 d, double *zexp)
{
    /* the nearest of the spheres |p - (x_i, 0, 4)| = 0.8 along t d */
    double tbest = INFINITY;
    for (int i = 0; i < NINST; i++) {
        /* the ray's distance from the centre: near 0.8, a silhouette */
        vec3 cen = v3(INST_X[i], 0, 4);
        double dist = v3_length(v3_cross(cen, d)) / v3_length(d);
        if (fabs(dist - 0.8) < 0.04) return EXPECT_SKIP;
        if (dist >= 0.8) continue;
        double a = v3_dot(d, d), b = -2.0 * v3_dot(cen, d), cc = v3_dot(cen, cen) - 0.64,
               disc = b * b - 4 * a * cc;
        tbest = fmin(tbest, (-b - sqrt(disc)) / (2 * a));
    }
    if (!isfinite(tbest)) return EXPECT_MISS;
    *zexp = tbest * d.z;
    return EXPECT_HIT;
}

static void test_instances_bent_normals_exact(void **state)
{
    (void)state;
    char rib[2048];
    int len = snprintf(rib, sizeof rib,
                       "Format 96 40 1\nProjection \"perspective\" \"fov\" [45]\n"
                       "Translate 0 0 4\nWorldBegin\nDisplacement \"%%s\"\n"
                       "ObjectBegin 1\n  Sphere 0.8 -0.8 0.8 360\nObjectEnd\n");
    for (int i = 0; i < NINST; i++)
        len += snprintf(rib + len, sizeof rib - (size_t)len,
                        "AttributeBegin\n  Translate %g 0 0\n  Rotate %d 0.3 1 0.2\n"
                        "  ObjectInstance 1\nAttributeEnd\n", INST_X[i], 40 * i + 10);
    snprintf(rib + len, sizeof rib - (size_t)len, "WorldEnd\n");
    fixture f;
    assert_true(fixture_open_named(&f, rib, "objbump", OBJBUMP_SL));
    int shared = fixture_count_shared(&f.js->world);
    exact_scan s;
    scan_exact(&f, sphere_instances, &s);
    printf("instances, bent normals: %d share the prototype's boxes; %d/%d hit, %d at the "
           "sphere's depth, %d hits off them; exact cells %ld, boxes %ld, proofs %ld\n", shared,
           s.hits, s.inside, s.exact, s.outside_hits, s.st.exact_cells, s.st.boxes, s.st.proofs);
    assert_int_equal(shared, NINST - 1);
    assert_all_exact(&s);
    /* one root's children for the prototype, the placements none: every
     * cell settled at the first level */
    assert_true(s.st.boxes <= 4);
    fixture_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flat_exact_and_wedge_open),
        cmocka_unit_test(test_any_displacement_is_not_undisplaced),
        cmocka_unit_test(test_varying_displacement_is_not_offset),
        cmocka_unit_test(test_raised_wedge_offset_exact),
        cmocka_unit_test(test_rounded_constant_is_offset),
        cmocka_unit_test(test_fresh_symbol_variation_is_not_offset),
        cmocka_unit_test(test_ramp_planar_exact),
        cmocka_unit_test(test_sphere_bent_normals_exact),
        cmocka_unit_test(test_patch_bent_normals_exact),
        cmocka_unit_test(test_instances_bent_normals_exact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

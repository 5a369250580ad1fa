/*
 * test_trace_mesh_scale.c: a mesh is one object (issue 23).
 *
 * - Bytes per face, counted by the allocator (glibc's mallinfo2, not the
 *   code's own accounting): a torus of 20,000 quads (40,000 triangles,
 *   curved: each quad is cut in two with vertex normals), parsed and made
 *   into a renderable world, must hold at most FACE_BYTES per face in all
 *   (the shared points, indices and normals, the pieces, their boxes,
 *   shared edges and BVH). When every piece was an object of its own the
 *   same mesh took ~28 KB a face.
 * - The mesh renders the same image as the same faces written as one
 *   Polygon each (the old path: an object per face): a flat grid whose
 *   faces stay polygons, so both give the same surfaces to the bit, seen
 *   through the mesh's BVH, views and hit copies on one side and the
 *   object BVH on the other.
 * - Instances place the one recorded mesh: 50 instances of a 2,000-face
 *   mesh cost a fraction of 50 copies.
 * - Instances are references (trace/group.h): 300 instances of a mesh and
 *   a sphere, each with its own colour, some scaled unevenly, some
 *   mirrored, render as the same objects written out one by one (objects
 *   of their own: the other path); 20,000 instances cost at most
 *   INSTANCE_BYTES each in all (scene, world, renderer), counted by the
 *   allocator (an instance was ~14 KB when each was a full object; ~380 now).
 * - A shadow ray cast while a piece's hit is being shaded cannot
 *   overwrite it: a mesh lit through another mesh renders as the same
 *   faces written one Polygon each.
 */
#include <malloc.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fixture.h"
#include "trace/bvh.h"
#include "trace/camera.h"
#include "trace/lazy_roots.h"
#include "trace/mesh.h"
#include "trace/render.h"
#include "scene/scene_mesh.h"

/* the budgets per face of a curved quad mesh (issue 23): beyond the
 * scene's shared arrays (~64 bytes: a point, a normal, 4 indices), <= 64
 * bytes before any box (its two 16-byte pieces and their shared edges)
 * and <= 32 of BVH; and everything the worker holds, the shared arrays
 * included, counted by the allocator */
enum { FACE_BYTES_BEYOND = 64 + 32, FACE_BVH_BYTES = 32, FACE_BYTES = 150 };

/* the budget per instance of a recorded mesh, everything included: the
 * scene's object (216 bytes, its transform in double, its attributes
 * shared: scene_attributes), the world's 6-byte box, index and BVH share
 * (~20), and its RIB text in the job (~150): 382 measured (2026-11-28) */
enum { INSTANCE_BYTES = 420 };

static void test_bytes_per_face(void **state)
{
    (void)state;
    enum { NU = 200, NV = 100 };
    char *rib = fixture_torus_rib(NU, NV, "", "PointsPolygons");
    job_options opt;
    job_options_default(&opt);
    job *jb = job_new("torus.rib", rib, strlen(rib), &opt);
    free(rib);
    char err[256];
    assert_true(job_finish(jb, err, sizeof err));
    sl_diag *d = sl_diag_new();
    size_t before = fixture_heap_bytes();
    job_scene *js = job_scene_new(jb, 0, true, NULL, d);
    size_t after = fixture_heap_bytes();
    if (!js) sl_diag_print(d, stderr);
    assert_non_null(js);
    assert_int_equal(js->scene->nobjects, 1);
    assert_int_equal(js->world.nobjects, 1);
    assert_int_equal(trace_object_npieces(&js->world.objects[0]), 2 * NU * NV);
    const scene_mesh *sm = js->scene->meshes[0];
    const trace_mesh *m = js->world.objects[0].mesh;
    double bvh = (double)trace_float_bvh_bytes(m->bvh, m->npieces) / (NU * NV);
    printf("torus of %d quads (%d pieces): BVH %.1f bytes per face (budget %d)\n", NU * NV,
           2 * NU * NV, bvh, FACE_BVH_BYTES);
    assert_true(bvh <= FACE_BVH_BYTES);
    size_t shared = scene_mesh_bytes(sm) - scene_mesh_piece_bytes(sm);
    if (after > before + shared) {
        double per_face = (double)(after - before) / (NU * NV);
        double beyond = (double)(after - before - shared) / (NU * NV);
        printf("%zu bytes held, %.1f bytes per face (budget %d), beyond the shared arrays "
               "%.1f (budget %d)\n", after - before, per_face, FACE_BYTES, beyond,
               FACE_BYTES_BEYOND);
        assert_true(per_face <= FACE_BYTES);
        assert_true(beyond <= FACE_BYTES_BEYOND);
    } else {
        /* a sanitizer's allocator: mallinfo2 counts nothing */
        printf("the heap is not counted here (%zu -> %zu bytes): budgets of the whole not "
               "checked\n", before, after);
    }
    /* and it renders: the torus covers the middle of the image */
    trace_thread *th = trace_thread_new(&js->world);
    double rgb[3], a, z;
    trace_render_sample(js->renderer, th, 16.5, 12.5, rgb, &a, &z);
    assert_true(a == 1.0);
    assert_true(th->stats.views_made > 0);
    trace_thread_destroy(&th);
    job_scene_destroy(&js);
    job_destroy(&jb);
    sl_diag_destroy(&d);
}

/* A flat grid of n x n unit quads at z = 0, as one mesh or one Polygon
 * each, with a point light and a sphere between them casting a shadow
 * (shadow rays during shading), an optional displacement. */
static char *grid_rib(int n, bool mesh, const char *disp)
{
    size_t cap = (size_t)n * n * 200 + 4096, len = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    len += (size_t)snprintf(t + len, cap - len,
                            "Format 48 48 1\nProjection \"perspective\" \"fov\" [50]\n"
                            "PixelSamples 2 2\nTranslate 0 0 %g\nRotate -30 1 0 0\nWorldBegin\n"
                            "Attribute \"light\" \"shadows\" [\"on\"]\n"
                            "LightSource \"pointlight\" 1 \"from\" [1 1 -3] \"intensity\" [12]\n"
                            "LightSource \"ambientlight\" 2 \"intensity\" [0.1]\n"
                            "Surface \"shiny\"\n"
                            "AttributeBegin\nTranslate 0.2 0.1 -0.6\nSphere 0.35 -0.35 0.35 360\n"
                            "AttributeEnd\n%s\n", 1.1 * n, disp);
    double h = n / 2.0;
    if (mesh) {
        len += (size_t)snprintf(t + len, cap - len, "PointsPolygons [");
        for (int i = 0; i < n * n; i++) len += (size_t)snprintf(t + len, cap - len, "4 ");
        len += (size_t)snprintf(t + len, cap - len, "] [");
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int a = j * (n + 1) + i;
                len += (size_t)snprintf(t + len, cap - len, "%d %d %d %d ", a, a + 1,
                                        a + n + 2, a + n + 1);
            }
        len += (size_t)snprintf(t + len, cap - len, "] \"P\" [");
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++)
                len += (size_t)snprintf(t + len, cap - len, "%g %g 0 ", i - h, j - h);
        len += (size_t)snprintf(t + len, cap - len, "]\n");
    } else {
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++)
                len += (size_t)snprintf(t + len, cap - len,
                                        "Polygon \"P\" [%g %g 0  %g %g 0  %g %g 0  %g %g 0]\n",
                                        i - h, j - h, i + 1 - h, j - h, i + 1 - h, j + 1 - h,
                                        i - h, j + 1 - h);
    }
    snprintf(t + len, cap - len, "WorldEnd\n");
    return t;
}

static const char *LIFT_SL =
    "displacement lift(float Km = 0.15)\n"
    "{\n"
    "    P += Km * sin(3 * xcomp(P)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* lit with shadows (the light's shadow rays run while the hit is shaded) */
static const char *SHINY_SL =
    "surface shiny(float Kd = 0.7, Ks = 0.4, roughness = 0.15)\n"
    "{\n"
    "    normal Nf = faceforward(normalize(N), I);\n"
    "    vector V = -normalize(I);\n"
    "    color c = 0;\n"
    "    illuminance(P, Nf, PI / 2) {\n"
    "        vector Ln = normalize(L);\n"
    "        c += Cl * (Kd * (Nf . Ln) + Ks * pow(max(0, Nf . normalize(Ln + V)), 1 / roughness));\n"
    "    }\n"
    "    Oi = Os;\n"
    "    Ci = Os * (Cs * (ambient() + c) + s * 0.2);\n"
    "}\n";

static void render_grid(int n, bool mesh, const char *disp, float *rgba)
{
    char *rib = grid_rib(n, mesh, disp);
    fixture f;
    fixture_shader sh[] = {{"lift", LIFT_SL}, {"shiny", SHINY_SL}};
    assert_true(fixture_open(&f, rib, sh, 2, NULL, 0));
    free(rib);
    assert_int_equal(f.js->world.nobjects, mesh ? 2 : 1 + n * n);
    float *z = malloc(sizeof *z * 48 * 48);
    assert_true(fixture_render(&f, 16, 2, 0, rgba, z));
    free(z);
    fixture_close(&f);
}

static void compare_grids(const char *disp)
{
    enum { N = 24, PX = 48 * 48 * 4 };   /* more pieces than a thread keeps views */
    float *a = malloc(sizeof *a * PX), *b = malloc(sizeof *b * PX);
    render_grid(N, true, disp, a);
    render_grid(N, false, disp, b);
    int differ = 0, lit = 0, covered = 0;
    for (int i = 0; i < PX; i++) differ += a[i] != b[i];
    for (int i = 0; i < PX; i += 4) {
        lit += a[i] > 0.2f;
        covered += a[i + 3] == 1.0f;
    }
    printf("grid %dx%d%s: %d of %d values differ; %d pixels lit, %d covered\n", N, N,
           disp[0] ? " (displaced)" : "", differ, PX, lit, covered);
    assert_true(covered > 48 * 48 / 2);     /* the grid fills most of the image */
    assert_true(lit > 100);
    assert_int_equal(differ, 0);
    free(a);
    free(b);
}

static void test_mesh_renders_as_its_faces(void **state)
{
    (void)state;
    compare_grids("");
}

static void test_displaced_mesh_renders_as_its_faces(void **state)
{
    (void)state;
    /* a flat grid's faces stay polygons with one normal: the same
     * displaced surfaces, box trees and hits on both sides */
    compare_grids("Displacement \"lift\"");
}

/* The hit a traversal returns, and the hit being shaded, are copies: the
 * thread's view cache turning over (every piece made once more) leaves
 * both as they were. */
static void test_hits_outlive_the_view_cache(void **state)
{
    (void)state;
    char *rib = fixture_torus_rib(40, 30, "", "PointsPolygons");
    fixture f;
    assert_true(fixture_open(&f, rib, NULL, 0, NULL, 0));
    free(rib);
    const trace_object *mesh = &f.js->world.objects[0];
    assert_non_null(mesh->mesh);
    trace_thread *th = trace_thread_new(&f.js->world);
    trace_ray ray;
    trace_camera_ray(&f.js->world.camera, 16.5, 12.5, &ray);
    trace_hit hit = {.t = ray.tmax, .obj = NULL};
    assert_true(trace_bvh_intersect(f.js->renderer->bvh, th, &ray, &f.js->renderer->primary_tol,
                                    false, &hit));
    int id = hit.obj->id;
    assert_true(id >= mesh->mesh->first_id);
    geom_surface *surf = malloc(sizeof *surf);
    *surf = hit.obj->surf;
    const trace_object *held = trace_view_hold(th, hit.obj, 0);
    assert_ptr_not_equal(held, hit.obj);
    for (int k = 0; k < trace_object_npieces(mesh); k++)
        assert_non_null(trace_mesh_view(th, mesh, k));
    assert_int_equal(hit.obj->id, id);
    assert_memory_equal(&hit.obj->surf, surf, sizeof *surf);
    /* another traversal overwrites the hit slot, never the held copy */
    trace_camera_ray(&f.js->world.camera, 8.5, 20.5, &ray);
    trace_hit other = {.t = ray.tmax, .obj = NULL};
    assert_true(trace_bvh_intersect(f.js->renderer->bvh, th, &ray, &f.js->renderer->primary_tol,
                                    false, &other));
    assert_int_not_equal(other.obj->id, id);
    assert_int_equal(held->id, id);
    assert_memory_equal(&held->surf, surf, sizeof *surf);
    free(surf);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* Three instances of a recorded undisplaced mesh share one trace_mesh
 * (its boxes and BVH in object space) and render as three copies of the
 * mesh written out, each with its own; and, as they lie apart on the
 * screen, as the sum of three renders of one instance each (an oracle
 * that shares nothing between the objects). */
enum { IW = 64, IH = 32, IPX = IW * IH * 4 };

static const char *const PLACES[3] = {"Translate -2.2 0 0\nRotate 30 0 1 0\nScale 0.5 0.5 0.5",
                                      "Translate 0 0.1 0\nRotate -50 1 0 0\nScale 0.5 0.5 0.5",
                                      "Translate 2.2 -0.1 0\nScale 0.45 0.45 0.45"};

/* the torus recorded once and instanced at the places in `which` (mask),
 * or (copies) written out at each */
static char *places_rib(const char *mesh, unsigned which, bool copies)
{
    size_t cap = strlen(mesh) * 4 + 4096, n = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    n += (size_t)snprintf(t + n, cap - n, "Format %d %d 1\nProjection \"perspective\" \"fov\" "
                          "[50]\nTranslate 0 0 5\nWorldBegin\nLightSource \"distantlight\" 1 "
                          "\"from\" [0 1 -1] \"to\" [0 0 0]\n", IW, IH);
    if (!copies) n += (size_t)snprintf(t + n, cap - n, "ObjectBegin 7\n%sObjectEnd\n", mesh);
    for (int i = 0; i < 3; i++)
        if (which & (1u << i))
            n += (size_t)snprintf(t + n, cap - n, "AttributeBegin\n%s\n%s\nAttributeEnd\n",
                                  PLACES[i], copies ? mesh : "ObjectInstance 7");
    snprintf(t + n, cap - n, "WorldEnd\n");
    return t;
}

static void render_places(const char *mesh, unsigned which, bool copies, float *rgba,
                          int *nmeshes)
{
    char *rib = places_rib(mesh, which, copies);
    fixture f;
    assert_true(fixture_open(&f, rib, NULL, 0, NULL, 0));
    free(rib);
    const trace_world *w = &f.js->world;
    *nmeshes = 0;
    for (int i = 0; i < w->nobjects; i++) {
        bool seen = !w->objects[i].mesh;       /* a group's placements: its prototype's */
        for (int j = 0; j < i; j++) seen |= w->objects[j].mesh == w->objects[i].mesh;
        *nmeshes += !seen;
    }
    float *z = malloc(sizeof *z * IW * IH);
    assert_true(fixture_render(&f, 16, 2, 0, rgba, z));
    free(z);
    fixture_close(&f);
}

static void test_instances_render_as_copies(void **state)
{
    (void)state;
    char *torus = fixture_torus_rib(30, 20, "", "PointsPolygons");
    char *pp = strstr(torus, "PointsPolygons"), *we = strstr(torus, "WorldEnd");
    *we = '\0';
    float *inst = malloc(sizeof *inst * IPX), *copies = malloc(sizeof *copies * IPX);
    float *one = malloc(sizeof *one * IPX), *sum = calloc(IPX, sizeof *sum);
    int nm;
    render_places(pp, 7, false, inst, &nm);
    assert_int_equal(nm, 1);                /* one trace_mesh for the three */
    render_places(pp, 7, true, copies, &nm);
    assert_int_equal(nm, 3);
    for (int i = 0; i < 3; i++) {
        render_places(pp, 1u << i, false, one, &nm);
        for (int k = 0; k < IPX; k++) sum[k] += one[k];
    }
    int differ = 0, apart = 0, covered = 0;
    for (int k = 0; k < IPX; k++) {
        differ += inst[k] != copies[k];
        apart += inst[k] != sum[k];
    }
    for (int k = 3; k < IPX; k += 4) covered += inst[k] > 0;
    printf("3 instances: %d of %d values differ from 3 copies, %d from the sum of single "
           "renders; %d pixels covered\n", differ, IPX, apart, covered);
    assert_true(covered > 150);
    assert_int_equal(differ, 0);
    assert_int_equal(apart, 0);
    free(inst);
    free(copies);
    free(one);
    free(sum);
    free(torus);
}

/* A displaced mesh's root boxes made by several threads are those one
 * thread makes, to the bit (trace_options.build_threads). */
static void test_boxes_by_threads(void **state)
{
    (void)state;
    /* 12,000 pieces: enough for the pieces' pass to take 2 threads of the 4
     * (world.c), and for the displaced roots' */
    enum { NU = 100, NV = 60 };
    for (int displaced = 0; displaced < 2; displaced++) {
        char *rib = fixture_torus_rib(NU, NV, displaced ? "Displacement \"lift\"\n" : "",
                                      "PointsPolygons");
        job_options opt;
        job_options_default(&opt);
        job *jb = job_new("torus.rib", rib, strlen(rib), &opt);
        free(rib);
        char err[256];
        assert_true(job_add_source(jb, "lift.sl", LIFT_SL, strlen(LIFT_SL), err, sizeof err));
        assert_true(job_add_shader(jb, "lift", "lift.sl", err, sizeof err));
        assert_true(job_finish(jb, err, sizeof err));
        job_scene *js[2];
        for (int i = 0; i < 2; i++) {
            sl_diag *d = sl_diag_new();
            js[i] = job_scene_new_threads(jb, 0, true, i == 0 ? 1 : 4, NULL, d);
            if (!js[i]) sl_diag_print(d, stderr);
            assert_non_null(js[i]);
            sl_diag_destroy(&d);
        }
        const trace_mesh *a = js[0]->world.objects[0].mesh, *b = js[1]->world.objects[0].mesh;
        size_t n = (size_t)a->npieces;
        assert_int_equal(a->npieces, 2 * NU * NV);
        if (displaced) {
            /* the root boxes made while building (none where the regions
             * bound the pieces: made when a ray reaches them) */
            assert_non_null(a->lazy);
            assert_non_null(b->lazy);
            for (size_t k = 0; k < n; k++) {
                double da[2], db[2];
                trace_box ra, rb;
                bool ha = trace_lazy_root(a->lazy, (int)k, &ra, da);
                bool hb = trace_lazy_root(b->lazy, (int)k, &rb, db);
                assert_true(ha == hb);
                if (ha) assert_memory_equal(&ra, &rb, sizeof ra);
                if (ha) assert_memory_equal(da, db, sizeof da);
            }
        }
        assert_true(trace_float_bvh_equal(a->bvh, b->bvh, a->npieces));
        /* the closed torus: every piece's three edges are another's */
        int shared = 0;
        for (int k = 0; k < a->npieces; k++) {
            uint64_t e = trace_mesh_shared_edges(a, k);
            shared += __builtin_popcountll(e);
            assert_true(e == trace_mesh_shared_edges(b, k));
        }
        assert_int_equal(shared, 3 * a->npieces);
        printf("%d %s pieces: the same boxes and shared edges from 1 and 4 threads\n",
               a->npieces, displaced ? "displaced" : "undisplaced");
        for (int i = 0; i < 2; i++) job_scene_destroy(&js[i]);
        job_destroy(&jb);
    }
}

/* Two 12-sided faces of a PointsPolygons sharing their 11th edge (from
 * corner 10 to 11): a piece's edges past the 8th are kept apart from its
 * byte (trace_mesh_mark_edge) and must still be found. */
static void test_wide_faces_share_their_edges(void **state)
{
    (void)state;
    char rib[4096];
    size_t n = (size_t)snprintf(rib, sizeof rib, "Format 32 32 1\nProjection \"perspective\" "
                                "\"fov\" [40]\nTranslate 0 0 6\nWorldBegin\nPointsPolygons [12 12] [");
    for (int i = 0; i < 24; i++) n += (size_t)snprintf(rib + n, sizeof rib - n, "%d ", i);
    n += (size_t)snprintf(rib + n, sizeof rib - n, "] \"P\" [");
    /* a regular 12-gon, and its mirror image across the line through
     * corners 10 and 11 (which stay where they are) */
    double x[12], y[12];
    for (int i = 0; i < 12; i++) x[i] = cos(2 * M_PI * i / 12), y[i] = sin(2 * M_PI * i / 12);
    double ax = x[10], ay = y[10], dx = x[11] - ax, dy = y[11] - ay, dd = dx * dx + dy * dy;
    for (int f = 0; f < 2; f++)
        for (int i = 0; i < 12; i++) {
            double px = x[i], py = y[i];
            if (f == 1 && i != 10 && i != 11) {
                double t = ((px - ax) * dx + (py - ay) * dy) / dd;
                px = 2 * (ax + t * dx) - px;
                py = 2 * (ay + t * dy) - py;
            }
            n += (size_t)snprintf(rib + n, sizeof rib - n, "%.17g %.17g 0 ", px, py);
        }
    snprintf(rib + n, sizeof rib - n, "]\nWorldEnd\n");
    job_options opt;
    job_options_default(&opt);
    job *jb = job_new("wide.rib", rib, strlen(rib), &opt);
    char err[256];
    assert_true(job_finish(jb, err, sizeof err));
    sl_diag *d = sl_diag_new();
    job_scene *js = job_scene_new(jb, 0, true, NULL, d);
    if (!js) sl_diag_print(d, stderr);
    assert_non_null(js);
    const trace_mesh *m = js->world.objects[0].mesh;
    assert_non_null(m);
    assert_int_equal(m->npieces, 2);
    for (int k = 0; k < 2; k++) {
        uint64_t e = trace_mesh_shared_edges(m, k);
        printf("12-gon %d: shared edges %#llx\n", k, (unsigned long long)e);
        assert_true(e == (uint64_t)1 << 10);
    }
    job_scene_destroy(&js);
    sl_diag_destroy(&d);
    job_destroy(&jb);
}

/* A mesh of every kind of piece: a flat grid of jittered quads (whole
 * polygons), some with a corner repeated (3 distinct corners of 4), some
 * pentagons, some concave (cut into triangles), beside a bumpy grid whose
 * quads are curved or not planar (triangles with corner normals), and a
 * Polygon sharing an edge with the flat grid. */
static char *mixed_rib(void)
{
    enum { N = 40 };
    size_t cap = 1 << 20, n = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    n += (size_t)snprintf(t + n, cap - n, "Format 32 32 1\nProjection \"perspective\" \"fov\" "
                          "[40]\nTranslate 0 0 8\nWorldBegin\n");
    for (int bumpy = 0; bumpy < 2; bumpy++) {
        n += (size_t)snprintf(t + n, cap - n, "AttributeBegin\nTranslate %d 0 0\nPointsPolygons [",
                              bumpy ? 3 : -3);
        for (int f = 0; f < (N - 1) * (N - 1); f++)
            n += (size_t)snprintf(t + n, cap - n, "%d ", !bumpy && f % 13 == 5 ? 5 : 4);
        n += (size_t)snprintf(t + n, cap - n, "] [");
        for (int i = 0; i + 1 < N; i++)
            for (int j = 0; j + 1 < N; j++) {
                int f = i * (N - 1) + j, a = i * N + j, b = a + 1, c = a + N + 1, d = a + N;
                if (!bumpy && f % 13 == 5)           /* a pentagon: the quad's centre too */
                    n += (size_t)snprintf(t + n, cap - n, "%d %d %d %d %d ", a, b, c, d, N * N + f);
                else if (!bumpy && f % 7 == 3)       /* a corner repeated */
                    n += (size_t)snprintf(t + n, cap - n, "%d %d %d %d ", a, b, b, c);
                else
                    n += (size_t)snprintf(t + n, cap - n, "%d %d %d %d ", a, b, c, d);
            }
        n += (size_t)snprintf(t + n, cap - n, "] \"P\" [");
        for (int i = 0; i < N; i++)
            for (int j = 0; j < N; j++) {
                double x = 4.0 * j / (N - 1) - 2, y = 4.0 * i / (N - 1) - 2, z = 0;
                if (bumpy) {
                    z = 0.3 * sin(3 * x) * cos(2 * y) + ((i * 7 + j * 3) % 5 == 0 ? 0.05 : 0);
                } else if (i > 0 && j > 0 && i + 1 < N && j + 1 < N) {
                    /* jittered; every 17th far enough to make its faces concave */
                    double k = (i * N + j) % 17 == 0 ? 0.9 : 0.2;
                    x += k * 4.0 / (N - 1) * sin(i * 12.9898 + j * 78.233);
                    y += k * 4.0 / (N - 1) * cos(i * 39.346 + j * 11.135);
                }
                n += (size_t)snprintf(t + n, cap - n, "%.17g %.17g %.17g ", x, y, z);
            }
        if (!bumpy)                                  /* the pentagons' centres (beyond the grid) */
            for (int f = 0; f < (N - 1) * (N - 1); f++) {
                int i = f / (N - 1), j = f % (N - 1);
                n += (size_t)snprintf(t + n, cap - n, "%.17g %.17g 0 ",
                                      4.0 * (j + 0.5) / (N - 1) - 2 - 0.3 * 4.0 / (N - 1),
                                      4.0 * (i + 0.5) / (N - 1) - 2);
            }
        n += (size_t)snprintf(t + n, cap - n, "]\nAttributeEnd\n");
    }
    /* a Polygon on the flat grid's first edge (corners 0 and 1), outside it */
    n += (size_t)snprintf(t + n, cap - n, "AttributeBegin\nTranslate -3 0 0\nPolygon \"P\" "
                          "[-2 -2 0  %.17g -2 0  -1.9 -2.5 0]\nAttributeEnd\nWorldEnd\n",
                          4.0 / (N - 1) - 2);
    assert_true(n < cap);
    return t;
}

/* The world's pass over a mesh's pieces reads their outlines (trace_mesh.
 * outline: the flat polygon's basis alone): the pieces' bounds and shared
 * edges are those the full pieces give, to the bit, for every kind of
 * piece and any thread count. */
static void test_outlines_give_the_pieces_bounds_and_edges(void **state)
{
    (void)state;
    char *rib = mixed_rib();
    job_options opt;
    job_options_default(&opt);
    job *jb = job_new("mixed.rib", rib, strlen(rib), &opt);
    free(rib);
    char err[256];
    assert_true(job_finish(jb, err, sizeof err));
    uint64_t first = 0;
    for (int threads = 1; threads <= 3; threads += 2) {
        sl_diag *d = sl_diag_new();
        job_scene *js = job_scene_new_threads(jb, 0, true, threads, NULL, d);
        if (!js) sl_diag_print(d, stderr);
        assert_non_null(js);
        trace_world *w = &js->world;
        trace_renderer_destroy(&js->renderer);
        /* the pass, with the outlines and with the full pieces */
        float (*bounds[2][2])[6] = {{NULL}};
        uint64_t *edges[2][2] = {{NULL}};
        int meshes = 0, kinds[3] = {0, 0, 0}, shared = 0, npieces[2] = {0, 0};
        for (int pass = 0; pass < 2; pass++) {
            assert_true(trace_world_prepare(w, err, sizeof err));
            int j = 0;
            for (int i = 0; i < w->nobjects; i++) {
                trace_mesh *m = w->objects[i].mesh;
                if (!m) continue;
                assert_true(j < 2);
                assert_true(pass == 1 || m->outline != NULL);
                npieces[j] = m->npieces;
                size_t b = sizeof *m->bounds * (size_t)m->npieces;
                bounds[pass][j] = malloc(b);
                edges[pass][j] = malloc(sizeof(uint64_t) * (size_t)m->npieces);
                memcpy(bounds[pass][j], m->bounds, b);
                for (int k = 0; k < m->npieces; k++)
                    edges[pass][j][k] = trace_mesh_shared_edges(m, k);
                m->outline = NULL;     /* the next pass: the full pieces */
                j++;
            }
            meshes = j;
        }
        assert_int_equal(meshes, 2);
        for (int j = 0; j < meshes; j++) {
            for (int k = 0; k < npieces[j]; k++) {
                if (memcmp(bounds[0][j][k], bounds[1][j][k], sizeof bounds[0][j][k]) != 0)
                    fail_msg("mesh %d piece %d: its outline's bounds differ from its surface's",
                             j, k);
                if (edges[0][j][k] != edges[1][j][k])
                    fail_msg("mesh %d piece %d: shared edges %#llx from its outline, %#llx from "
                             "its surface", j, k, (unsigned long long)edges[0][j][k],
                             (unsigned long long)edges[1][j][k]);
                shared += __builtin_popcountll(edges[0][j][k]);
            }
            free(bounds[0][j]);
            free(bounds[1][j]);
            free(edges[0][j]);
            free(edges[1][j]);
        }
        /* the world as built, its digest the same for any thread count */
        js->renderer = trace_renderer_new(w, err, sizeof err);
        assert_non_null(js->renderer);
        uint64_t digest = 0;
        for (int i = 0; i < w->nobjects; i++) {
            const trace_mesh *m = w->objects[i].mesh;
            if (!m) continue;
            digest ^= trace_mesh_digest(m);
            for (int k = 0; k < m->npieces; k++) {
                geom_surface *s = malloc(sizeof *s);
                int npv;
                assert_non_null(s);
                assert_true(m->piece(m->user, &w->objects[i], k, s, NULL, &npv));
                kinds[s->nuv == 3 ? (s->nvn ? 1 : 0) : 2]++;
                free(s);
            }
        }
        if (threads == 1) first = digest;
        assert_true(digest == first);
        printf("%d threads: %d flat triangles, %d with corner normals, %d larger polygons; "
               "%d shared edges, the same from outlines and pieces\n", threads, kinds[0],
               kinds[1], kinds[2], shared);
        assert_true(kinds[0] > 0 && kinds[1] > 0 && kinds[2] > 0);
        assert_true(shared > 4 * 39 * 39);
        job_scene_destroy(&js);
        sl_diag_destroy(&d);
    }
    job_destroy(&jb);
}

static void test_instances_share_the_mesh(void **state)
{
    (void)state;
    enum { NU = 50, NV = 40, COPIES = 50 };
    /* the mesh recorded once, placed COPIES times */
    size_t cap = (size_t)NU * NV * 90 + 4096 + COPIES * 64;
    char *t = malloc(cap);
    char *torus = fixture_torus_rib(NU, NV, "", "PointsPolygons");
    /* fixture_torus_rib's text from "PointsPolygons" to "WorldEnd" */
    char *pp = strstr(torus, "PointsPolygons"), *we = strstr(torus, "WorldEnd");
    *we = '\0';
    size_t n = (size_t)snprintf(t, cap, "Format 32 32 1\nProjection \"perspective\" \"fov\" "
                                "[40]\nTranslate 0 0 30\nWorldBegin\nObjectBegin 1\n%s"
                                "ObjectEnd\n", pp);
    for (int i = 0; i < COPIES; i++)
        n += (size_t)snprintf(t + n, cap - n, "AttributeBegin\nTranslate %d %d 0\n"
                              "ObjectInstance 1\nAttributeEnd\n", i % 10 * 3 - 14, i / 10 * 3 - 6);
    snprintf(t + n, cap - n, "WorldEnd\n");
    free(torus);
    sl_diag *d = sl_diag_new();
    size_t before = fixture_heap_bytes();
    scene *s = scene_parse("inst.rib", t, strlen(t), d);
    size_t after = fixture_heap_bytes();
    if (!s) sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, COPIES);
    assert_int_equal(s->nmeshes, 1);
    for (int i = 1; i < COPIES; i++) assert_ptr_equal(s->objects[i].mesh, s->objects[0].mesh);
    /* undisplaced: its boxes are shared, its pieces count once */
    assert_int_equal(s->npieces, (long)2 * NU * NV);
    size_t one = scene_mesh_bytes(s->meshes[0]);
    printf("%d instances of a %d-face mesh: %zu bytes held (one mesh: %zu)\n", COPIES, NU * NV,
           after - before, one);
    assert_true(after - before < 3 * one);
    scene_destroy(&s);
    sl_diag_destroy(&d);
    free(t);
}

/* a 10 x 10 grid of quads with "st", bent a little, and a sphere */
static const char *REF_OBJECT_GRID_HEAD = "PointsPolygons [";

static char *ref_object(bool sphere)
{
    enum { G = 10 };
    size_t cap = 64 * 1024, n = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    n += (size_t)snprintf(t + n, cap - n, "%s", REF_OBJECT_GRID_HEAD);
    for (int i = 0; i < G * G; i++) n += (size_t)snprintf(t + n, cap - n, "4 ");
    n += (size_t)snprintf(t + n, cap - n, "] [");
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            int a = j * (G + 1) + i;
            n += (size_t)snprintf(t + n, cap - n, "%d %d %d %d ", a, a + 1, a + G + 2, a + G + 1);
        }
    n += (size_t)snprintf(t + n, cap - n, "] \"P\" [");
    for (int j = 0; j <= G; j++)
        for (int i = 0; i <= G; i++)
            n += (size_t)snprintf(t + n, cap - n, "%.6g %.6g %.6g ", i / (double)G - 0.5,
                                  j / (double)G - 0.5, 0.15 * sin(3.0 * i / G) * cos(2.0 * j / G));
    n += (size_t)snprintf(t + n, cap - n, "] \"varying float s\" [");
    for (int j = 0; j <= G; j++)
        for (int i = 0; i <= G; i++) n += (size_t)snprintf(t + n, cap - n, "%.6g ", i / (double)G);
    n += (size_t)snprintf(t + n, cap - n, "] \"varying float t\" [");
    for (int j = 0; j <= G; j++)
        for (int i = 0; i <= G; i++) n += (size_t)snprintf(t + n, cap - n, "%.6g ", j / (double)G);
    snprintf(t + n, cap - n, "]\n%s", sphere ? "Translate 0 0 -0.3\nSphere 0.2 -0.2 0.2 360\n" : "");
    return t;
}

/* k of n instances on a grid, each its own colour and motion: every
 * third scaled unevenly, every fifth mirrored (its normals flip) */
static size_t instance_text(char *t, size_t cap, int k, int n, const char *object)
{
    int side = (int)ceil(sqrt(n));
    double x = (k % side) - 0.5 * (side - 1), y = (k / side) - 0.5 * (side - 1);
    x *= 0.8, y *= 0.8;
    return (size_t)snprintf(t, cap, "AttributeBegin\nColor [%.3f %.3f %.3f]\nTranslate %g %g 0\n"
                            "Rotate %d 0.3 1 0.2\nScale 1.3 1.3 1.3\n%s%s%s\nAttributeEnd\n",
                            0.3 + 0.7 * (k % 7) / 6.0, 0.3 + 0.7 * (k % 5) / 4.0,
                            0.3 + 0.7 * (k % 3) / 2.0, x * 1.1, y * 1.1, (k * 37) % 360,
                            k % 3 == 0 ? "Scale 1 0.6 1.3\n" : "",
                            k % 5 == 0 ? "Scale -1 1 1\n" : "", object);
}

static char *instances_rib(int n, int res, bool copies, bool sphere)
{
    char *object = ref_object(sphere);
    size_t cap = (copies ? strlen(object) + 256 : 256) * (size_t)n + strlen(object) + 4096, m = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    int side = (int)ceil(sqrt(n));
    m += (size_t)snprintf(t + m, cap - m, "Format %d %d 1\nProjection \"perspective\" \"fov\" "
                          "[40]\nTranslate 0 0 %g\nWorldBegin\nLightSource \"distantlight\" 1 "
                          "\"from\" [0 1 -1] \"to\" [0 0 0]\nSurface \"stc\"\nSides 1\nOrientation \"lh\"\n", res, res,
                          1.2 * side + 1.0);
    if (!copies) m += (size_t)snprintf(t + m, cap - m, "ObjectBegin \"ref\"\n%sObjectEnd\n", object);
    for (int k = 0; k < n; k++)
        m += instance_text(t + m, cap - m, k, n, copies ? object : "ObjectInstance \"ref\"");
    snprintf(t + m, cap - m, "WorldEnd\n");
    free(object);
    return t;
}

/* N's side shows (no faceforward, one-sided: a face turned away is not
 * seen), and with Orientation "lh" a mirrored instance's normals flip */
#define STC_SL                                                                  \
    "surface stc() {\n"                                                         \
    "    float d = normalize(N) . normalize(-I);\n"                             \
    "    Ci = Cs * color(s, t, 0.5) * (0.6 + 0.4 * d);\n"                       \
    "    Oi = 1;\n"                                                             \
    "}\n"

static const fixture_shader STC[] = {{"stc", STC_SL}};

/* the world's groups of placements (trace/group.h) and their placements */
static int count_placements(const trace_world *w, int *ngroups)
{
    int n = 0;
    *ngroups = 0;
    for (int i = 0; i < w->nobjects; i++)
        if (w->objects[i].group) {
            (*ngroups)++;
            n += w->objects[i].group->n;
        }
    return n;
}

static void render_instances(int n, bool copies, float *rgba, int *placements)
{
    enum { RES = 64 };
    char *rib = instances_rib(n, RES, copies, true);
    fixture f;
    assert_true(fixture_open(&f, rib, STC, 1, NULL, 0));
    free(rib);
    int ngroups;
    *placements = count_placements(&f.js->world, &ngroups);
    float *z = malloc(sizeof *z * RES * RES);
    assert_true(fixture_render(&f, 16, 2, 0, rgba, z));
    free(z);
    fixture_close(&f);
}

static void test_instances_are_references(void **state)
{
    (void)state;
    enum { N = 300, PX = 64 * 64 * 4 };
    float *inst = malloc(sizeof *inst * PX), *copies = malloc(sizeof *copies * PX);
    int placed, placed_copies;
    render_instances(N, false, inst, &placed);
    render_instances(N, true, copies, &placed_copies);
    /* both parts of every instance but the first are references */
    assert_int_equal(placed, 2 * (N - 1));
    assert_int_equal(placed_copies, 0);
    int differ = 0, covered = 0, colours = 0;
    for (int i = 0; i < PX; i++) differ += inst[i] != copies[i];
    for (int i = 0; i < PX; i += 4) {
        covered += inst[i + 3] > 0.0f;
        colours += i >= 4 && fabsf(inst[i] - inst[i - 4]) > 0.05f;
    }
    printf("%d instances (%d references): %d of %d values differ from the copies; %d pixels "
           "covered, %d colour changes\n", N, placed, differ, PX, covered, colours);
    assert_true(covered > 64 * 64 / 3);
    assert_true(colours > 200);
    assert_int_equal(differ, 0);
    free(inst);
    free(copies);
}

/* heap bytes held by a world built (and prepared) from n instances */
static size_t instances_bytes(int n)
{
    char *rib = instances_rib(n, 16, false, false);
    size_t before = fixture_heap_bytes();
    fixture f;
    assert_true(fixture_open(&f, rib, STC, 1, NULL, 0));
    size_t after = fixture_heap_bytes();
    fixture_close(&f);
    free(rib);
    return after - before;
}

static void test_bytes_per_instance(void **state)
{
    (void)state;
    enum { N = 20000 };
    size_t one = instances_bytes(1), many = instances_bytes(N);
    double per = (double)(many - one) / (N - 1);
    printf("%d instances: %zu bytes held, %zu for one: %.0f bytes per instance (budget %d)\n", N,
           many, one, per, INSTANCE_BYTES);
    assert_true(per <= INSTANCE_BYTES);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bytes_per_face),
        cmocka_unit_test(test_mesh_renders_as_its_faces),
        cmocka_unit_test(test_displaced_mesh_renders_as_its_faces),
        cmocka_unit_test(test_hits_outlive_the_view_cache),
        cmocka_unit_test(test_instances_render_as_copies),
        cmocka_unit_test(test_boxes_by_threads),
        cmocka_unit_test(test_wide_faces_share_their_edges),
        cmocka_unit_test(test_outlines_give_the_pieces_bounds_and_edges),
        cmocka_unit_test(test_instances_share_the_mesh),
        cmocka_unit_test(test_instances_are_references),
        cmocka_unit_test(test_bytes_per_instance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_trace_region_box.c: trace_mesh_region_box (trace/region.h, issue
 * 23), the one-run box of many pieces of a displaced mesh, against an
 * independent oracle.
 *
 * Meshes: a curved 8 x 8 grid (a saddle z = f(x, y)) as quads with
 * vertex normals "N" and "st" (the pieces are their triangles), as
 * triangles with neither (flat pieces), and as a Catmull-Clark cage with
 * "st" (the pieces its refined faces), displaced by corpus shaders of different kinds (noise, du/dv
 * filter widths, a texture() height map read through st, raw N, dPdu,
 * the globals u v I Ng, calculatenormal). For subsets of pieces
 * (contiguous runs, as a BVH node's, and random sets) the region box must
 * hold (a) every piece's own root box, made the existing way (the
 * world's build: one shader run per piece), and (b) displaced points of
 * every piece sampled with the renderer's point path
 * (trace_surface_point_eval, dual mode), mapped to object space. It
 * prints how loose the region is: its volume over that of the hull of
 * the pieces' root boxes (what a BVH node holds today) and to that of
 * the sampled points.
 *
 * (b) is asserted; (a) is counted and printed: the two are enclosures of
 * the same surface, each looser than the other in places, and a root box
 * pokes out of its region in about a sixth of the subsets (by up to a
 * third of its extent), where 33 x 33 samples of the piece find no
 * displaced point outside.
 *
 * A mesh whose primitive variable is a parameter of the displacement
 * shader is refused (false, the unbounded box), never a tight box.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>

#include "corpus.h"
#include "trace/displace.h"
#include "trace/mesh.h"
#include "trace/region.h"
#include "trace/render.h"

enum { GRID = 8 };

static corpus C;

static double height(double x, double y) { return 0.3 * (x * x - 0.6 * y * y) + 0.1 * x * y; }

enum { FLAT, SMOOTH, SUBDIV, NKINDS };
static const char *KIND_NAMES[NKINDS] = {"triangles", "quads", "subdiv"};

/* The grid over [-1,1]^2: PointsPolygons of quads with "N" and "st"
 * (SMOOTH), of triangles without (FLAT), or a Catmull-Clark cage of the
 * quads with "st" (SUBDIV) */
static void grid_rib(char *out, size_t size, int kind)
{
    bool smooth = kind != FLAT;
    size_t n = (size_t)snprintf(out, size, kind == SUBDIV ? "SubdivisionMesh \"catmull-clark\" ["
                                                          : "PointsPolygons [");
    for (int f = 0; f < GRID * GRID * (smooth ? 1 : 2); f++)
        n += (size_t)snprintf(out + n, size - n, "%d ", smooth ? 4 : 3);
    n += (size_t)snprintf(out + n, size - n, "] [");
    for (int j = 0; j < GRID; j++)
        for (int i = 0; i < GRID; i++) {
            int a = j * (GRID + 1) + i, b = a + 1, c = a + GRID + 2, d = a + GRID + 1;
            if (smooth)
                n += (size_t)snprintf(out + n, size - n, "%d %d %d %d  ", a, b, c, d);
            else
                n += (size_t)snprintf(out + n, size - n, "%d %d %d  %d %d %d  ", a, b, c, a, c, d);
        }
    n += (size_t)snprintf(out + n, size - n, kind == SUBDIV ? "] [\"interpolateboundary\"] [0 0] [] []"
                                                           " \"P\" ["  : "] \"P\" [");
    for (int j = 0; j <= GRID; j++)
        for (int i = 0; i <= GRID; i++) {
            double x = -1 + 2.0 * i / GRID, y = -1 + 2.0 * j / GRID;
            n += (size_t)snprintf(out + n, size - n, "%.17g %.17g %.17g  ", x, y, height(x, y));
        }
    n += (size_t)snprintf(out + n, size - n, "]\n");
    if (!smooth) return;
    if (kind == SMOOTH) {
        n += (size_t)snprintf(out + n, size - n, "  \"N\" [");
        for (int j = 0; j <= GRID; j++)
            for (int i = 0; i <= GRID; i++) {
                double x = -1 + 2.0 * i / GRID, y = -1 + 2.0 * j / GRID;
                double fx = 0.6 * x + 0.1 * y, fy = -0.36 * y + 0.1 * x;
                n += (size_t)snprintf(out + n, size - n, "%.17g %.17g 1  ", -fx, -fy);
            }
        n += (size_t)snprintf(out + n, size - n, "]\n");
    }
    n += (size_t)snprintf(out + n, size - n, "  \"st\" [");
    for (int j = 0; j <= GRID; j++)
        for (int i = 0; i <= GRID; i++)
            n += (size_t)snprintf(out + n, size - n, "%.17g %.17g  ", 0.1 + 0.8 * i / GRID,
                                  0.3 * j / GRID);
    snprintf(out + n, size - n, "]\n");
}

/* The job of `sh` (a corpus shader, or an inline one when src is set)
 * displacing the grid, its renderer prepared (the pieces' root boxes) */
static bool open_grid(fixture *f, const char *name, const char *src, int kind,
                      const char *extra)
{
    static char geom[65536], rib[70000];
    grid_rib(geom, sizeof geom, kind);
    snprintf(rib, sizeof rib,
             "Option \"searchpath\" \"texture\" [\"%s\"]\n"
             "Format 64 48 1\nProjection \"perspective\" \"fov\" [35]\n"
             "WorldBegin\nAttributeBegin\nTranslate 0 0 5\nRotate -40 1 0 0\n"
             "Displacement \"%s\"\n%s%s\nAttributeEnd\nWorldEnd\n",
             C.texdir, name, geom, extra ? extra : "");
    job_options opt;
    job_options_default(&opt);
    memset(f, 0, sizeof *f);
    f->diag = sl_diag_new();
    f->job = job_new("region.rib", rib, strlen(rib), &opt);
    char why[256], file[96];
    for (int i = 0; i < C.nheaders; i++)
        if (!job_add_source(f->job, C.headers[i].name, C.headers[i].text,
                            strlen(C.headers[i].text), why, sizeof why))
            return false;
    if (!src)
        for (int i = 0; i < C.nshaders; i++)
            if (!strcmp(C.shaders[i].name, name)) src = C.shaders[i].text;
    if (!src) {
        fprintf(stderr, "no shader %s in the corpus\n", name);
        return false;
    }
    snprintf(file, sizeof file, "%s.sl", name);
    if (!job_add_source(f->job, file, src, strlen(src), why, sizeof why) ||
        !job_add_shader(f->job, name, file, why, sizeof why) || !job_finish(f->job, why, sizeof why)) {
        fprintf(stderr, "%s: %s\n", name, why);
        return false;
    }
    f->js = job_scene_new(f->job, 0, true, NULL, f->diag);
    if (!f->js) sl_diag_print(f->diag, stderr);
    return f->js != NULL;
}

static const trace_object *mesh_of(const fixture *f)
{
    for (int i = 0; i < f->js->world.nobjects; i++)
        if (f->js->world.objects[i].mesh) return &f->js->world.objects[i];
    return NULL;
}

static bool inside(const trace_box *r, vec3 lo, vec3 hi)
{
    return r->lo.x <= lo.x && r->lo.y <= lo.y && r->lo.z <= lo.z && hi.x <= r->hi.x &&
           hi.y <= r->hi.y && hi.z <= r->hi.z;
}

static double volume(vec3 lo, vec3 hi)
{
    return (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
}

typedef struct looseness {
    double log_sum[2];                 /* of volume ratios to the roots' hull: small
                                          (<= 4 pieces), large */
    double log_pts[2];                 /* ... to the sampled points' hull */
    int count[2];
} looseness;

/* What escaped the regions: root boxes, sampled points (each counted
 * once per subset), and the regions refused */
typedef struct escapes {
    int roots, points, refused, subsets;
    double excess;                     /* the most a root box pokes out, over its extent */
} escapes;

/* The region of pieces[0..n) against the oracle (printing the first
 * escapes of each kind) */
static void check_subset(trace_thread *th, const trace_object *mobj, const int *pieces, int n,
                         looseness *loose, escapes *esc, const char *what)
{
    trace_box r;
    bool bounded = trace_mesh_region_box(th, mobj, pieces, n, &r);
    assert_false(th->failed);
    esc->subsets++;
    if (!bounded) {
        assert_true(r.flags & AA_UNBOUNDED);
        esc->refused++;                /* trivially sound (counted) */
        return;
    }
    trace_view *v = malloc(sizeof *v);
    vec3 ulo = v3(INFINITY, INFINITY, INFINITY), uhi = v3(-INFINITY, -INFINITY, -INFINITY);
    vec3 plo = ulo, phi = uhi;
    bool root_out = false, point_out = false;
    for (int i = 0; i < n; i++) {
        assert_true(trace_mesh_view_make(th, mobj, pieces[i], true, v));
        const trace_box *root = &v->obj.root;
        assert_false(root->flags & AA_UNBOUNDED);
        ulo = v3(fmin(ulo.x, root->lo.x), fmin(ulo.y, root->lo.y), fmin(ulo.z, root->lo.z));
        uhi = v3(fmax(uhi.x, root->hi.x), fmax(uhi.y, root->hi.y), fmax(uhi.z, root->hi.z));
        double rl[3] = {root->lo.x, root->lo.y, root->lo.z}, rh[3] = {root->hi.x, root->hi.y, root->hi.z};
        double gl[3] = {r.lo.x, r.lo.y, r.lo.z}, gh[3] = {r.hi.x, r.hi.y, r.hi.z};
        for (int a = 0; a < 3; a++)
            esc->excess = fmax(esc->excess, fmax(gl[a] - rl[a], rh[a] - gh[a]) / (rh[a] - rl[a]));
        if (!root_out && !inside(&r, root->lo, root->hi)) {
            if (esc->roots < 3)        /* the first few, for the record */
                printf("  %s: piece %d's root box [%g %g %g]-[%g %g %g] is not in the "
                       "region [%g %g %g]-[%g %g %g]\n", what, pieces[i], root->lo.x,
                       root->lo.y, root->lo.z, root->hi.x, root->hi.y, root->hi.z, r.lo.x,
                       r.lo.y, r.lo.z, r.hi.x, r.hi.y, r.hi.z);
            root_out = true;
        }
        /* a 5 x 5 grid over the piece's (u,v) square, 33 x 33 where its
         * root box pokes out of the region (where the surface might too) */
        bool pokes = !inside(&r, root->lo, root->hi);
        int S = pokes ? 33 : 5;
        for (int j = 0; !point_out && j < S * S; j++) {
            double u = (j % S) / (double)(S - 1), w = (j / S) / (double)(S - 1);
            trace_surface_point sp;
            trace_surface_point_eval(th, &v->obj, u, w, &sp);
            assert_false(th->failed);
            vec3 p = mat4_xform_point(&mobj->from_camera, sp.P);
            plo = v3(fmin(plo.x, p.x), fmin(plo.y, p.y), fmin(plo.z, p.z));
            phi = v3(fmax(phi.x, p.x), fmax(phi.y, p.y), fmax(phi.z, p.z));
            /* the camera -> object map of the test rounds: a hair */
            double e = 1e-12 * (fabs(p.x) + fabs(p.y) + fabs(p.z) + 1);
            if (!inside(&r, v3_add(p, v3(e, e, e)), v3_sub(p, v3(e, e, e)))) {
                printf("  %s: piece %d at (%g, %g): P (%.9g %.9g %.9g) is not in the region "
                       "[%g %g %g]-[%g %g %g]\n", what, pieces[i], u, w, p.x, p.y, p.z,
                       r.lo.x, r.lo.y, r.lo.z, r.hi.x, r.hi.y, r.hi.z);
                point_out = true;
            }
        }
    }
    free(v);
    esc->roots += root_out;
    esc->points += point_out;
    double ratio = volume(r.lo, r.hi) / volume(ulo, uhi);
    int big = n > 4;
    loose->log_sum[big] += log(ratio);
    loose->log_pts[big] += log(volume(r.lo, r.hi) / volume(plo, phi));
    loose->count[big]++;
}

/* Subsets of the mesh's pieces: contiguous runs of 1, 4, 16 and all,
 * and random sets of 2, 8 and 32, three times */
static void check_mesh(const char *name, int kind, escapes *esc, looseness *loose)
{
    fixture f;
    assert_true(open_grid(&f, name, NULL, kind, NULL));
    const trace_object *mobj = mesh_of(&f);
    assert_non_null(mobj);
    int np = mobj->mesh->npieces;
    assert_true(np >= GRID * GRID);
    trace_thread *th = trace_thread_new(&f.js->world);
    corpus_rng rng = {(uint64_t)np * 7919u + (unsigned char)name[0]};
    int *set = malloc(sizeof *set * (size_t)np);
    static const int runs[] = {1, 4, 16, -1}, picks[] = {2, 8, 32};
    char what[128];
    for (int rep = 0; rep < 3; rep++) {
        for (size_t s = 0; s < sizeof runs / sizeof runs[0]; s++) {
            int n = runs[s] < 0 ? np : runs[s];
            int a = (int)(corpus_rng_uniform(&rng) * (np - n + 1));
            for (int i = 0; i < n; i++) set[i] = a + i;
            snprintf(what, sizeof what, "%s on %s, pieces [%d, %d)", name,
                     KIND_NAMES[kind], a, a + n);
            check_subset(th, mobj, set, n, loose, esc, what);
        }
        for (size_t s = 0; s < sizeof picks / sizeof picks[0]; s++) {
            int n = picks[s];
            for (int i = 0; i < n; i++) set[i] = (int)(corpus_rng_uniform(&rng) * np);
            snprintf(what, sizeof what, "%s on %s, %d random pieces", name,
                     KIND_NAMES[kind], n);
            check_subset(th, mobj, set, n, loose, esc, what);
        }
    }
    free(set);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static const char *SHADERS[] = {
    "dents_shader",       /* noise sum, pow, shader space */
    "bumps_world",        /* vector noise, world space */
    "du_smoothstep",      /* the global du as a filter width */
    "fbm_du",             /* octaves from du, dv */
    "fw_stripes",         /* filterwidth: Du, Dv (derivative bounds) */
    "tex_heightmap",      /* texture() of st, blurred by filter widths */
    "rawn_noise",         /* raw N */
    "dpdu_rivets",        /* dPdu, s, t */
    "calcnormal_before",  /* calculatenormal before moving P */
    "ng_ripple",          /* Ng, faceforward with I */
    "uv_quilt",           /* u, v */
};

static void test_region_holds_every_piece(void **state)
{
    (void)state;
    escapes esc = {0, 0, 0, 0, 0.0};
    printf("region volume over that of the hull of the pieces' root boxes, and of\n"
           "their sampled points (geometric means; subsets of <= 4 and > 4 pieces):\n"
           "%-18s %-9s %9s %9s %9s %9s\n", "shader", "mesh", "roots<=4", "roots>4",
           "points<=4", "points>4");
    for (size_t s = 0; s < sizeof SHADERS / sizeof SHADERS[0]; s++)
        for (int kind = 0; kind < NKINDS; kind++) {
            looseness l = {{0, 0}, {0, 0}, {0, 0}};
            int r0 = esc.refused;
            check_mesh(SHADERS[s], kind, &esc, &l);
            printf("%-18s %-9s %9.3g %9.3g %9.3g %9.3g%s\n", SHADERS[s],
                   KIND_NAMES[kind], exp(l.log_sum[0] / l.count[0]),
                   exp(l.log_sum[1] / l.count[1]), exp(l.log_pts[0] / l.count[0]),
                   exp(l.log_pts[1] / l.count[1]), esc.refused > r0 ? " (some refused)" : "");
        }
    printf("%d subsets: a root box outside in %d (by up to %.3g of its extent), a sampled "
           "point outside in %d, %d refused\n", esc.subsets, esc.roots, esc.excess, esc.points,
           esc.refused);
    /* (b) is the contract: no displaced point outside. (a) is reported,
     * not asserted: a piece's root box and the region are two enclosures
     * of the same surface, each looser than the other somewhere (the root
     * box wraps its own shader run's slack), so neither holds the other;
     * the dense samples where a root box pokes out find no point there */
    assert_int_equal(esc.points, 0);
    assert_int_equal(esc.refused, 0);
    assert_true(esc.subsets > 400);
}

/* The cost, printed (not asserted: wall time): a region of every piece
 * (one shader run and a visit of the pieces) against every piece's own
 * root box (a shader run each) */
static void test_cost_is_printed(void **state)
{
    (void)state;
    static const char *names[] = {"dents_shader", "tex_heightmap", "calcnormal_before"};
    for (size_t s = 0; s < sizeof names / sizeof names[0]; s++) {
        fixture f;
        assert_true(open_grid(&f, names[s], NULL, SMOOTH, NULL));
        const trace_object *mobj = mesh_of(&f);
        int np = mobj->mesh->npieces, *all = malloc(sizeof *all * (size_t)np);
        for (int i = 0; i < np; i++) all[i] = i;
        trace_thread *th = trace_thread_new(&f.js->world);
        trace_view *v = malloc(sizeof *v);
        trace_box b;
        struct timespec t0, t1, t2, t3, t4;
        clock_gettime(CLOCK_MONOTONIC, &t4);
        for (int rep = 0; rep < 10; rep++)     /* the views alone */
            for (int i = 0; i < np; i++) assert_true(trace_mesh_view_make(th, mobj, i, false, v));
        clock_gettime(CLOCK_MONOTONIC, &t3);
        clock_gettime(CLOCK_MONOTONIC, &t0);
        for (int rep = 0; rep < 10; rep++) assert_true(trace_mesh_region_box(th, mobj, all, np, &b));
        clock_gettime(CLOCK_MONOTONIC, &t1);
        for (int rep = 0; rep < 10; rep++)
            for (int i = 0; i < np; i++) {
                assert_true(trace_mesh_view_make(th, mobj, i, false, v));
                trace_surface_box(th, &v->obj, 0, 1, 0, 1, &b);
            }
        clock_gettime(CLOCK_MONOTONIC, &t2);
        double region = ((double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec)) / 10;
        double roots = ((double)(t2.tv_sec - t1.tv_sec) + 1e-9 * (double)(t2.tv_nsec - t1.tv_nsec)) / 10;
        double views = ((double)(t3.tv_sec - t4.tv_sec) + 1e-9 * (double)(t3.tv_nsec - t4.tv_nsec)) / 10;
        printf("%-18s region of %d pieces %.0f us (%.2f us a piece, %.2f of it making the "
               "views), their %d root boxes %.0f us (%.1f us each)\n", names[s], np,
               1e6 * region, 1e6 * region / np, 1e6 * views / np, np, 1e6 * roots,
               1e6 * roots / np);
        free(v);
        free(all);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
}

static const char *LIFT_SL =
    "displacement lift(float height = 0)\n"
    "{\n"
    "    P += height * normalize(N);\n"
    "}\n";

/* A primitive variable that is a parameter of the displacement shader:
 * refused, the unbounded box */
static void test_param_primvar_is_refused(void **state)
{
    (void)state;
    char extra[4096];
    size_t n = (size_t)snprintf(extra, sizeof extra, "  \"vertex float height\" [");
    for (int k = 0; k < (GRID + 1) * (GRID + 1); k++)
        n += (size_t)snprintf(extra + n, sizeof extra - n, "%g ", 0.01 * (k % 7));
    snprintf(extra + n, sizeof extra - n, "]");
    fixture f;
    assert_true(open_grid(&f, "lift", LIFT_SL, SMOOTH, extra));
    const trace_object *mobj = mesh_of(&f);
    assert_non_null(mobj);
    trace_thread *th = trace_thread_new(&f.js->world);
    int pieces[3] = {0, 1, 2};
    trace_box r;
    assert_false(trace_mesh_region_box(th, mobj, pieces, 3, &r));
    assert_true(r.flags & AA_UNBOUNDED);
    assert_true(isinf(r.lo.x) && isinf(r.hi.z));
    assert_false(th->failed);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* An undisplaced region is the union of the pieces' bounds; none, empty */
static void test_empty_region(void **state)
{
    (void)state;
    fixture f;
    assert_true(open_grid(&f, "dents_shader", NULL, FLAT, NULL));
    trace_thread *th = trace_thread_new(&f.js->world);
    trace_box r;
    assert_true(trace_mesh_region_box(th, mesh_of(&f), NULL, 0, &r));
    assert_true(r.lo.x > r.hi.x);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

int main(void)
{
    if (!corpus_load(&C)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_region_holds_every_piece),
        cmocka_unit_test(test_param_primvar_is_refused),
        cmocka_unit_test(test_empty_region),
        cmocka_unit_test(test_cost_is_printed),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    corpus_free(&C);
    return rc;
}

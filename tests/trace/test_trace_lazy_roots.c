/*
 * test_trace_lazy_roots.c: a displaced mesh's root boxes are made when a
 * ray first reaches a piece (issue 23; trace/mesh.c, trace/lazy_roots.h).
 *
 * - The BVH's boxes, made before any piece's own box from one shader run
 *   per region of the tree, hold every displaced point of every piece (of
 *   polygon meshes and of a Catmull-Clark cage):
 *   points sampled on the surface by the float evaluator (not by the
 *   boxes' code) are each reached by a ray aimed at them through the tree.
 * - The regions' bounds of du and dv (from a 3 x 3 grid) hold each
 *   piece's own (the 9 x 9 grid's).
 * - Nothing of a lazily bounded mesh's roots is made when the world is
 *   built, and a view of a corner of the mesh makes a fraction of them.
 * - The image is the one the eager build gives (every root box made
 *   first, as before: world option lazy_roots off), and rendered by four
 *   threads at once it is the one thread's, with the same roots, to the
 *   bit, as the eager build's.
 * - Under a budget for the roots (trace_options.roots_bytes) the store,
 *   counted by the allocator, stays within it while 1 and 4 threads
 *   render the whole mesh (roots evicted and made again), and the image
 *   is the eager build's, to the bit.
 * - Where a region cannot bound its pieces (a displacement shader
 *   parameter from a primitive variable; a filter width that makes a
 *   region's bound useless), their roots are made when the world is built.
 */
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fixture.h"
#include "trace/displace.h"
#include "trace/lazy_roots.h"
#include "trace/mesh.h"
#include "trace/render.h"

enum { W = 48, H = 36, PX = W * H * 4 };

/* An n x n grid of quads over [-n/2, n/2]^2 (z = 0), bent a little so its
 * normals differ, with "st" and an optional "varying float amp"; seen
 * whole (fov 60) or only near its middle (fov 12) */
static bool subdiv_grid = false;   /* grid_rib: a Catmull-Clark cage instead */

static char *grid_rib(int n, const char *disp, bool amp, bool narrow)
{
    size_t cap = (size_t)(n + 1) * (n + 1) * 120 + (size_t)n * n * 40 + 4096, len = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    len += (size_t)snprintf(t + len, cap - len,
                            "Format %d %d 1\nProjection \"perspective\" \"fov\" [%d]\n"
                            "Translate 0 0 %g\nRotate -40 1 0 0\nWorldBegin\n"
                            "LightSource \"distantlight\" 1 \"from\" [1 2 -3] \"to\" [0 0 0]\n"
                            "%s\n%s [",
                            W, H, narrow ? 12 : 60, 0.9 * n, disp,
                            subdiv_grid ? "SubdivisionMesh \"catmull-clark\"" : "PointsPolygons");
    for (int i = 0; i < n * n; i++) len += (size_t)snprintf(t + len, cap - len, "4 ");
    len += (size_t)snprintf(t + len, cap - len, "] [");
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int a = j * (n + 1) + i;
            len += (size_t)snprintf(t + len, cap - len, "%d %d %d %d ", a, a + 1, a + n + 2,
                                    a + n + 1);
        }
    double h = n / 2.0;
    if (subdiv_grid) len += (size_t)snprintf(t + len, cap - len, "] [\"interpolateboundary\"] [0 0] [] [");
    len += (size_t)snprintf(t + len, cap - len, "] \"P\" [");
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            double x = i - h, y = j - h;
            len += (size_t)snprintf(t + len, cap - len, "%g %g %.9g ", x, y,
                                    0.02 * (x * x - 0.5 * y * y) / n);
        }
    len += (size_t)snprintf(t + len, cap - len, "] \"st\" [");
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++)
            len += (size_t)snprintf(t + len, cap - len, "%.9g %.9g ", (double)i / n,
                                    (double)j / n);
    len += (size_t)snprintf(t + len, cap - len, "]");
    if (amp) {
        len += (size_t)snprintf(t + len, cap - len, " \"varying float amp\" [");
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++)
                len += (size_t)snprintf(t + len, cap - len, "%g ", 0.2 + 0.1 * ((i + j) % 3));
        len += (size_t)snprintf(t + len, cap - len, "]");
    }
    snprintf(t + len, cap - len, "\nWorldEnd\n");
    return t;
}

static const char *BUMPS_SL =
    "displacement bumps(float Km = 0.6)\n"
    "{\n"
    "    P += Km * (noise(P * 0.9) - 0.5) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *STWAVE_SL =
    "displacement stwave(float Km = 0.5)\n"
    "{\n"
    "    P += Km * sin(12.5 * s) * cos(9.4 * t) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* a parameter from a primitive variable: no region binds it */
static const char *AMP_SL =
    "displacement amp(float amp = 0.1)\n"
    "{\n"
    "    P += amp * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* 1 / the filter width of s: a region's hull of ds/du reaches 0, so its bound is
 * useless (wider than the mesh); each piece's own is small */
static const char *FWIDE_SL =
    "displacement fwide(float Km = 0.001)\n"
    "{\n"
    "    float w = abs(Du(s) * du) + abs(Dv(s) * dv);\n"
    "    P += Km * min(1 / max(w, 1e-30), 1e30) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const fixture_shader SHADERS[] = {
    {"bumps", NULL}, {"stwave", NULL}, {"amp", NULL}, {"fwide", NULL}};

static void open_grid(fixture *f, int n, const char *disp, bool amp, bool narrow)
{
    fixture_shader sh[4];
    memcpy(sh, SHADERS, sizeof sh);
    sh[0].source = BUMPS_SL;
    sh[1].source = STWAVE_SL;
    sh[2].source = AMP_SL;
    sh[3].source = FWIDE_SL;
    char *rib = grid_rib(n, disp, amp, narrow);
    assert_true(fixture_open(f, rib, sh, 4, NULL, 0));
    free(rib);
    assert_int_equal(f->js->world.nobjects, 1);
    assert_non_null(f->js->world.objects[0].mesh);
}

/* The world built again with lazy root boxes on or off */
static void rebuild(fixture *f, bool lazy)
{
    trace_renderer_destroy(&f->js->renderer);
    f->js->world.options.lazy_roots = lazy;
    char err[256];
    f->js->renderer = trace_renderer_new(&f->js->world, err, sizeof err);
    if (!f->js->renderer) fprintf(stderr, "%s\n", err);
    assert_non_null(f->js->renderer);
}

static const trace_mesh *mesh_of(const fixture *f)
{
    return f->js->world.objects[0].mesh;
}

/* ---- the BVH's boxes hold the surface -------------------------------- */

typedef struct visit {
    int want;
    bool seen;
} visit;

static int record(void *ctx, int k)
{
    visit *v = ctx;
    if (k == v->want) v->seen = true;
    return 0;
}

static unsigned rng_state = 12345u;
static double rnd(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (rng_state >> 8) / 16777216.0;
}

/* Points on each piece (the float evaluator's), each aimed at by a ray
 * from a random direction through the mesh's BVH (object space): the
 * walk must reach the piece. Returns the misses. */
static int misses(fixture *f, int samples)
{
    const trace_object *obj = &f->js->world.objects[0];
    const trace_mesh *m = obj->mesh;
    trace_thread *th = trace_thread_new(&f->js->world);
    trace_view *v = malloc(sizeof *v);
    int missed = 0, points = 0;
    for (int k = 0; k < m->npieces; k++) {
        assert_true(trace_mesh_view_make(th, obj, k, false, v));
        for (int s = 0; s < samples; s++) {
            double u = rnd(), w = rnd();
            if (!geom_uv_inside(&v->obj.surf, u, w)) continue;
            trace_surface_point sp;
            trace_surface_point_eval(th, &v->obj, u, w, &sp);
            if (!v3_is_finite(sp.P)) continue;
            vec3 p = mat4_xform_point(&obj->from_camera, sp.P);
            vec3 d = v3_normalize(v3(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5));
            trace_ray ray;
            trace_ray_init(&ray, v3_sub(p, v3_scale(d, 100.0)), d, 0.0, INFINITY);
            trace_hit best = {.t = INFINITY};
            visit vis = {k, false};
            trace_float_bvh_walk(m->bvh, &ray, &best, false, record, &vis);
            missed += !vis.seen;
            points++;
        }
    }
    assert_false(th->failed);
    assert_true(points > m->npieces);
    free(v);
    trace_thread_destroy(&th);
    return missed;
}

static void test_boxes_hold_the_surface(void **state)
{
    (void)state;
    const char *disp[] = {"Displacement \"bumps\"", "Displacement \"stwave\"",
                          "Displacement \"bumps\""};
    for (int i = 0; i < 3; i++) {
        fixture f;
        subdiv_grid = i == 2;          /* a Catmull-Clark cage's limit pieces */
        open_grid(&f, i == 2 ? 12 : 24, disp[i], false, false);
        subdiv_grid = false;
        const trace_mesh *m = mesh_of(&f);
        /* every region bounded its pieces: no root made yet */
        assert_non_null(m->lazy);
        assert_int_equal(trace_lazy_roots_known(m->lazy), 0);
        int missed = misses(&f, 6);
        printf("%s on %s: %d pieces, %d sampled points missed by the BVH\n", disp[i],
               i == 2 ? "a Catmull-Clark cage" : "a polygon mesh", m->npieces, missed);
        assert_int_equal(missed, 0);
        fixture_close(&f);
    }
}

/* The regions' du, dv: the 3 x 3 grid's bounds hold each piece's own
 * (the 9 x 9 grid's) value, on a grid seen from near (perspective: the
 * pieces' raster sizes vary) */
static void test_grid_spacing_bounds(void **state)
{
    (void)state;
    fixture f;
    open_grid(&f, 24, "Displacement \"stwave\"", false, false);
    const trace_object *obj = &f.js->world.objects[0];
    trace_thread *th = trace_thread_new(&f.js->world);
    trace_view *v = malloc(sizeof *v);
    int n = obj->mesh->npieces, above = 0;
    double lo = INFINITY, hi = 0, slack = INFINITY;
    for (int k = 0; k < n; k++) {
        assert_true(trace_mesh_view_make(th, obj, k, false, v));
        double du, dv;
        trace_object_grid_spacing_max(&f.js->world, &v->obj, &du, &dv);
        above += !(v->obj.du <= du) + !(v->obj.dv <= dv);
        lo = fmin(lo, v->obj.du);
        hi = fmax(hi, v->obj.du);
        slack = fmin(slack, du / v->obj.du);
    }
    printf("%d pieces: du in [%g, %g], its 3 x 3 bound at least %g of it; %d values above\n",
           n, lo, hi, slack, above);
    assert_true(hi > 2 * lo);       /* the sizes vary */
    assert_int_equal(above, 0);
    free(v);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* ---- lazy = eager, on any number of threads --------------------------- */

typedef struct band {
    fixture *f;
    int y0, y1;
    float *rgba;
    bool ok;
    long published;                    /* the thread's stats.lazy_roots */
} band;

static void *render_band(void *arg)
{
    band *b = arg;
    trace_thread *th = trace_thread_new(&b->f->js->world);
    float *z = malloc(sizeof *z * W * H);
    b->ok = trace_render_tile(b->f->js->renderer, th, 0, b->y0, W, b->y1 - b->y0,
                              b->rgba + (size_t)b->y0 * W * 4, z);
    free(z);
    b->published = th->stats.lazy_roots;
    trace_thread_destroy(&th);
    return NULL;
}

/* The image by `threads` threads at once, each a band of rows; the root
 * boxes they published, by their stats */
static long render_parallel(fixture *f, int threads, float *rgba)
{
    pthread_t tid[8];
    band b[8];
    assert_true(threads <= 8);
    for (int i = 0; i < threads; i++) {
        b[i] = (band){f, H * i / threads, H * (i + 1) / threads, rgba, false, 0};
        assert_int_equal(pthread_create(&tid[i], NULL, render_band, &b[i]), 0);
    }
    long published = 0;
    for (int i = 0; i < threads; i++) {
        pthread_join(tid[i], NULL);
        assert_true(b[i].ok);
        published += b[i].published;
    }
    return published;
}

static int differ(const float *a, const float *b)
{
    int n = 0;
    for (int i = 0; i < PX; i++) n += a[i] != b[i];
    return n;
}

static void test_lazy_renders_as_eager(void **state)
{
    (void)state;
    float *lazy1 = malloc(sizeof(float) * PX), *lazy4 = malloc(sizeof(float) * PX);
    float *eager = malloc(sizeof(float) * PX);
    fixture f;
    open_grid(&f, 40, "Displacement \"bumps\"", false, true);
    const trace_mesh *m = mesh_of(&f);
    int n = m->npieces;
    long published1 = render_parallel(&f, 1, lazy1);
    long known1 = trace_lazy_roots_known(m->lazy);
    /* the roots one thread made, kept to compare */
    trace_box *roots = calloc((size_t)n, sizeof *roots);
    unsigned char *had = calloc((size_t)n, 1);
    for (int k = 0; k < n; k++) {
        double dudv[2];
        if (trace_lazy_root(m->lazy, k, &roots[k], dudv)) had[k] = 1;
    }
    rebuild(&f, true);
    m = mesh_of(&f);
    assert_int_equal(trace_lazy_roots_known(m->lazy), 0);
    long published4 = render_parallel(&f, 4, lazy4);
    long known4 = trace_lazy_roots_known(m->lazy);
    rebuild(&f, false);
    m = mesh_of(&f);
    /* eager: every root made when the world is built */
    assert_int_equal(trace_lazy_roots_known(m->lazy), n);
    render_parallel(&f, 2, eager);
    int covered = 0, same_roots = 0;
    for (int i = 3; i < PX; i += 4) covered += lazy1[i] > 0;
    for (int k = 0; k < n; k++) {
        if (!had[k]) continue;
        double dudv[2];
        trace_box r;
        assert_true(trace_lazy_root(m->lazy, k, &r, dudv));
        assert_memory_equal(&r, &roots[k], sizeof r);
        same_roots++;
    }
    printf("%d pieces: 1 thread made %ld roots, 4 threads %ld (the eager build %d); "
           "%d pixels covered; lazy vs eager %d values differ, 1 vs 4 threads %d\n",
           n, known1, known4, n, covered, differ(lazy1, eager), differ(lazy1, lazy4));
    assert_true(covered > W * H / 2);
    /* a corner of the mesh: a fraction of its roots */
    assert_true(known1 > 0 && known1 < n / 2);
    assert_int_equal(same_roots, known1);
    /* each root published once, by one thread (--stats' lazy_roots) */
    assert_int_equal(published1, known1);
    assert_int_equal(published4, known4);
    assert_int_equal(differ(lazy1, eager), 0);
    assert_int_equal(differ(lazy1, lazy4), 0);
    free(roots);
    free(had);
    fixture_close(&f);
    free(lazy1);
    free(lazy4);
    free(eager);
}

/* ---- the roots' budget ------------------------------------------------ */

/* The world's roots budget (trace_options.roots_bytes) kept, counted by
 * the allocator while 1 and 4 threads render the whole mesh, whose roots
 * would take several times the budget: roots are evicted and made again,
 * and the image is the eager build's, to the bit */
static void test_roots_budget_kept(void **state)
{
    (void)state;
    enum { BUDGET = 8192 };
    float *eager = malloc(sizeof(float) * PX), *img = malloc(sizeof(float) * PX);
    fixture f;
    open_grid(&f, 40, "Displacement \"bumps\"", false, false);
    rebuild(&f, false);
    render_parallel(&f, 2, eager);
    long all = trace_lazy_roots_known(mesh_of(&f)->lazy);
    f.js->world.options.roots_bytes = BUDGET;
    for (int threads = 1; threads <= 4; threads += 3) {
        rebuild(&f, true);
        const trace_mesh *m = mesh_of(&f);
        size_t before = fixture_heap_bytes();
        long published = render_parallel(&f, threads, img);
        size_t after = fixture_heap_bytes();
        long known = trace_lazy_roots_known(m->lazy);
        long evicted = trace_lazy_roots_evicted(m->lazy);
        size_t held = trace_lazy_roots_bytes(m->lazy);
        long grown = (long)after - (long)before;
        printf("budget %d bytes, %d threads: %d slots for %d pieces (%ld roots eagerly); "
               "%ld published, %ld held, %ld evicted; the store %zu bytes, the heap grew by "
               "%ld; %d values differ from the eager image\n",
               BUDGET, threads, trace_lazy_roots_slots(m->lazy), m->npieces, all, published,
               known, evicted, held, grown, differ(img, eager));
        assert_true(held <= BUDGET);
        assert_true(known <= trace_lazy_roots_slots(m->lazy));
        assert_true(evicted > 0);      /* the budget bit */
        /* the allocator's count (0 under a sanitizer's allocator) */
        if (after > 0) assert_true(grown <= BUDGET);
        assert_int_equal(differ(img, eager), 0);
    }
    fixture_close(&f);
    free(eager);
    free(img);
}

/* ---- regions that cannot bound their pieces ------------------------- */

static void test_unbounded_regions_make_roots_first(void **state)
{
    (void)state;
    struct {
        const char *disp;
        bool amp;
    } c[] = {{"Displacement \"amp\"", true}, {"Displacement \"fwide\"", false}};
    for (int i = 0; i < 2; i++) {
        float *a = malloc(sizeof(float) * PX), *b = malloc(sizeof(float) * PX);
        fixture f;
        open_grid(&f, 16, c[i].disp, c[i].amp, false);
        const trace_mesh *m = mesh_of(&f);
        long known = trace_lazy_roots_known(m->lazy);
        printf("%s: %ld of %d roots made with the world\n", c[i].disp, known, m->npieces);
        /* the parameter: every region refused; the filter width: the
         * regions whose hull of ds/du reaches 0 */
        if (c[i].amp) assert_int_equal(known, m->npieces);
        else assert_true(known > 0);
        assert_int_equal(misses(&f, 4), 0);
        render_parallel(&f, 2, a);
        rebuild(&f, false);
        render_parallel(&f, 2, b);
        assert_int_equal(differ(a, b), 0);
        fixture_close(&f);
        free(a);
        free(b);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_boxes_hold_the_surface),
        cmocka_unit_test(test_grid_spacing_bounds),
        cmocka_unit_test(test_lazy_renders_as_eager),
        cmocka_unit_test(test_roots_budget_kept),
        cmocka_unit_test(test_unbounded_regions_make_roots_first),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

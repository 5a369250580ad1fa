/*
 * test_corpus_render.c: issue 9, "the corpus", renders: every corpus
 * shader on the plane, the sphere and the mesh of eight triangles sharing
 * edges (where cracks between polygons would show as missed pixels), a
 * small image (one primary ray per
 * pixel through its centre, trace_render_sample) in affine arithmetic,
 * against a brute-force reference: the displaced surface tessellated on a
 * fine (u,v) grid with the renderer's own point path
 * (trace_surface_point_eval) and projected to raster space. Every pixel
 * whose centre lies well inside the reference (the centre and four points
 * half a pixel away are all covered, so it is not at the tessellation's
 * silhouette) must be a hit of the renderer: the guarantee of conservative
 * boxes (Heidrich & Seidel §3). The work per ray, boxes computed / primary
 * rays (trace_stats), must stay under MAX_BOXES_PER_RAY.
 *
 * Each render runs in a child process, stopped (and counted as a failure)
 * when one ray has computed more than MAX_BOXES_ONE_RAY boxes or the image
 * more than MAX_BOXES_PER_RAY per pixel (box counts, watched by a thread of
 * the child, so the stop does not depend on the machine's speed); a child
 * still running after AAFARM_CORPUS_RENDER_LIMIT seconds (default 30: a ray
 * that spins without computing boxes) is killed and counted. So a runaway
 * shader fails the test instead of hanging it.
 *
 *   AAFARM_CORPUS_ONLY          comma-separated shader names (default all)
 *   AAFARM_CORPUS_RENDER_LIMIT  seconds per render before SIGKILL (default 30)
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "corpus.h"
#include "geom/surface.h"
#include "trace/mesh.h"
#include "trace/displace.h"

enum { W = 48, H = 36 };            /* image */
enum { GRID = 200 };                /* reference tessellation: GRID x GRID points per scene,
                                       split among its objects */
enum { MAX_BOXES_PER_RAY = 100 };   /* the stated bound: boxes computed / primary rays */
enum { MAX_BOXES_ONE_RAY = 20000 }; /* a single ray past this is a runaway */
/* issue 24, walls and patterns: the brick, tile and slate-roof shaders
 * (step/mod/floor in both directions) within this many boxes per ray on
 * the sphere (bricks_filtered took 60.8 before its seams were split into
 * cases: trace_surface_box_cases) */
enum { MAX_PATTERN_BOXES_PER_RAY = 10 };
static const char *const PATTERNS[] = {"bricks", "bricks_filtered", "slate_roof", "tiles_hex",
                                       "tiles_pillow", "pnoise_tiles", "uv_quilt", "fwp_checks"};

static bool is_pattern(const char *name)
{
    for (size_t k = 0; k < sizeof PATTERNS / sizeof PATTERNS[0]; k++)
        if (strcmp(name, PATTERNS[k]) == 0) return true;
    return false;
}
/* the filtered pulse trains: their seams' boxes proven thin by the cases
 * of one value (common/sl/split_plan.c), with no box on the sphere
 * re-estimated from samples (before: several hundred) */
static const char *const PULSE_TRAINS[] = {"dv_lines", "fw_stripes"};

static bool is_pulse_train(const char *name)
{
    for (size_t k = 0; k < sizeof PULSE_TRAINS / sizeof PULSE_TRAINS[0]; k++)
        if (strcmp(name, PULSE_TRAINS[k]) == 0) return true;
    return false;
}
static const double MARGIN = 0.5;   /* pixels: how far inside the reference a centre must be */

typedef enum { RS_OK, RS_OPEN, RS_BUDGET, RS_SHADER, RS_KILLED, RS_CRASHED } render_status;
static const char *STATUS[] = {"ok", "scene failed", "box budget", "shader error",
                               "killed (runaway)", "crashed"};

typedef struct render_result {
    int status;
    long rendered;                  /* pixels traced before any stop */
    long hits, certain, missed, extra;
    long boxes, wall_leaves, depth_cap_leaves, sampled_boxes;
    double render_s, reference_s;   /* CPU seconds (printed, never asserted) */
    int miss_x, miss_y;             /* the first missed pixel */
    char error[256];
} render_result;

static corpus C;

static int setup(void **state) { return corpus_group_load(&C, state); }
static int teardown(void **state) { return corpus_group_free(&C, state); }

/* raster position of a camera-space point (the inverse of trace_camera_ray
 * for a perspective camera: RI Spec 3.2 §4.1.1) */
static bool raster_of(const trace_camera *c, vec3 p, double *x, double *y)
{
    if (!(p.z > c->near_clip)) return false;
    double sx = p.x / p.z / c->tan_half_fov, sy = p.y / p.z / c->tan_half_fov;
    *x = (sx - c->screen[0]) / (c->screen[1] - c->screen[0]) * c->xres;
    *y = (c->screen[3] - sy) / (c->screen[3] - c->screen[2]) * c->yres;
    return isfinite(*x) && isfinite(*y);
}

/* the five sample positions of a pixel: centre, then +-MARGIN in x and y */
static void sample_at(int i, int j, int k, double *x, double *y)
{
    static const double off[5][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    *x = i + 0.5 + off[k][0] * MARGIN;
    *y = j + 0.5 + off[k][1] * MARGIN;
}

static double edge(double ax, double ay, double bx, double by, double px, double py)
{
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

/* marks in cover[] (5 bits per pixel) the samples inside triangle abc */
static void raster_triangle(const double a[2], const double b[2], const double c[2],
                            unsigned char *cover)
{
    double area = edge(a[0], a[1], b[0], b[1], c[0], c[1]);
    if (area == 0 || !isfinite(area)) return;
    double x0 = fmin(a[0], fmin(b[0], c[0])) - 1, x1 = fmax(a[0], fmax(b[0], c[0])) + 1;
    double y0 = fmin(a[1], fmin(b[1], c[1])) - 1, y1 = fmax(a[1], fmax(b[1], c[1])) + 1;
    int i0 = (int)fmax(0, floor(x0)), i1 = (int)fmin(W - 1, ceil(x1));
    int j0 = (int)fmax(0, floor(y0)), j1 = (int)fmin(H - 1, ceil(y1));
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++)
            for (int k = 0; k < 5; k++) {
                double x, y;
                sample_at(i, j, k, &x, &y);
                double e0 = edge(a[0], a[1], b[0], b[1], x, y);
                double e1 = edge(b[0], b[1], c[0], c[1], x, y);
                double e2 = edge(c[0], c[1], a[0], a[1], x, y);
                if (area < 0) { e0 = -e0; e1 = -e1; e2 = -e2; }
                if (e0 >= 0 && e1 >= 0 && e2 >= 0) cover[j * W + i] |= (unsigned char)(1u << k);
            }
}

/* one point of the reference: raster position, false when behind the eye */
static bool ref_point(trace_thread *th, const trace_object *obj, const trace_camera *cam,
                      double u, double v, double xy[2])
{
    trace_surface_point sp;
    trace_surface_point_eval(th, obj, u, v, &sp);
    return raster_of(cam, sp.P, &xy[0], &xy[1]);
}

/* the (u,v) triangle abc on a triangular grid of G steps per side */
static void ref_triangle(trace_thread *th, const trace_object *obj, const trace_camera *cam,
                         const double a[2], const double b[2], const double c[2], int G,
                         double (*xy)[2], bool *ok, unsigned char *cover)
{
    const int S = G + 1;
    for (int j = 0; j <= G; j++)
        for (int i = 0; i + j <= G; i++) {
            double fi = (double)i / G, fj = (double)j / G;
            double u = a[0] + (b[0] - a[0]) * fi + (c[0] - a[0]) * fj;
            double v = a[1] + (b[1] - a[1]) * fi + (c[1] - a[1]) * fj;
            ok[j * S + i] = ref_point(th, obj, cam, u, v, xy[j * S + i]);
        }
    for (int j = 0; j < G; j++)
        for (int i = 0; i + j < G; i++) {
            int k = j * S + i;
            if (ok[k] && ok[k + 1] && ok[k + S]) raster_triangle(xy[k], xy[k + 1], xy[k + S], cover);
            if (i + j + 1 < G && ok[k + 1] && ok[k + S + 1] && ok[k + S])
                raster_triangle(xy[k + 1], xy[k + S + 1], xy[k + S], cover);
        }
}

/* the reference: each object tessellated finely (about GRID x GRID points
 * per scene, split among its objects, since the triangles of a mesh are
 * small): quadrics and patches on a (u,v) grid, polygons as a fan of
 * triangles over their own (u,v) outline, each on a triangular grid, so
 * that the tessellation reaches the polygon's edges exactly */
static void reference(trace_thread *th, const trace_world *w, unsigned char *cover)
{
    int nsurf = 0;
    for (int o = 0; o < w->nobjects; o++) nsurf += trace_object_npieces(&w->objects[o]);
    const int G = (int)ceil(GRID / sqrt((double)nsurf));
    double (*xy)[2] = malloc(sizeof *xy * (size_t)(G + 1) * (size_t)(G + 1));
    bool *ok = malloc(sizeof *ok * (size_t)(G + 1) * (size_t)(G + 1));
    trace_view *view = malloc(sizeof *view);
    for (int o = 0; o < w->nobjects; o++)
      for (int pc = 0; pc < trace_object_npieces(&w->objects[o]); pc++) {
        const trace_object *obj = trace_object_piece(th, &w->objects[o], pc, view);
        if (obj->surf.kind == GEOM_POLYGON) {
            const geom_surface *g = &obj->surf;
            for (int k = 1; k + 1 < g->nuv; k++)
                ref_triangle(th, obj, &w->camera, g->uv[0], g->uv[k], g->uv[k + 1], G, xy, ok,
                             cover);
            continue;
        }
        for (int j = 0; j < G; j++)
            for (int i = 0; i < G; i++)
                ok[j * G + i] = ref_point(th, obj, &w->camera, (double)i / (G - 1),
                                          (double)j / (G - 1), xy[j * G + i]);
        for (int j = 0; j + 1 < G; j++)
            for (int i = 0; i + 1 < G; i++) {
                int k00 = j * G + i, k10 = k00 + 1, k01 = k00 + G, k11 = k01 + 1;
                if (!(ok[k00] && ok[k10] && ok[k01] && ok[k11])) continue;
                raster_triangle(xy[k00], xy[k10], xy[k11], cover);
                raster_triangle(xy[k00], xy[k11], xy[k01], cover);
            }
    }
    free(view);
    free(xy);
    free(ok);
}

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* the child's box watchdog: the render thread publishes the pixel it
 * traces and the box count at its start */
typedef struct watch {
    trace_thread *th;
    volatile long ray_start;        /* th->stats.boxes when the current pixel began */
    volatile int pixel;             /* j * W + i */
    volatile int rendering;
    int fd;                         /* the result pipe */
    render_result *r;
} watch;

static void *watchdog(void *arg)
{
    watch *wd = arg;
    long budget = (long)MAX_BOXES_PER_RAY * W * H;
    while (wd->rendering) {
        long boxes = *(volatile long *)&wd->th->stats.boxes;
        int px = wd->pixel;
        bool one = boxes - wd->ray_start > MAX_BOXES_ONE_RAY, all = boxes > budget;
        if (wd->rendering && (one || all)) {
            render_result *r = wd->r;
            r->status = RS_BUDGET;
            r->rendered = px;
            r->boxes = boxes;
            if (one)
                snprintf(r->error, sizeof r->error,
                         "the ray through pixel (%d,%d) computed more than %d boxes",
                         px % W, px / W, MAX_BOXES_ONE_RAY);
            else
                snprintf(r->error, sizeof r->error, "%ld boxes after %d of %d pixels", boxes,
                         px, W * H);
            ssize_t n = write(wd->fd, r, sizeof *r);
            _exit(n == (ssize_t)sizeof *r ? 0 : 3);
        }
        struct timespec ts = {0, 2 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    return NULL;
}

/* the child's work: render, reference, compare */
static void render_one(const corpus_file *sh, corpus_surface s, int fd, render_result *r)
{
    memset(r, 0, sizeof *r);
    r->miss_x = r->miss_y = -1;
    fixture f;
    if (!corpus_open(&f, &C, sh, s, TRACE_ARITH_AFFINE, W, H, true)) {
        r->status = RS_OPEN;
        snprintf(r->error, sizeof r->error, "%s", "the scene did not open (diagnostics above)");
        fixture_close(&f);
        return;
    }
    trace_thread *th = trace_thread_new(&f.js->world);
    bool hit[W * H];
    memset(hit, 0, sizeof hit);
    watch wd = {.th = th, .ray_start = 0, .pixel = 0, .rendering = 1, .fd = fd, .r = r};
    pthread_t tid;
    double c0 = cpu_now();
    if (pthread_create(&tid, NULL, watchdog, &wd) != 0) wd.rendering = 0;
    for (int j = 0; j < H && r->status == RS_OK; j++)
        for (int i = 0; i < W; i++) {
            wd.ray_start = th->stats.boxes;
            wd.pixel = j * W + i;
            double rgb[3], a, z;
            trace_render_sample(f.js->renderer, th, i + 0.5, j + 0.5, rgb, &a, &z);
            if (th->failed) {
                r->status = RS_SHADER;
                snprintf(r->error, sizeof r->error, "%.255s", th->error);
                break;
            }
            hit[j * W + i] = isfinite(z);
            r->rendered++;
        }
    if (wd.rendering) {
        wd.rendering = 0;
        pthread_join(tid, NULL);
    }
    trace_thread_sync_stats(th);
    r->boxes = th->stats.boxes;
    r->wall_leaves = th->stats.wall_leaves;
    r->depth_cap_leaves = th->stats.depth_cap_leaves;
    r->sampled_boxes = th->stats.sampled_boxes;
    r->render_s = cpu_now() - c0;
    if (r->status == RS_OK) {
        unsigned char cover[W * H];
        memset(cover, 0, sizeof cover);
        c0 = cpu_now();
        reference(th, &f.js->world, cover);
        r->reference_s = cpu_now() - c0;
        for (int k = 0; k < W * H; k++) {
            r->hits += hit[k];
            if (cover[k] == 0x1f) {
                r->certain++;
                if (!hit[k]) {
                    if (r->missed++ == 0) { r->miss_x = k % W; r->miss_y = k / W; }
                }
            }
            if (hit[k] && cover[k] == 0) r->extra++;
        }
    }
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* runs render_one in a child, killed after `limit` seconds */
static void render_guarded(const corpus_file *sh, corpus_surface s, double limit,
                           render_result *r)
{
    int fd[2];
    assert_int_equal(pipe(fd), 0);
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        close(fd[0]);
        render_result res;
        render_one(sh, s, fd[1], &res);
        ssize_t n = write(fd[1], &res, sizeof res);
        _exit(n == (ssize_t)sizeof res ? 0 : 3);
    }
    close(fd[1]);
    double t0 = now();
    int wstatus = 0;
    bool killed = false;
    for (;;) {
        pid_t w = waitpid(pid, &wstatus, WNOHANG);
        if (w == pid) break;
        if (w < 0 && errno != EINTR) break;
        if (!killed && now() - t0 > limit) {
            kill(pid, SIGKILL);
            killed = true;
        }
        struct timespec ts = {0, 5 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    memset(r, 0, sizeof *r);
    r->miss_x = r->miss_y = -1;
    if (killed) {
        r->status = RS_KILLED;
        snprintf(r->error, sizeof r->error, "still running after %.0f s", limit);
    } else if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0 ||
               read(fd[0], r, sizeof *r) != (ssize_t)sizeof *r) {
        memset(r, 0, sizeof *r);
        r->status = RS_CRASHED;
        snprintf(r->error, sizeof r->error, "child %s %d",
                 WIFSIGNALED(wstatus) ? "killed by signal" : "exit status",
                 WIFSIGNALED(wstatus) ? WTERMSIG(wstatus) : WEXITSTATUS(wstatus));
    }
    close(fd[0]);
}

static void run_surface(corpus_surface s)
{
    double limit = (double)corpus_env_long("AAFARM_CORPUS_RENDER_LIMIT", 30);
    long bad = 0, missed = 0, certain = 0, boxes = 0, rays = 0;
    printf("%-20s %-7s %-16s %5s %5s %7s %6s %5s %9s %7s %6s %7s %6s %6s\n", "shader", "surface",
           "status", "hits", "sure", "missed", "extra", "first", "boxes/ray", "walls", "depth",
           "sampled", "cpu_s", "ref_s");
    for (int i = 0; i < C.nshaders; i++) {
        render_result r;
        render_guarded(&C.shaders[i], s, limit, &r);
        double bpr = (double)r.boxes / (double)(r.rendered > 0 ? r.rendered : 1);
        bool fail = r.status != RS_OK || r.missed > 0 || bpr > MAX_BOXES_PER_RAY ||
                    (s == CORPUS_SPHERE && is_pattern(C.shaders[i].name) &&
                     bpr > MAX_PATTERN_BOXES_PER_RAY) ||
                    (s == CORPUS_SPHERE && is_pulse_train(C.shaders[i].name) &&
                     r.sampled_boxes > 0);
        char first[32] = "-";
        if (r.missed) snprintf(first, sizeof first, "%d,%d", r.miss_x, r.miss_y);
        printf("%-20s %-7s %-16s %5ld %5ld %7ld %6ld %5s %9.1f %7ld %6ld %7ld %6.2f %6.2f%s\n",
               C.shaders[i].name, corpus_surface_name(s), STATUS[r.status], r.hits, r.certain,
               r.missed, r.extra, first, bpr, r.wall_leaves, r.depth_cap_leaves, r.sampled_boxes,
               r.render_s, r.reference_s, fail ? "  FAIL" : "");
        if (r.error[0]) printf("    %s\n", r.error);
        bad += fail;
        missed += r.missed;
        certain += r.certain;
        if (r.status == RS_OK) {
            boxes += r.boxes;
            rays += r.rendered;
        }
    }
    printf("%s total: %ld shaders failing, %ld of %ld sure pixels missed, %.1f boxes/ray "
           "over the finished renders (bound %d)\n", corpus_surface_name(s), bad, missed, certain,
           rays ? (double)boxes / (double)rays : 0.0, MAX_BOXES_PER_RAY);
    fflush(stdout);
    assert_true(certain > 0);
    assert_int_equal(missed, 0);
    assert_int_equal(bad, 0);
}

static void test_plane(void **state) { (void)state; run_surface(CORPUS_PLANE); }
static void test_sphere(void **state) { (void)state; run_surface(CORPUS_SPHERE); }
static void test_mesh(void **state) { (void)state; run_surface(CORPUS_MESH); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane),
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_mesh),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

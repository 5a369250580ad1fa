/*
 * bench/mesh_bench.c: how polygon meshes scale (common/scene/rib_mesh.c):
 * a closed torus of nu x nv planar quads (PointsPolygons, shared points)
 * at 1k, 10k and 100k faces; prints the wall seconds of parsing (with
 * geom_surface_prepare per face, the faces over all the cores as a worker
 * parses them: scene_parse_frame_threads), the wall seconds of building the
 * renderer's scene as a worker does (job_scene_new_threads over all the
 * cores: the parse again, then the world: the pieces' edges and boxes, the
 * BVH; "parse+world", the aim of issue 23, and "world", that less the
 * parse's seconds), of rendering 128x128 at one sample per
 * pixel with the default surface, and the peak resident memory; and the
 * bytes a face costs (issue 23: a mesh is one object): the scene's shared
 * arrays (points, indices, normals; a subdivision cage's control points)
 * and, beyond them, the pieces, their shared edges, a subdivision mesh's
 * own tables (geom/subdiv.h: its control faces, point -> corners and a
 * byte per refined face) and the BVH (its part printed apart: the budgets
 * are 64 bytes a face before any box and 32 of BVH), per face; and a
 * digest of the meshes' worlds (their BVHs and shared edges,
 * trace_mesh_digest: equal between builds that make the same world, to
 * hold a change to main's bits). Never fails on timing.
 *
 *   mesh_bench [max_faces [subdiv|displaced]]
 *                                     (default 100000; 1000000 and
 *                                      10000000 run the production rows;
 *                                      subdiv: the torus as a Catmull-Clark
 *                                      cage, 4 limit pieces a face;
 *                                      displaced: bumped by a noise shader,
 *                                      its root boxes made lazily, then
 *                                      again under a worker's default
 *                                      roots budget (the same image), then the
 *                                      world built again with all of them
 *                                      first, as before: "eager" rows)
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include <unistd.h>
#include <sys/resource.h>

#include "job/job.h"
#include "job/job_scene.h"
#include "trace/lazy_roots.h"
#include "trace/mesh.h"
#include "trace/render.h"

static double wall_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static long peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024;
}

/* The RIB text of a torus (radii 1 and 0.4) of nu x nv quads, a
 * PointsPolygons or (subdiv) a SubdivisionMesh. */
static char *torus_rib(int nu, int nv, bool subdiv, bool displaced, size_t *len)
{
    size_t cap = (size_t)nu * nv * 80 + 4096, n = 0;
    char *t = malloc(cap);
    if (!t) abort();
    n += (size_t)sprintf(t + n, "Format 128 128 1\nProjection \"perspective\" \"fov\" [40]\n"
                         "Translate 0 0 4\nRotate 60 1 0 0\nWorldBegin\n%s%s [",
                         displaced ? "Displacement \"bumps\"\n" : "",
                         subdiv ? "SubdivisionMesh \"catmull-clark\"" : "PointsPolygons");
    for (int i = 0; i < nu * nv; i++) n += (size_t)sprintf(t + n, "4 ");
    n += (size_t)sprintf(t + n, "]\n[");
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
            n += (size_t)sprintf(t + n, "%d %d %d %d ", i * nv + j, i * nv + j1, i1 * nv + j1,
                                 i1 * nv + j);
        }
    n += (size_t)sprintf(t + n, "]\n\"P\" [");
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double a = 2 * M_PI * i / nu, b = 2 * M_PI * j / nv, r = 1 + 0.4 * cos(b);
            n += (size_t)sprintf(t + n, "%.9g %.9g %.9g ", r * cos(a), r * sin(a), 0.4 * sin(b));
        }
    n += (size_t)sprintf(t + n, "]\nWorldEnd\n");
    *len = n;
    return t;
}

/* noise bumps along the normal (the displaced rows) */
static const char *BUMPS_SL =
    "displacement bumps(float Km = 0.03)\n"
    "{\n"
    "    P += Km * (noise(P * 8) - 0.5) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

/* The world of js built again with its root boxes made first (as before
 * they were made lazily): its wall seconds */
static double eager_world(job_scene *js)
{
    trace_renderer_destroy(&js->renderer);
    js->world.options.lazy_roots = false;
    char err[256];
    double t0 = wall_now();
    js->renderer = trace_renderer_new(&js->world, err, sizeof err);
    double t = wall_now() - t0;
    if (!js->renderer) { fprintf(stderr, "%s\n", err); exit(1); }
    return t;
}

/* Root boxes made so far, over the scene's meshes */
static long roots_known(const job_scene *js)
{
    long n = 0;
    for (int i = 0; i < js->world.nobjects; i++)
        if (js->world.objects[i].mesh && js->world.objects[i].mesh->lazy)
            n += trace_lazy_roots_known(js->world.objects[i].mesh->lazy);
    return n;
}

/* The 128x128 image at one sample per pixel into rgba (its covered
 * pixels into *hits): its CPU seconds */
static double render_128(job_scene *js, double *rgba, long *hits)
{
    double t0 = cpu_now();
    trace_thread *th = trace_thread_new(&js->world);
    *hits = 0;
    for (int y = 0; y < 128; y++)
        for (int x = 0; x < 128; x++) {
            double *px = rgba + 4 * (y * 128 + x), z;
            trace_render_sample(js->renderer, th, x + 0.5, y + 0.5, px, &px[3], &z);
            *hits += px[3] > 0;
        }
    trace_thread_destroy(&th);
    return cpu_now() - t0;
}

/* The world built again lazily under a worker's default roots budget
 * (4 MiB a thread: trace_options.roots_bytes, job_scene.c) and rendered
 * again: its seconds, the roots made (evicted ones again where rays come
 * back) and evicted, and the image
 * against the unlimited store's (the same, to the bit) */
static void budget_row(job_scene *js, int threads, const double *image, double render,
                       long made)
{
    trace_renderer_destroy(&js->renderer);
    js->world.options.roots_bytes = (size_t)threads << 22;
    char err[256];
    js->renderer = trace_renderer_new(&js->world, err, sizeof err);
    if (!js->renderer) { fprintf(stderr, "%s\n", err); exit(1); }
    double *again = malloc(sizeof *again * 128 * 128 * 4);
    if (!again) { fprintf(stderr, "out of memory\n"); exit(1); }
    long hits;
    double t = render_128(js, again, &hits);
    long evicted = 0, held = 0;
    size_t bytes = 0;
    for (int i = 0; i < js->world.nobjects; i++) {
        const trace_mesh *m = js->world.objects[i].mesh;
        if (!m || !m->lazy) continue;
        evicted += trace_lazy_roots_evicted(m->lazy);
        held += trace_lazy_roots_known(m->lazy);
        bytes += trace_lazy_roots_bytes(m->lazy);
    }
    int differ = 0;
    for (int i = 0; i < 128 * 128 * 4; i++) differ += image[i] != again[i];
    printf("%9s under a roots budget of %d MiB (a worker's default, %d threads): render %.3f s "
           "(unlimited %.3f), %ld roots made (unlimited %ld), %ld held in %zu bytes, %ld "
           "evicted; %d values differ from the unlimited store's image\n", "", 4 * threads,
           threads, t, render, held + evicted, made, held, bytes, evicted, differ);
    free(again);
    js->world.options.roots_bytes = 0;
}

int main(int argc, char **argv)
{
    int max_faces = argc > 1 ? atoi(argv[1]) : 100000;
    bool subdiv = argc > 2 && strcmp(argv[2], "subdiv") == 0;
    bool displaced = argc > 2 && strcmp(argv[2], "displaced") == 0;
    int threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (threads < 1) threads = 1;
    printf("%s torus; parse s: the parse over %d threads (wall seconds); parse+world s: "
           "job_scene_new as a worker runs it (the parse and the world over %d threads, wall "
           "seconds); world s: that less parse s\n",
           subdiv      ? "Catmull-Clark (SubdivisionMesh)"
           : displaced ? "PointsPolygons, displaced"
                       : "PointsPolygons",
           threads, threads);
    printf("%9s %8s %8s %13s %8s %8s %9s %12s %12s %9s %9s\n", "faces", "parse s", "world s",
           "parse+world s", "render s", "objects", "pieces", "shared B/f", "beyond B/f",
           "(BVH B/f)", "peak MiB");
    for (int faces = 1000; faces <= max_faces; faces *= 10) {
        int nv = (int)sqrt(faces / 2.5), nu = faces / nv;
        size_t len;
        char *text = torus_rib(nu, nv, subdiv, displaced, &len);
        job_options opt;
        job_options_default(&opt);
        job *jb = job_new("torus.rib", text, len, &opt);
        free(text);
        char why[256];
        if (displaced && (!job_add_source(jb, "bumps.sl", BUMPS_SL, strlen(BUMPS_SL), why,
                                          sizeof why) ||
                          !job_add_shader(jb, "bumps", "bumps.sl", why, sizeof why))) {
            fprintf(stderr, "%s\n", why);
            return 1;
        }
        if (!job_finish(jb, why, sizeof why)) { fprintf(stderr, "%s\n", why); return 1; }
        sl_diag *d = sl_diag_new();
        double t0 = wall_now();
        scene *s = scene_parse_frame_threads(jb->scene_file, jb->scene_text, jb->scene_len, NULL,
                                             SCENE_MAX_OBJECTS, 0, threads, NULL, d);
        double parse = wall_now() - t0;
        int nobj = s ? s->nobjects : 0;
        scene_destroy(&s);
        /* as a worker builds it: the parse again, then the world over
         * its threads (wall seconds) */
        t0 = wall_now();
        job_scene *js = job_scene_new_threads(jb, 0, true, threads, NULL, d);
        double world = wall_now() - t0;
        if (!js) { sl_diag_print(d, stderr); return 1; }
        long known_built = roots_known(js);
        double *image = malloc(sizeof *image * 128 * 128 * 4);
        if (!image) { fprintf(stderr, "out of memory\n"); return 1; }
        long hits = 0;
        double render = render_128(js, image, &hits);
        long known_rendered = roots_known(js);
        /* bytes: the scene's meshes (shared arrays and 16-byte pieces), the
         * world's per-piece arrays */
        size_t shared = 0, beyond = 0;
        long pieces = 0;
        for (int i = 0; i < js->scene->nmeshes; i++) {
            const scene_mesh *m = js->scene->meshes[i];
            size_t pb = scene_mesh_piece_bytes(m);
            size_t points, sdb = scene_mesh_subdiv_bytes(m, &points);
            shared += scene_mesh_bytes(m) - pb + points;
            beyond += pb + sdb - points;
            pieces += scene_mesh_npieces(m);
        }
        size_t bvh = 0;
        for (int i = 0; i < js->world.nobjects; i++) {
            const trace_mesh *tm = js->world.objects[i].mesh;
            if (!tm) continue;
            beyond += trace_mesh_bytes(tm);
            bvh += trace_float_bvh_bytes(tm->bvh, tm->npieces);
        }
        int f = nu * nv;
        uint64_t digest = 0;
        for (int i = 0; i < js->world.nobjects; i++)
            if (js->world.objects[i].mesh)
                digest ^= trace_mesh_digest(js->world.objects[i].mesh);
        printf("%9d %8.3f %8.3f %13.3f %8.3f %8d %9ld %12.1f %12.1f %9.1f %9ld   (%ld of 16384 "
               "pixels; world %016llx)\n",
               f, parse, world - parse, world, render, nobj, pieces, (double)shared / f,
               (double)beyond / f, (double)bvh / f, peak_mib(), hits,
               (unsigned long long)digest);
        if (displaced) {
            printf("%9s root boxes: %ld made with the world, %ld after the render\n", "",
                   known_built, known_rendered);
            budget_row(js, threads, image, render, known_rendered);
            printf("%9s the world built again with all %ld first (eager): %.3f s wall\n", "",
                   pieces, eager_world(js));
        }
        free(image);
        job_scene_destroy(&js);
        job_destroy(&jb);
        sl_diag_destroy(&d);
    }
    return 0;
}

/*
 * bench/instance_bench.c: the box cache memory of an instanced displaced
 * object against its copies (issue 14; docs/renderer.md "Instances share
 * one set of boxes"). N spheres bumped by scenes/shaders/lumpy.sl, each
 * moved and turned differently, on a grid seen from the front, written
 * once as N ObjectInstance of one definition and once as N separate
 * Sphere requests; 256 x 256 pixels at one sample per pixel on one thread
 * with an unlimited box cache. Prints the objects that share their
 * prototype's boxes (objects, or placements of a group: trace/group.h),
 * the bytes the scene and world hold (job_scene_new, with the allocator),
 * the cache's peak bytes and broods, the boxes computed and the render
 * CPU seconds. Never fails on timing. --mesh draws a Catmull-Clark cube
 * (24 limit pieces, a displaced mesh: its placements walk the prototype's
 * mesh, or have meshes of their own) instead of each sphere.
 *
 *   instance_bench [max_n] [--instances-only] [--mesh]
 *                              (N = 1, 4, 16, 64 up to max_n; default 64)
 */
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "job/job.h"
#include "job/job_scene.h"

enum { RES = 256 };

/* the primitive: a unit sphere, or (--mesh) a cube cage of side 1.6 */
static const char *SPHERE = "Sphere 1 -1 1 360";
static const char *CUBE =
    "SubdivisionMesh \"catmull-clark\" [4 4 4 4 4 4] "
    "[0 1 3 2 2 3 5 4 4 5 7 6 6 7 1 0 1 7 5 3 6 0 2 4] [] [] [] [] "
    "\"P\" [-0.8 -0.8 0.8  0.8 -0.8 0.8  -0.8 0.8 0.8  0.8 0.8 0.8  -0.8 0.8 -0.8  "
    "0.8 0.8 -0.8  -0.8 -0.8 -0.8  0.8 -0.8 -0.8]";
static const char *prim;

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static char *read_shader(const char *name, size_t *len)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.sl", AAFARM_SHADER_DIR, name);
    FILE *f = fopen(path, "rb");
    if (!f) { perror(path); exit(1); }
    char *t = malloc(1 << 16);
    if (!t) abort();
    *len = fread(t, 1, (1 << 16) - 1, f);
    fclose(f);
    return t;
}

/* n spheres on a k x k grid (k = ceil(sqrt(n))) filling the view */
static char *scene_rib(int n, bool instanced, size_t *len)
{
    int k = (int)ceil(sqrt(n));
    size_t cap = (size_t)n * (200 + strlen(prim)) + 4096, m = 0;
    char *t = malloc(cap);
    if (!t) abort();
    m += (size_t)snprintf(t + m, cap - m,
        "Format %d %d 1\nPixelSamples 1 1\nProjection \"perspective\" \"fov\" [40]\n"
        "Translate 0 0 %g\nWorldBegin\n"
        "LightSource \"distantlight\" 1 \"from\" [1 1 -2] \"to\" [0 0 0]\n"
        "Surface \"plastic\"\nDisplacement \"lumpy\" \"float Km\" [0.08] "
        "\"float frequency\" [7]\n", RES, RES, 2.9 * k);
    if (instanced)
        m += (size_t)snprintf(t + m, cap - m, "ObjectBegin 1\n%s\nObjectEnd\n", prim);
    for (int i = 0; i < n; i++)
        m += (size_t)snprintf(t + m, cap - m,
            "AttributeBegin\nTranslate %g %g 0\nRotate %d 0.3 1 0.2\n%s\nAttributeEnd\n",
            2.1 * (i % k - (k - 1) / 2.0), 2.1 * (i / k - (k - 1) / 2.0), 37 * i,
            instanced ? "ObjectInstance 1" : prim);
    m += (size_t)snprintf(t + m, cap - m, "WorldEnd\n");
    *len = m;
    return t;
}

/* bytes the allocator holds (glibc) */
static size_t heap_bytes(void)
{
    struct mallinfo2 mi = mallinfo2();
    return mi.uordblks + mi.hblkhd;
}

static int run(int n, bool instanced)
{
    size_t len, llen, plen;
    char *text = scene_rib(n, instanced, &len);
    char *lumpy = read_shader("lumpy", &llen), *plastic = read_shader("plastic", &plen);
    job_options opt;
    job_options_default(&opt);
    job *jb = job_new("instances.rib", text, len, &opt);
    char why[256];
    if (!job_add_source(jb, "lumpy.sl", lumpy, llen, why, sizeof why) ||
        !job_add_shader(jb, "lumpy", "lumpy.sl", why, sizeof why) ||
        !job_add_source(jb, "plastic.sl", plastic, plen, why, sizeof why) ||
        !job_add_shader(jb, "plastic", "plastic.sl", why, sizeof why) ||
        !job_finish(jb, why, sizeof why)) {
        fprintf(stderr, "%s\n", why);
        return 1;
    }
    free(text);
    free(lumpy);
    free(plastic);
    sl_diag *d = sl_diag_new();
    size_t before = heap_bytes();
    job_scene *js = job_scene_new(jb, 0, true, NULL, d);
    if (!js) { sl_diag_print(d, stderr); return 1; }
    size_t held = heap_bytes() - before;
    /* objects sharing a prototype's boxes, and placements (trace/group.h)
     * that are their prototype moved */
    int shared = 0;
    for (int i = 0; i < js->world.nobjects; i++) {
        const trace_object *o = &js->world.objects[i];
        shared += o->box_proto != NULL;
        if (o->group && o->group->own) shared += o->group->n - o->group->nown;
    }
    trace_thread *th = trace_thread_new(&js->world);
    double t0 = cpu_now();
    long covered = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            double rgb[3], a, z;
            trace_render_sample(js->renderer, th, x + 0.5, y + 0.5, rgb, &a, &z);
            covered += a > 0;
        }
    double secs = cpu_now() - t0;
    const trace_boxcache_stats *c = trace_boxcache_stats_get(th->cache);
    printf("%4d %-10s %7d %10.1f %12.1f %10zu %12ld %10.3f %9ld\n", n,
           instanced ? "instances" : "copies", shared, held / 1024.0, c->peak_bytes / 1024.0,
           c->peak_bytes / trace_boxcache_brood_bytes(), th->stats.boxes, secs, covered);
    trace_thread_destroy(&th);
    job_scene_destroy(&js);
    job_destroy(&jb);
    sl_diag_destroy(&d);
    return 0;
}

int main(int argc, char **argv)
{
    int max_n = 64;
    bool copies = true;
    prim = SPHERE;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--instances-only") == 0) copies = false;
        else if (strcmp(argv[i], "--mesh") == 0) prim = CUBE;
        else if (strcmp(argv[i], "--help") == 0 || atoi(argv[i]) <= 0) {
            fprintf(stderr, "usage: instance_bench [max_n] [--instances-only] [--mesh]\n"
                            "  N = 1, 4, 16 ... up to max_n (default 64) bumped spheres (--mesh:\n"
                            "  Catmull-Clark cubes), written as instances and (unless\n"
                            "  --instances-only) as copies\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        } else max_n = atoi(argv[i]);
    }
    printf("%4s %-10s %7s %10s %12s %10s %12s %10s %9s\n", "N", "written as", "shared",
           "scene KiB", "cache KiB", "broods", "boxes", "render s", "pixels");
    for (int n = 1; n <= max_n; n *= 4)
        for (int inst = 1; inst >= (copies ? 0 : 1); inst--)
            if (run(n, inst)) return 1;
    return 0;
}

/*
 * render_bench.c: the renderer against the figures of Heidrich & Seidel
 * 1998 §7 (Table 2): the paper's scenes at the paper's resolutions, one
 * thread, box cache budgets 40 KB / 400 KB / 4 MB / unlimited: seconds,
 * boxes per ray, shader evaluations per ray, cache behaviour; and the boxes
 * one UFO ray needs in affine and in interval arithmetic (the paper: 174
 * and 1450). Prints figures; never fails on time.
 *
 *   render_bench [--quick] [--scenes DIR]
 *
 * --quick renders at a quarter of the resolution (each axis / 2) with the
 * unlimited and 40 KB budgets only (the demo and CI smoke run).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "job/job.h"
#include "job/job_scene.h"
#include "trace/camera.h"
#include "trace/render.h"

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

typedef struct paper_row { const char *scene; double secs_1998; } paper_row;

static const paper_row PAPER[] = {
    {"wave", 66.2}, {"nail", 32.6}, {"ufo", 82.2},
};

static job_scene *open_scene(const char *dir, const char *name, trace_arith arith,
                             size_t cache, job **jb_out)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.rib", dir, name);
    job_options opt;
    job_options_default(&opt);
    opt.arith = arith;
    sl_diag *diag = sl_diag_new();
    job *jb = job_load(path, &opt, NULL, diag);
    job_scene *js = jb ? job_scene_new(jb, cache, true, NULL, diag) : NULL;
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    if (!js) job_destroy(&jb);
    *jb_out = jb;
    return js;
}

/* Renders the image with one thread, one sample per pixel at the pixel
 * centre (the paper's setting); returns CPU seconds, fills stats. */
static double render_once(job_scene *js, int shrink, trace_stats *st)
{
    trace_world *w = &js->world;
    int W = w->camera.xres / shrink, H = w->camera.yres / shrink;
    trace_thread *th = trace_thread_new(w);
    double t0 = cpu_now();
    const int tile = 16;
    for (int ty = 0; ty < H; ty += tile)
        for (int tx = 0; tx < W; tx += tile)
            for (int y = ty; y < ty + tile && y < H; y++)
                for (int x = tx; x < tx + tile && x < W; x++) {
                    double rgb[3], a, z;
                    trace_render_sample(js->renderer, th, (x + 0.5) * shrink, (y + 0.5) * shrink,
                                        rgb, &a, &z);
                }
    double secs = cpu_now() - t0;
    trace_thread_sync_stats(th);
    *st = th->stats;
    trace_thread_destroy(&th);
    return secs;
}

static long boxes_for_one_ray(const char *dir, const char *name, trace_arith arith)
{
    job *jb;
    job_scene *js = open_scene(dir, name, arith, 0, &jb);
    if (!js) return -1;
    trace_thread *th = trace_thread_new(&js->world);
    double rgb[3], a, z;
    /* the centre of the image: through the saucer */
    trace_render_sample(js->renderer, th, js->world.camera.xres * 0.5 + 0.25,
                        js->world.camera.yres * 0.5 + 0.25, rgb, &a, &z);
    long boxes = th->stats.boxes;
    trace_thread_destroy(&th);
    job_scene_destroy(&js);
    job_destroy(&jb);
    return boxes;
}

int main(int argc, char **argv)
{
    bool quick = false;
    const char *dir = "scenes";
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0) quick = true;
        else if (strcmp(argv[i], "--scenes") == 0 && i + 1 < argc) dir = argv[++i];
        else {
            fprintf(stderr, "usage: render_bench [--quick] [--scenes DIR]\n");
            return 2;
        }
    }
    const size_t budgets[] = {40 * 1024, 400 * 1024, 4 * 1024 * 1024, 0};
    const char *budget_names[] = {"40 KB", "400 KB", "4 MB", "unlimited"};
    /* unlimited first: the other budgets are given relative to it */
    const int order_full[] = {3, 0, 1, 2}, order_quick[] = {3, 0};
    const int *order = quick ? order_quick : order_full;
    int nb = quick ? 2 : 4;
    int shrink = quick ? 2 : 1;
    printf("render_bench: Heidrich & Seidel 1998 Table 2 layout; 1 thread, 1 ray per pixel%s\n",
           quick ? " (--quick: half resolution, 2 budgets)" : "");
    printf("%-6s %-10s %9s %8s %10s %10s %9s %10s %14s\n", "scene", "cache", "pixels",
           "cpu s", "boxes/ray", "evals/ray", "hit rate", "evictions", "compared");
    for (size_t s = 0; s < sizeof PAPER / sizeof PAPER[0]; s++) {
        double unlimited = 0;
        for (int bi = 0; bi < nb; bi++) {
            int b = order[bi];
            job *jb;
            job_scene *js = open_scene(dir, PAPER[s].scene, TRACE_ARITH_AFFINE, budgets[b], &jb);
            if (!js) return 1;
            trace_stats st;
            double secs = render_once(js, shrink, &st);
            long rays = st.primary_rays + st.shadow_rays;
            long lookups = st.cache_hits + st.cache_misses;
            char ratio[32] = "";
            if (budgets[b] == 0) {
                unlimited = secs;
                if (!quick) snprintf(ratio, sizeof ratio, "%.0fx 1998", PAPER[s].secs_1998 / secs);
            } else if (unlimited > 0) {
                snprintf(ratio, sizeof ratio, "%+.1f%% vs unl.", 100.0 * (secs / unlimited - 1));
            }
            printf("%-6s %-10s %4dx%-4d %8.2f %10.1f %10.1f %8.1f%% %10ld %14s\n", PAPER[s].scene,
                   budget_names[b], js->world.camera.xres / shrink, js->world.camera.yres / shrink,
                   secs, rays ? (double)st.boxes / rays : 0,
                   rays ? (double)(st.evals_affine + st.evals_dual + st.evals_float) / rays : 0,
                   lookups ? 100.0 * st.cache_hits / lookups : 0.0, st.cache_evictions, ratio);
            job_scene_destroy(&js);
            job_destroy(&jb);
        }
    }
    long aa = boxes_for_one_ray(dir, "ufo", TRACE_ARITH_AFFINE);
    long ia = boxes_for_one_ray(dir, "ufo", TRACE_ARITH_INTERVAL);
    printf("\none UFO ray through the image centre, empty cache: %ld boxes affine, %ld interval "
           "(%.1fx; the paper: 174 vs 1450, 8.3x)\n", aa, ia, aa > 0 ? (double)ia / aa : 0);
    return 0;
}

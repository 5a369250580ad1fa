/*
 * peers_aafarm.c: aafarm's image for the peer benchmark (bench/peers/):
 * renders a RIB scene through aafarm's own renderer (common/trace, the
 * library aafarm-worker runs) with ONE ray per pixel at the pixel CENTRE,
 * the ray POV-Ray and peers_embree shoot, instead of the worker's jittered
 * sample, so images can be compared pixel by pixel. One thread, 16x16
 * tiles in raster order like a worker's tile.
 *
 *   peers_aafarm SCENE.rib OUT.png [--leaf F] [--cache-bytes B]
 *
 * --leaf F  stop subdividing at boxes of F pixels (default 1, the
 *           renderer's own setting; the benchmark's reference uses 1/16:
 *           Heidrich & Seidel §3's pixel-sized termination made 16x finer,
 *           so the shading point lies within 1/32 pixel of the true hit)
 *
 * Prints one line of figures: "render_cpu_s R boxes_per_ray B
 * cache_peak_bytes C hits H".
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "job/job.h"
#include "job/job_scene.h"
#include "peers_png.h"
#include "trace/render.h"

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int usage(void)
{
    fprintf(stderr, "usage: peers_aafarm SCENE.rib OUT.png [--leaf F] [--cache-bytes B]\n");
    return 2;
}

int main(int argc, char **argv)
{
    if (argc < 3) return usage();
    const char *rib = argv[1], *out = argv[2];
    double leaf = 1.0;
    size_t cache = 0;
    for (int i = 3; i < argc; i++) {
        char *end = NULL;
        if (strcmp(argv[i], "--leaf") == 0 && i + 1 < argc) {
            leaf = strtod(argv[++i], &end);
            if (*end || !(leaf > 0 && leaf <= 1)) {
                fprintf(stderr, "peers_aafarm: --leaf wants a number in (0, 1], got '%s'\n", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--cache-bytes") == 0 && i + 1 < argc) {
            cache = (size_t)strtoull(argv[++i], &end, 10);
            if (*end) {
                fprintf(stderr, "peers_aafarm: --cache-bytes wants a byte count, got '%s'\n", argv[i]);
                return 2;
            }
        } else {
            return usage();
        }
    }
    job_options opt;
    job_options_default(&opt);
    sl_diag *diag = sl_diag_new();
    job *jb = job_load(rib, &opt, NULL, diag);
    job_scene *js = jb ? job_scene_new(jb, cache, false, NULL, diag) : NULL;
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    if (!js) {
        job_destroy(&jb);
        return 3;
    }
    char err[512];
    js->world.options.leaf_fraction = leaf;
    js->renderer = trace_renderer_new(&js->world, err, sizeof err);
    if (!js->renderer) {
        fprintf(stderr, "peers_aafarm: %s: %s\n", rib, err);
        job_scene_destroy(&js);
        job_destroy(&jb);
        return 1;
    }
    int W = js->world.camera.xres, H = js->world.camera.yres;
    float *img = calloc((size_t)W * (size_t)H * 4, sizeof *img);
    if (!img) abort();
    trace_thread *th = trace_thread_new(&js->world);
    long hits = 0;
    double t0 = cpu_now();
    const int tile = 16;
    for (int ty = 0; ty < H; ty += tile)
        for (int tx = 0; tx < W; tx += tile)
            for (int y = ty; y < ty + tile && y < H; y++)
                for (int x = tx; x < tx + tile && x < W; x++) {
                    double rgb[3], a, z;
                    trace_render_sample(js->renderer, th, x + 0.5, y + 0.5, rgb, &a, &z);
                    float *p = &img[((size_t)y * (size_t)W + (size_t)x) * 4];
                    for (int k = 0; k < 3; k++) p[k] = (float)(rgb[k] * js->world.gain);
                    p[3] = (float)a;
                    hits += a > 0.5;
                }
    double secs = cpu_now() - t0;
    int rc = 0;
    if (th->failed) {
        fprintf(stderr, "peers_aafarm: %s: render failed: %s\n", rib, th->error);
        rc = 1;
    }
    trace_thread_sync_stats(th);
    trace_stats st = th->stats;
    long rays = st.primary_rays + st.shadow_rays;
    if (rc == 0 && !peers_png_write(out, W, H, img, err, sizeof err)) {
        fprintf(stderr, "peers_aafarm: %s\n", err);
        rc = 1;
    }
    if (rc == 0)
        printf("render_cpu_s %.4f boxes_per_ray %.3f cache_peak_bytes %zu hits %ld\n", secs,
               rays ? (double)st.boxes / (double)rays : 0.0, st.cache_peak_bytes, hits);
    trace_thread_destroy(&th);
    free(img);
    job_scene_destroy(&js);
    job_destroy(&jb);
    return rc;
}

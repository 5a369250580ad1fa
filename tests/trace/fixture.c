/*
 * fixture.c: in-memory jobs for renderer tests (see fixture.h).
 */
#include "fixture.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool fixture_open(fixture *f, const char *rib, const fixture_shader *shaders,
                  int nshaders, const job_options *opt, size_t cache_bytes)
{
    memset(f, 0, sizeof *f);
    f->diag = sl_diag_new();
    f->job = job_new("test.rib", rib, strlen(rib), opt);
    char why[256];
    for (int i = 0; i < nshaders; i++) {
        char file[128];
        snprintf(file, sizeof file, "%s.sl", shaders[i].name);
        if (!job_add_source(f->job, file, shaders[i].source, strlen(shaders[i].source), why, sizeof why) ||
            !job_add_shader(f->job, shaders[i].name, file, why, sizeof why)) {
            fprintf(stderr, "fixture: %s\n", why);
            return false;
        }
    }
    if (!job_finish(f->job, why, sizeof why)) {
        fprintf(stderr, "fixture: %s\n", why);
        return false;
    }
    f->js = job_scene_new(f->job, cache_bytes, true, NULL, f->diag);
    if (!f->js) {
        sl_diag_print(f->diag, stderr);
        return false;
    }
    return true;
}

void fixture_close(fixture *f)
{
    job_scene_destroy(&f->js);
    job_destroy(&f->job);
    sl_diag_destroy(&f->diag);
}

bool fixture_render(fixture *f, int tile, int nthreads, size_t cache_bytes,
                    float *rgba, float *z)
{
    trace_world *w = &f->js->world;
    size_t saved = w->options.cache_bytes;
    w->options.cache_bytes = cache_bytes;
    trace_thread **th = calloc((size_t)nthreads, sizeof *th);
    for (int i = 0; i < nthreads; i++) th[i] = trace_thread_new(w);
    w->options.cache_bytes = saved;
    int W = w->camera.xres, H = w->camera.yres, k = 0;
    bool ok = true;
    float *trgba = malloc(sizeof(float) * 4 * (size_t)tile * (size_t)tile);
    float *tz = malloc(sizeof(float) * (size_t)tile * (size_t)tile);
    for (int y0 = 0; y0 < H && ok; y0 += tile)
        for (int x0 = 0; x0 < W && ok; x0 += tile) {
            int tw = x0 + tile <= W ? tile : W - x0, thh = y0 + tile <= H ? tile : H - y0;
            trace_thread *t = th[k++ % nthreads];
            if (!trace_render_tile(f->js->renderer, t, x0, y0, tw, thh, trgba, tz)) {
                fprintf(stderr, "fixture: %s\n", t->error);
                ok = false;
                break;
            }
            for (int y = 0; y < thh; y++) {
                memcpy(&rgba[((size_t)(y0 + y) * (size_t)W + (size_t)x0) * 4],
                       &trgba[(size_t)y * (size_t)tw * 4], sizeof(float) * 4 * (size_t)tw);
                memcpy(&z[(size_t)(y0 + y) * (size_t)W + (size_t)x0],
                       &tz[(size_t)y * (size_t)tw], sizeof(float) * (size_t)tw);
            }
        }
    free(trgba);
    free(tz);
    for (int i = 0; i < nthreads; i++) trace_thread_destroy(&th[i]);
    free(th);
    return ok;
}

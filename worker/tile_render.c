/*
 * tile_render.c: one tile through the renderer into an image_tile.
 */
#include "tile_render.h"
#include "util/err.h"

#include <stdio.h>

image_tile *worker_filter_tile(const job_scene *js, const trace_tile_samples *ts,
                               image_rect rect, unsigned layers,
                               worker_nonfinite *nonfinite, char *err, size_t errsz)
{
    nonfinite->count = 0;
    image_tile *tile = image_tile_new(rect.x0, rect.y0, rect.w, rect.h, layers);
    if (!tile) {
        err_set(err, errsz, "cannot allocate a %dx%d tile", rect.w, rect.h);
        return NULL;
    }
    trace_tile_samples_filter(js->renderer, ts, tile->rgba, tile->z);
    nonfinite->count = image_tile_clear_nonfinite(tile, &nonfinite->x, &nonfinite->y);
    return tile;
}

image_tile *worker_render_tile(const job_scene *js, trace_thread *th,
                               image_rect rect, unsigned layers,
                               worker_nonfinite *nonfinite,
                               char *err, size_t errsz)
{
    nonfinite->count = 0;
    trace_tile_samples *ts = trace_tile_samples_new(js->renderer, rect.x0, rect.y0,
                                                    rect.w, rect.h);
    bool ok = true;
    for (int b = 0; ok && b < trace_tile_samples_blocks(ts); b++)
        ok = trace_tile_samples_trace(js->renderer, th, ts, b);
    image_tile *tile = NULL;
    if (!ok) {
        err_set(err, errsz, "tile at (%d,%d): %s", rect.x0, rect.y0, th->error);
        th->failed = false;
        th->error[0] = '\0';
    } else {
        tile = worker_filter_tile(js, ts, rect, layers, nonfinite, err, errsz);
    }
    trace_tile_samples_destroy(&ts);
    return tile;
}

void worker_print_shader_line(void *ctx, const char *text)
{
    (void)ctx;
    fputs(text, stderr);
}

void worker_log_warning(void *user, const char *message)
{
    (void)user;
    fprintf(stderr, "aafarm: warning: %s\n", message);
}

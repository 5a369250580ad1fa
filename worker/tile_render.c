/*
 * tile_render.c: a tile's traced samples into an image_tile (trace/render.h
 * traces them, tile_share.h shares the tracing between threads).
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

/*
 * tile_render.c: one tile through the renderer into an image_tile.
 */
#include "tile_render.h"
#include "util/err.h"

#include <stdio.h>

image_tile *worker_render_tile(const job_scene *js, trace_thread *th,
                               image_rect rect, unsigned layers,
                               worker_nonfinite *nonfinite,
                               char *err, size_t errsz)
{
    nonfinite->count = 0;
    image_tile *tile = image_tile_new(rect.x0, rect.y0, rect.w, rect.h, layers);
    if (!tile) {
        err_set(err, errsz, "cannot allocate a %dx%d tile", rect.w, rect.h);
        return NULL;
    }
    if (!trace_render_tile(js->renderer, th, rect.x0, rect.y0, rect.w, rect.h,
                           tile->rgba, tile->z)) {
        err_set(err, errsz, "tile at (%d,%d): %s", rect.x0, rect.y0, th->error);
        th->failed = false;
        th->error[0] = '\0';
        image_tile_destroy(&tile);
        return NULL;
    }
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

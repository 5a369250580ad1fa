/*
 * tile_render.h: a tile of a job from its traced samples into an
 * image_tile (the worker's unit of work, in the farm and standalone
 * alike; the tracing: tile_share.h), and where the renderer's warnings
 * and shaders' printf() lines go.
 */
#ifndef WORKER_TILE_RENDER_H
#define WORKER_TILE_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image/tile.h"
#include "job/job_scene.h"
#include "trace/render.h"
#include "trace/thread.h"

/* Non-finite samples found in a tile and written as 0 (image/tile.h,
 * image_tile_clear_nonfinite): how many, and the first one's pixel. */
typedef struct worker_nonfinite {
    uint64_t count;
    int x, y;
} worker_nonfinite;

/* The tile of rectangle `rect` with the given layers from its traced
 * samples (every block of ts traced, by any threads: trace/render.h).
 * NaN and infinite samples of the film are made safe here, at the film,
 * and counted in *nonfinite (the renderer itself is not asked to avoid
 * them). NULL when the tile cannot be allocated (err says so). */
image_tile *worker_filter_tile(const job_scene *js, const trace_tile_samples *ts,
                               image_rect rect, unsigned layers,
                               worker_nonfinite *nonfinite, char *err, size_t errsz);

/* The renderer's warnings (trace_renderer_set_log) on stderr, as
 * "aafarm: warning: <message>". */
void worker_log_warning(void *user, const char *message);

/* Shaders' printf() lines (trace_thread_set_print) on stderr, as written. */
void worker_print_shader_line(void *ctx, const char *text);

#endif

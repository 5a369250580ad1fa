/*
 * tile_render.h: rendering one tile of a job into an image_tile (the
 * worker's unit of work, in the farm and standalone alike).
 */
#ifndef WORKER_TILE_RENDER_H
#define WORKER_TILE_RENDER_H

#include <stdbool.h>
#include <stddef.h>

#include "image/tile.h"
#include "job/job_scene.h"
#include "trace/thread.h"

/* Renders rectangle `rect` with the given layers. NULL on failure (a
 * shader over its budget ...), with the reason in err. */
image_tile *worker_render_tile(const job_scene *js, trace_thread *th,
                               image_rect rect, unsigned layers,
                               char *err, size_t errsz);

#endif

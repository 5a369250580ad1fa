/*
 * render.h: rendering tiles of an image (the part of the renderer a worker
 * thread calls).
 *
 *   trace_renderer   the prepared world (root boxes, BVH); shared, read-only
 *   trace_thread     per-thread state (thread.h)
 *   trace_render_tile  one tile: primary rays for every sample of every
 *                    pixel whose filter reaches the tile, shading with
 *                    shadows, pixel filter, exposure
 *   trace_tile_samples one tile traced in blocks by several threads
 *
 * Determinism (DESIGN.md §2): a pixel's value depends only on the world and
 * the pixel: samples are hashed from (pixel, index), a sample outside the
 * tile that the filter needs is traced again rather than borrowed, and the
 * box cache only changes speed.
 */
#ifndef TRACE_RENDER_H
#define TRACE_RENDER_H

#include <stdatomic.h>
#include <stdbool.h>

#include "trace/bvh.h"
#include "trace/thread.h"
#include "trace/world.h"

/* Where the renderer's warnings go (a line without the program's prefix,
 * e.g. "light 0 (shader 'spot'): shadow map 'spot.shd' does not exist; ...").
 * Called from any render thread; the library never prints itself. */
typedef void (*trace_log_fn)(void *user, const char *message);

typedef struct trace_renderer {
    const trace_world *world;
    trace_bvh *bvh;
    trace_tolerance primary_tol;
    /* shadow() without a shadow map, answered by a traced ray: warned
     * once per light (world->nlights entries, then one for surface
     * shaders' illuminance loops), by whichever thread comes first */
    atomic_uchar *shadow_warned;
    trace_log_fn log;     /* warnings (NULL: dropped); trace_renderer_set_log */
    void *log_user;
} trace_renderer;

/* Computes every object's scale, root box (through its displacement
 * shader, in the world's arithmetic) and camera-space bound, then builds
 * the BVH. The world must stay alive and unchanged while the renderer
 * exists. On a shader failure returns NULL with the message in err. */
trace_renderer *trace_renderer_new(trace_world *world, char *err, size_t errsz);
void trace_renderer_destroy(trace_renderer **self_p);

/* Hands the renderer's warnings to fn(user, message) (before rendering). */
void trace_renderer_set_log(trace_renderer *self, trace_log_fn fn, void *user);

/* Renders pixels [x0, x0+w) x [y0, y0+h): rgba gets 4 floats per pixel
 * (premultiplied, exposure applied), z one float (camera-space depth of the
 * nearest sample of the pixel; +inf where nothing was hit). Returns false
 * when a shader failed (th->error says why); the buffers are then garbage. */
bool trace_render_tile(const trace_renderer *self, trace_thread *th,
                       int x0, int y0, int w, int h, float *rgba, float *z);

/* The same tile in parts, so that several threads can trace one tile (the
 * standalone renderer's threads left without tiles at the end of a frame
 * help the tiles still being traced: worker/standalone.c). A tile's samples
 * fall into trace_tile_samples_blocks() blocks of TRACE_TILE_BLOCK
 * consecutive Morton indices (8 x 8 pixels); each block is traced once, by
 * any thread with its own trace_thread (blocks write disjoint samples),
 * then one thread filters them into rgba and z as trace_render_tile does.
 * A sample is a pure function of its pixel and index: who traces a block
 * changes no bit of the tile. trace_tile_samples_trace returns false when
 * a shader failed (th->error) or th was cancelled. */
enum { TRACE_TILE_BLOCK = 64 };
typedef struct trace_tile_samples trace_tile_samples;
trace_tile_samples *trace_tile_samples_new(const trace_renderer *self, int x0, int y0,
                                           int w, int h);
int trace_tile_samples_blocks(const trace_tile_samples *ts);
bool trace_tile_samples_trace(const trace_renderer *self, trace_thread *th,
                              trace_tile_samples *ts, int block);
void trace_tile_samples_filter(const trace_renderer *self, const trace_tile_samples *ts,
                               float *rgba, float *z);
void trace_tile_samples_destroy(trace_tile_samples **ts_p);

/* One primary sample at raster (x, y): colour, alpha, depth. For tests.
 * Through the lens centre (a pinhole). */
void trace_render_sample(const trace_renderer *self, trace_thread *th,
                         double x, double y, double rgb[3], double *alpha,
                         double *z);
/* The same from lens position (lu, lv) in [0,1)^2 (camera.h). */
void trace_render_sample_lens(const trace_renderer *self, trace_thread *th, double x,
                              double y, double lu, double lv, double rgb[3], double *alpha,
                              double *z);

#endif

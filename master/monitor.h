/*
 * monitor.h: what the live monitor shows (docs/farm.md "Watching a
 * render"), held between two threads: the master's loop, which is the
 * only writer, and the HTTP server's thread (http_server.c), which only
 * reads. One mutex guards everything here; nothing here points into the
 * master's own state (the farm, the scheduler, the registry), so the HTTP
 * thread never touches what the loop changes without the lock.
 *
 *   documents  JSON texts the loop builds and publishes whole (the
 *              status and the worker list, farm_monitor.c); a reader gets
 *              a copy of the latest one;
 *   images     per frame, the image so far as 8-bit sRGB (the conversion
 *              of image/preview.h): tiles not in yet are black; every
 *              tile taken is decoded and put here. A reader gets it as a
 *              PNG, encoded outside the lock and cached until the next
 *              tile, so the PNG of a complete frame is the same bytes as
 *              its --preview file.
 *
 * Memory: an image wider or taller than MONITOR_MAX_SIDE pixels is kept
 * at 1/k of its size (every k-th pixel, k the smallest that fits). Frames
 * of a sequence get their image when their first tile arrives; beyond
 * MONITOR_MAX_IMAGES held, the image of the earliest complete frame is
 * dropped (its PNG is then refused with the reason).
 *
 * Ready for more than one render (a job queue): a monitor is per render
 * today; the documents are opaque texts and frames are numbered, so a
 * queue can hold one per job.
 */
#ifndef MASTER_MONITOR_H
#define MASTER_MONITOR_H

#include <stdbool.h>
#include <stddef.h>

#include "image/format.h"

enum { MONITOR_MAX_SIDE = 4096, MONITOR_MAX_IMAGES = 16 };

typedef enum monitor_doc {
    MONITOR_STATUS,      /* GET /api/status */
    MONITOR_WORKERS,     /* GET /api/workers */
    MONITOR_NDOCS
} monitor_doc;

typedef struct monitor monitor;

monitor *monitor_new(void);
void monitor_destroy(monitor **self_p);

/* ---- the master's loop ---- */

/* A frame of width x height pixels (before any reader); its index. */
int monitor_add_frame(monitor *self, int width, int height);

/* Tile rectangle r of frame `frame` is in: rgba holds its r.w x r.h
 * pixels, 4 floats each (image_tile_decode_rgba). */
void monitor_put_tile(monitor *self, int frame, image_rect r, const float *rgba);

/* Every tile of the frame is in (its image may be dropped later, see
 * above). */
void monitor_frame_complete(monitor *self, int frame);

/* Replaces a document with text (len bytes; the monitor takes it: it was
 * allocated with malloc or util/xalloc.h). */
void monitor_publish(monitor *self, monitor_doc doc, char *text, size_t len);

/* ---- any thread ---- */

/* A copy of the latest document (the caller frees), or NULL when none was
 * published yet. */
char *monitor_doc_copy(monitor *self, monitor_doc doc, size_t *len);

/* The frame's image so far as a PNG (the caller frees *png). False with
 * the reason in err: no such frame (*missing set), its image dropped, or
 * the encoder failed. */
bool monitor_png(monitor *self, int frame, void **png, size_t *len, bool *missing, char *err,
                 size_t errsz);

#endif

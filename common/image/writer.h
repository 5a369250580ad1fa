/*
 * writer.h: the output image, a tiled OpenEXR file written tile by tile in
 * any order (image_writer).
 *
 * Used by the master (tiles arrive from workers as one-tile EXR files:
 * image_writer_put_exr_chunk) and by the standalone renderer (tiles are
 * float buffers: image_writer_put_tile). Both paths produce the same chunk
 * bytes for the same pixels, so a farm render and a standalone render of a
 * scene give files with identical chunks.
 *
 * The file (format.h for the channels): single part, tiled, ONE_LEVEL,
 * line order RANDOM_Y (chunks are stored in the order they arrive; the
 * chunk offset table says where each one is), ZIP. Chunks go to disk as
 * they come; memory use is the offset table and one byte per tile, not
 * the image. Writing happens in "OUT.exr.tmp-<pid>" (outfile.h); only
 * image_writer_finish() renames it to OUT.exr, after every tile is in and
 * the offset table is written. image_writer_destroy() before that is an
 * abort: the temporary file is removed and an existing OUT.exr is left as
 * it was.
 *
 * A tile that is already in the file is ignored (returns true): by the
 * determinism contract a tile rendered twice (a retry) has the same bytes.
 * A write error (disk full) makes the writer unusable: every later call
 * fails with that error, and finish removes the temporary file.
 * Not thread-safe: one thread owns a writer.
 */
#ifndef IMAGE_WRITER_H
#define IMAGE_WRITER_H

#include <stdbool.h>
#include <stddef.h>

#include "image/format.h"
#include "image/tile.h"

typedef struct image_writer image_writer;

/* Creates path's temporary file and writes the header; NULL with the
 * reason in err. */
image_writer *image_writer_new(const char *path, const image_format *fmt,
                               char *err, size_t errsz);

/* Aborts an unfinished writer: removes the temporary file. */
void image_writer_destroy(image_writer **self_p);

/* Compresses and writes one tile (a tile of the format's grid with the
 * format's layers). */
bool image_writer_put_tile(image_writer *self, const image_tile *tile,
                           char *err, size_t errsz);

/* Validates bytes/len as the one-tile EXR file of rectangle `expect`
 * (image_tile_validate_exr) and copies its compressed chunk into the file
 * unchanged. A rejected tile leaves the writer as it was. */
bool image_writer_put_exr_chunk(image_writer *self, const void *bytes,
                                size_t len, image_rect expect,
                                char *err, size_t errsz);

/* True once a write to the file failed (disk full, I/O error): the
 * writer's own fault, never the tile's. A false return of a put call with
 * this still false means the tile was rejected and the writer is fine. */
bool image_writer_failed(const image_writer *self);

/* Copies a compressed chunk that was validated before (a chunk
 * image_tile_exr_chunk() returned, kept in the master's journal) into the
 * file as tile (tx, ty). */
bool image_writer_put_chunk(image_writer *self, int tx, int ty, const void *chunk,
                            size_t chunk_len, char *err, size_t errsz);

bool image_writer_has_tile(const image_writer *self, int tx, int ty);
int image_writer_tiles_written(const image_writer *self);
const image_format *image_writer_format(const image_writer *self);
const char *image_writer_temp_path(const image_writer *self);

/* When every tile is written: writes the offset table, closes the file and
 * renames it to its final name; destroys the writer (*self_p = NULL) and
 * returns whether the file is in place. When tiles are missing: returns
 * false and leaves the writer untouched (err names the first missing
 * tile), so work is never lost by an early call. */
bool image_writer_finish(image_writer **self_p, char *err, size_t errsz);

#endif

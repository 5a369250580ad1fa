/*
 * tile.h: one rendered tile (image_tile) and its journey over the network
 * as a complete, self-contained OpenEXR file held in memory.
 *
 * A worker renders a tile into float buffers, then encodes it with
 * image_tile_encode_exr() into the bytes of a one-tile EXR file (no temp
 * file: a custom write stream). That file is designed so that its only
 * chunk is byte-for-byte the chunk the output file needs at the same tile
 * position: same tile size, same channels and types, same compression and
 * ZIP level, and data window = the tile's rectangle in full-image
 * coordinates (display window = the whole image). The master therefore
 * never decodes and re-encodes a tile: after image_tile_validate_exr() it
 * copies the compressed chunk into the output file (writer.h).
 *
 * The bytes come from the network and are untrusted. Validation never
 * crashes and rejects, with a one-line reason, anything but a tile file
 * this version of aafarm would write for the expected rectangle: the
 * header must be byte-identical to the expected header (so magic, version
 * flags, tiling, tile size, data and display windows, channels, types and
 * compression are all checked before OpenEXRCore parses anything), the
 * chunk offset table and chunk leader must point exactly at the chunk, the
 * chunk must fill the rest of the bytes, and the chunk must decompress
 * cleanly (zlib's checks) to exactly the expected unpacked size. The
 * samples are not converted: any bit pattern is a valid half or float.
 * Cost on the master: about 0.05 ms for a 32x32 tile, 13 ms for 512x512
 * (bench/tile_validate_bench).
 *
 * Buffers of an image_tile are row-major, w*h pixels, row y of the tile
 * first at index y*w: rgba 4 floats per pixel (R G B A, premultiplied),
 * z 1, n and p 3 (x y z) when their layer is on, NULL otherwise. R G B A
 * are stored as HALF in the file (rounded to nearest even by OpenEXR),
 * Z, N and P as FLOAT (exact).
 */
#ifndef IMAGE_TILE_H
#define IMAGE_TILE_H

#include <stdbool.h>
#include <stddef.h>

#include "image/format.h"

typedef struct image_tile {
    int x0, y0;        /* top-left pixel in full-image coordinates */
    int w, h;          /* size in pixels */
    unsigned layers;   /* IMAGE_LAYER_* flags */
    float *rgba;       /* 4 per pixel */
    float *z;          /* 1 per pixel */
    float *n;          /* 3 per pixel, or NULL without IMAGE_LAYER_N */
    float *p;          /* 3 per pixel, or NULL without IMAGE_LAYER_P */
} image_tile;

/* A tile with zeroed buffers; NULL when the size is not 1..
 * IMAGE_MAX_TILE_SIZE or the layers are unknown (a few MB at most: out of
 * memory aborts, util/xalloc.h). */
image_tile *image_tile_new(int x0, int y0, int w, int h, unsigned layers);
void image_tile_destroy(image_tile **self_p);

image_rect image_tile_rect(const image_tile *self);

/* Encodes the tile as a one-tile EXR file of image `fmt` (the tile must be
 * a tile of fmt's grid and have fmt's layers). On success *bytes (the
 * caller frees) and *len hold the file. Same pixels, same bytes. */
/* Non-finite samples (a surface shader dividing by zero, overflowing...)
 * made safe before the tile is written: NaN, +Inf and -Inf in RGBA, N and P
 * become 0; in Z, NaN and -Inf become +Inf ("nothing hit", what Z holds
 * where no object is) while +Inf stays. Returns how many samples were
 * changed; the first one's pixel goes to *first_x, *first_y (full-image
 * coordinates; untouched when none). */
size_t image_tile_clear_nonfinite(image_tile *self, int *first_x, int *first_y);

bool image_tile_encode_exr(const image_tile *self, const image_format *fmt,
                           void **bytes, size_t *len, char *err, size_t errsz);

/* image_tile_encode_exr, and *chunk, *chunk_len point at the compressed
 * chunk inside *bytes (what the output writer copies: the standalone
 * renderer's threads compress their tiles before taking the writer's
 * lock). Located, not checked as image_tile_exr_chunk checks a file from
 * elsewhere: this process's own encoder wrote it (asserts hold the
 * layout). */
bool image_tile_encode_chunk(const image_tile *self, const image_format *fmt,
                             void **bytes, size_t *len, const void **chunk,
                             size_t *chunk_len, char *err, size_t errsz);

/* True when bytes/len is the tile file of rectangle `expect` of image
 * `fmt`, as described above; otherwise false with the reason in err. */
bool image_tile_validate_exr(const void *bytes, size_t len,
                             const image_format *fmt, image_rect expect,
                             char *err, size_t errsz);

/* Validates like image_tile_validate_exr() and on success points *chunk
 * and *chunk_len at the compressed chunk data inside bytes (what the
 * output writer copies). */
bool image_tile_exr_chunk(const void *bytes, size_t len,
                          const image_format *fmt, image_rect expect,
                          const void **chunk, size_t *chunk_len,
                          char *err, size_t errsz);

/* Decodes the R, G, B, A samples of the compressed chunk of tile rectangle
 * r (a chunk image_tile_exr_chunk() pointed at, or one kept in the
 * master's journal) into rgba: r.w x r.h pixels of 4 floats, row-major,
 * the halves of the file converted exactly. For the master's live image
 * (master/monitor.h); false with the reason in err when it does not
 * decode. */
bool image_tile_decode_rgba(const image_format *fmt, image_rect r,
                            const void *chunk, size_t chunk_len, float *rgba,
                            char *err, size_t errsz);

#endif

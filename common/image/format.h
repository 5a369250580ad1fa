/*
 * format.h: the shape of an aafarm output image (image_format) and the
 * rectangles it is cut into (image_rect, the tile grid).
 *
 * Every image aafarm writes is a tiled OpenEXR file: width x height pixels,
 * data window = display window = (0,0)-(width-1,height-1), square tiles of
 * tile_size pixels (ONE_LEVEL, no mipmaps), ZIP compression, and a fixed
 * set of channels chosen by `layers`:
 *
 *     A B G R   HALF    always (premultiplied colour and coverage)
 *     Z         FLOAT   always (camera-space depth; +inf where nothing hit)
 *     N.x N.y N.z FLOAT when IMAGE_LAYER_N (shading normal)
 *     P.x P.y P.z FLOAT when IMAGE_LAYER_P (hit position)
 *
 * listed here in the order an EXR channel list requires (sorted by name,
 * strcmp order). Tile (tx, ty) covers pixels x0 = tx*tile_size,
 * y0 = ty*tile_size, of size min(tile_size, width-x0) x min(tile_size,
 * height-y0): tiles at the right and bottom edges are smaller. The same
 * grid is used by workers (what they render), the master (what it asks
 * for and checks) and the output file (OpenEXR's own tile grid), so a
 * tile's compressed bytes fit the output file unchanged (see tile.h).
 */
#ifndef IMAGE_FORMAT_H
#define IMAGE_FORMAT_H

#include <stdbool.h>
#include <stddef.h>

/* Optional layers (bit flags); RGBA and Z are always present. */
enum {
    IMAGE_LAYER_N = 1u << 0,   /* N.x N.y N.z */
    IMAGE_LAYER_P = 1u << 1,   /* P.x P.y P.z */
    IMAGE_LAYERS_ALL = IMAGE_LAYER_N | IMAGE_LAYER_P
};

/* Limits: generous for renders, small enough that no size computation
 * overflows and that a tile's buffers stay a few tens of MB at most. */
enum {
    IMAGE_MAX_SIZE = 65536,        /* width, height */
    IMAGE_MAX_TILE_SIZE = 1024,    /* tile_size */
    IMAGE_MAX_TILES = 1 << 22,     /* tiles per image */
    IMAGE_MAX_CHANNELS = 11        /* A B G N.x N.y N.z P.x P.y P.z R Z */
};

typedef struct image_format {
    int width, height;     /* pixels */
    int tile_size;         /* tile edge in pixels */
    unsigned layers;       /* IMAGE_LAYER_* flags */
} image_format;

/* A rectangle of pixels in full-image coordinates. */
typedef struct image_rect {
    int x0, y0;            /* top-left pixel */
    int w, h;              /* size in pixels */
} image_rect;

/* Where a channel's values come from in an image_tile (tile.h). */
typedef enum image_source {
    IMAGE_SOURCE_RGBA,     /* tile->rgba, 4 floats per pixel */
    IMAGE_SOURCE_Z,        /* tile->z, 1 float per pixel */
    IMAGE_SOURCE_N,        /* tile->n, 3 floats per pixel */
    IMAGE_SOURCE_P         /* tile->p, 3 floats per pixel */
} image_source;

typedef enum image_pixel_type {
    IMAGE_PIXEL_HALF,      /* 16-bit float in the file */
    IMAGE_PIXEL_FLOAT      /* 32-bit float in the file */
} image_pixel_type;

typedef struct image_channel {
    const char *name;          /* EXR channel name */
    image_pixel_type type;     /* storage type in the file */
    image_source source;       /* which tile buffer */
    int component;             /* index within a pixel of that buffer */
} image_channel;

/* True when the format is usable (sizes within limits, known layers);
 * otherwise false with a one-line reason in err. */
bool image_format_check(const image_format *self, char *err, size_t errsz);

int image_format_tiles_x(const image_format *self);
int image_format_tiles_y(const image_format *self);
int image_format_tile_count(const image_format *self);

/* The rectangle of tile (tx, ty); tx, ty must be inside the grid. */
image_rect image_format_tile_rect(const image_format *self, int tx, int ty);

/* When `rect` is exactly one tile of the grid, stores its index in
 * *tx, *ty and returns true; otherwise false with a reason in err. */
bool image_format_tile_index(const image_format *self, image_rect rect,
                             int *tx, int *ty, char *err, size_t errsz);

/* The channels present in the format, in file order: i runs from 0 to
 * image_format_channel_count()-1. Entries are static (never freed). */
int image_format_channel_count(const image_format *self);
const image_channel *image_format_channel(const image_format *self, int i);

/* Bytes of one pixel over all channels as stored uncompressed in the file. */
size_t image_format_pixel_bytes(const image_format *self);

/* Floats per pixel of a source buffer (4, 1, 3, 3). */
int image_source_floats(image_source source);

#endif

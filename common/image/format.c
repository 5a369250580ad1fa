/*
 * format.c: image_format checks, the tile grid and the channel table.
 *
 * The channel table is the single place that says which channels an aafarm
 * image has, their types and where their values live in an image_tile;
 * the tile encoder, the validator and the output writer all walk it, which
 * is what keeps a worker's tile and the master's output file compatible
 * chunk for chunk.
 */
#include "image/format.h"
#include "util/err.h"

#include <stdio.h>

/* Sorted by name (strcmp), as the OpenEXR channel list requires
 * (OpenEXR file layout, "chlist" attribute). `layer` 0: always present. */
static const struct {
    image_channel channel;
    unsigned layer;
} channel_table[IMAGE_MAX_CHANNELS] = {
    {{"A",   IMAGE_PIXEL_HALF,  IMAGE_SOURCE_RGBA, 3}, 0},
    {{"B",   IMAGE_PIXEL_HALF,  IMAGE_SOURCE_RGBA, 2}, 0},
    {{"G",   IMAGE_PIXEL_HALF,  IMAGE_SOURCE_RGBA, 1}, 0},
    {{"N.x", IMAGE_PIXEL_FLOAT, IMAGE_SOURCE_N,    0}, IMAGE_LAYER_N},
    {{"N.y", IMAGE_PIXEL_FLOAT, IMAGE_SOURCE_N,    1}, IMAGE_LAYER_N},
    {{"N.z", IMAGE_PIXEL_FLOAT, IMAGE_SOURCE_N,    2}, IMAGE_LAYER_N},
    {{"P.x", IMAGE_PIXEL_FLOAT, IMAGE_SOURCE_P,    0}, IMAGE_LAYER_P},
    {{"P.y", IMAGE_PIXEL_FLOAT, IMAGE_SOURCE_P,    1}, IMAGE_LAYER_P},
    {{"P.z", IMAGE_PIXEL_FLOAT, IMAGE_SOURCE_P,    2}, IMAGE_LAYER_P},
    {{"R",   IMAGE_PIXEL_HALF,  IMAGE_SOURCE_RGBA, 0}, 0},
    {{"Z",   IMAGE_PIXEL_FLOAT, IMAGE_SOURCE_Z,    0}, 0},
};

static bool has_layer(const image_format *self, unsigned layer)
{
    return layer == 0 || (self->layers & layer) != 0;
}

bool image_format_check(const image_format *self, char *err, size_t errsz)
{
    if (self->width < 1 || self->height < 1 || self->width > IMAGE_MAX_SIZE
        || self->height > IMAGE_MAX_SIZE) {
        return err_set(err, errsz, "image size %dx%d is out of range: width and "
                       "height must be 1..%d", self->width, self->height,
                       IMAGE_MAX_SIZE);
    }
    if (self->tile_size < 1 || self->tile_size > IMAGE_MAX_TILE_SIZE) {
        return err_set(err, errsz, "tile size %d is out of range: use 1..%d",
                       self->tile_size, IMAGE_MAX_TILE_SIZE);
    }
    if ((self->layers & ~(unsigned) IMAGE_LAYERS_ALL) != 0) {
        return err_set(err, errsz, "unknown image layer flags 0x%x",
                       self->layers & ~(unsigned) IMAGE_LAYERS_ALL);
    }
    if ((long long) image_format_tiles_x(self) * image_format_tiles_y(self)
        > IMAGE_MAX_TILES) {
        return err_set(err, errsz, "image %dx%d with tile size %d has more than %d "
                       "tiles: use a larger tile size", self->width, self->height,
                       self->tile_size, IMAGE_MAX_TILES);
    }
    return true;
}

int image_format_tiles_x(const image_format *self)
{
    return (self->width + self->tile_size - 1) / self->tile_size;
}

int image_format_tiles_y(const image_format *self)
{
    return (self->height + self->tile_size - 1) / self->tile_size;
}

int image_format_tile_count(const image_format *self)
{
    return image_format_tiles_x(self) * image_format_tiles_y(self);
}

static int min_int(int a, int b)
{
    return a < b ? a : b;
}

image_rect image_format_tile_rect(const image_format *self, int tx, int ty)
{
    image_rect r;
    r.x0 = tx * self->tile_size;
    r.y0 = ty * self->tile_size;
    r.w = min_int(self->tile_size, self->width - r.x0);
    r.h = min_int(self->tile_size, self->height - r.y0);
    return r;
}

bool image_format_tile_index(const image_format *self, image_rect rect,
                             int *tx, int *ty, char *err, size_t errsz)
{
    int t = self->tile_size;
    if (rect.x0 < 0 || rect.y0 < 0 || rect.x0 >= self->width
        || rect.y0 >= self->height || rect.x0 % t != 0 || rect.y0 % t != 0) {
        return err_set(err, errsz, "rectangle at (%d,%d) is not the corner of a "
                       "%dx%d tile of a %dx%d image", rect.x0, rect.y0, t, t,
                       self->width, self->height);
    }
    image_rect want = image_format_tile_rect(self, rect.x0 / t, rect.y0 / t);
    if (rect.w != want.w || rect.h != want.h) {
        return err_set(err, errsz, "tile at (%d,%d) is %dx%d, expected %dx%d "
                       "(tile size %d, image %dx%d)", rect.x0, rect.y0, rect.w,
                       rect.h, want.w, want.h, t, self->width, self->height);
    }
    *tx = rect.x0 / t;
    *ty = rect.y0 / t;
    return true;
}

int image_format_channel_count(const image_format *self)
{
    int n = 0;
    for (int i = 0; i < IMAGE_MAX_CHANNELS; i++)
        n += has_layer(self, channel_table[i].layer);
    return n;
}

const image_channel *image_format_channel(const image_format *self, int i)
{
    for (int k = 0; k < IMAGE_MAX_CHANNELS; k++) {
        if (!has_layer(self, channel_table[k].layer))
            continue;
        if (i-- == 0)
            return &channel_table[k].channel;
    }
    return NULL;
}

size_t image_format_pixel_bytes(const image_format *self)
{
    size_t bytes = 0;
    for (int i = 0; i < image_format_channel_count(self); i++)
        bytes += image_format_channel(self, i)->type == IMAGE_PIXEL_HALF
                 ? 2 : 4;
    return bytes;
}

int image_source_floats(image_source source)
{
    switch (source) {
    case IMAGE_SOURCE_RGBA: return 4;
    case IMAGE_SOURCE_Z: return 1;
    case IMAGE_SOURCE_N: return 3;
    case IMAGE_SOURCE_P: return 3;
    }
    return 0;
}

/*
 * writer.c: the tiled output EXR (see writer.h).
 *
 * Stitching by chunk copy: a tile file's only chunk was compressed from a
 * w x h block with the output's channels, types, ZIP level and tile size
 * (tile.h), which is exactly what the output file's chunk for that tile
 * must hold (OpenEXR file layout: a tiled chunk is tile coordinates, level,
 * size and the compressed pixel block; nothing in the compressed block
 * depends on where the tile sits). So the master hands the validated bytes
 * to exr_write_tile_chunk() with the output tile coordinates, and
 * OpenEXRCore writes the chunk leader, the data and (at exr_finish) the
 * offset table. No pixel is decoded or re-encoded on the master; the chunk
 * is decompressed once, inside validation, to prove it intact.
 */
#include "image/writer.h"
#include "util/err.h"

#include <assert.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/exr_io.h"
#include "image/outfile.h"
#include "util/xalloc.h"

struct image_writer {
    image_format fmt;
    image_outfile *file;
    image_exr_stream stream;    /* the context's I/O; address must not move */
    exr_context_t ctxt;
    uint8_t *written;           /* one flag per tile, row-major */
    int tiles_written;
    char failure[ERR_LEN];      /* set once a write failed: writer unusable */
};

image_writer *image_writer_new(const char *path, const image_format *fmt,
                               char *err, size_t errsz)
{
    if (!image_format_check(fmt, err, errsz))
        return NULL;
    image_writer *self = xcalloc(1, sizeof *self);
    self->fmt = *fmt;
    self->written = xcalloc((size_t) image_format_tile_count(fmt), 1);
    self->file = image_outfile_new(path, err, errsz);
    if (!self->file) {
        image_writer_destroy(&self);
        return NULL;
    }
    image_exr_stream_fd(&self->stream, image_outfile_fd(self->file));
    image_rect whole = {0, 0, fmt->width, fmt->height};
    exr_result_t rv = image_exr_start_write(&self->ctxt, path, &self->stream);
    if (rv == EXR_ERR_SUCCESS)
        rv = image_exr_define_part(self->ctxt, fmt, whole);
    if (rv != EXR_ERR_SUCCESS) {
        char what[300];
        snprintf(what, sizeof what, "cannot write EXR header to %s",
                 image_outfile_temp_path(self->file));
        image_exr_error(err, errsz, what, rv, &self->stream);
        image_writer_destroy(&self);
    }
    return self;
}

void image_writer_destroy(image_writer **self_p)
{
    if (!self_p || !*self_p)
        return;
    image_writer *self = *self_p;
    if (self->ctxt) {
        self->stream.discard = true;   /* the file is going away */
        exr_finish(&self->ctxt);
    }
    image_outfile_destroy(&self->file);
    free(self->written);
    free(self);
    *self_p = NULL;
}

static bool usable(const image_writer *self, char *err, size_t errsz)
{
    if (self->failure[0] == '\0')
        return true;
    return err_set(err, errsz, "%s", self->failure);
}

static uint8_t *written_flag(const image_writer *self, int tx, int ty)
{
    assert(tx >= 0 && ty >= 0 && tx < image_format_tiles_x(&self->fmt)
           && ty < image_format_tiles_y(&self->fmt));
    return &self->written[(size_t) ty * (size_t) image_format_tiles_x(&self->fmt)
                          + (size_t) tx];
}

/* After a successful chunk write; or records the failure for good (the
 * file's chunk area may hold a partial chunk now). */
static bool record_write(image_writer *self, int tx, int ty, exr_result_t rv,
                         char *err, size_t errsz)
{
    if (rv == EXR_ERR_SUCCESS) {
        assert(!*written_flag(self, tx, ty));    /* each tile written once */
        *written_flag(self, tx, ty) = 1;
        self->tiles_written++;
        assert(self->tiles_written <= image_format_tile_count(&self->fmt));
        return true;
    }
    char what[320];
    snprintf(what, sizeof what, "cannot write tile (%d,%d) to %s", tx, ty,
             image_outfile_temp_path(self->file));
    image_exr_error(self->failure, sizeof self->failure, what, rv,
                    &self->stream);
    return err_set(err, errsz, "%s", self->failure);
}

bool image_writer_put_tile(image_writer *self, const image_tile *tile,
                           char *err, size_t errsz)
{
    int tx, ty;
    if (!usable(self, err, errsz)
        || !image_format_tile_index(&self->fmt, image_tile_rect(tile), &tx,
                                    &ty, err, errsz))
        return false;
    if (tile->layers != self->fmt.layers || !tile->rgba || !tile->z
        || (tile->layers & IMAGE_LAYER_N && !tile->n)
        || (tile->layers & IMAGE_LAYER_P && !tile->p)) {
        return err_set(err, errsz, "tile at (%d,%d) does not have the image's "
                       "layers 0x%x", tile->x0, tile->y0, self->fmt.layers);
    }
    if (*written_flag(self, tx, ty))
        return true;
    image_exr_stream_reset_errors(&self->stream);
    exr_result_t rv = image_exr_write_tile(self->ctxt, &self->fmt, tx, ty,
                                           tile);
    return record_write(self, tx, ty, rv, err, errsz);
}

bool image_writer_put_exr_chunk(image_writer *self, const void *bytes,
                                size_t len, image_rect expect,
                                char *err, size_t errsz)
{
    const void *chunk = NULL;
    size_t chunk_len = 0;
    int tx, ty;
    if (!usable(self, err, errsz)
        || !image_format_tile_index(&self->fmt, expect, &tx, &ty, err, errsz)
        || !image_tile_exr_chunk(bytes, len, &self->fmt, expect, &chunk,
                                 &chunk_len, err, errsz))
        return false;
    return image_writer_put_chunk(self, tx, ty, chunk, chunk_len, err, errsz);
}

bool image_writer_put_chunk(image_writer *self, int tx, int ty, const void *chunk,
                            size_t chunk_len, char *err, size_t errsz)
{
    if (!usable(self, err, errsz))
        return false;
    if (tx < 0 || ty < 0 || tx >= image_format_tiles_x(&self->fmt)
        || ty >= image_format_tiles_y(&self->fmt)) {
        return err_set(err, errsz, "tile (%d,%d) is not in the image", tx, ty);
    }
    if (*written_flag(self, tx, ty))
        return true;
    image_exr_stream_reset_errors(&self->stream);
    exr_result_t rv = exr_write_tile_chunk(self->ctxt, 0, tx, ty, 0, 0, chunk,
                                           chunk_len);
    return record_write(self, tx, ty, rv, err, errsz);
}

bool image_writer_failed(const image_writer *self)
{
    return self->failure[0] != '\0';
}

bool image_writer_has_tile(const image_writer *self, int tx, int ty)
{
    return tx >= 0 && ty >= 0 && tx < image_format_tiles_x(&self->fmt)
           && ty < image_format_tiles_y(&self->fmt)
           && *written_flag(self, tx, ty);
}

int image_writer_tiles_written(const image_writer *self)
{
    return self->tiles_written;
}

const image_format *image_writer_format(const image_writer *self)
{
    return &self->fmt;
}

const char *image_writer_temp_path(const image_writer *self)
{
    return image_outfile_temp_path(self->file);
}

static bool report_missing(const image_writer *self, char *err, size_t errsz)
{
    int total = image_format_tile_count(&self->fmt);
    int nx = image_format_tiles_x(&self->fmt);
    for (int i = 0; i < total; i++) {
        if (!self->written[i]) {
            err_set(err, errsz, "cannot finish %s: %d of %d tiles missing, "
                    "first tile (%d,%d)", image_outfile_path(self->file),
                    total - self->tiles_written, total, i % nx, i / nx);
            return true;
        }
    }
    return false;
}

bool image_writer_finish(image_writer **self_p, char *err, size_t errsz)
{
    image_writer *self = *self_p;
    if (self->failure[0] == '\0' && report_missing(self, err, errsz))
        return false;
    if (!usable(self, err, errsz)) {
        image_writer_destroy(self_p);
        return false;
    }
    image_exr_stream_reset_errors(&self->stream);
    exr_result_t rv = exr_finish(&self->ctxt);
    self->ctxt = NULL;
    if (rv != EXR_ERR_SUCCESS) {
        char what[300];
        snprintf(what, sizeof what, "cannot finish %s",
                 image_outfile_temp_path(self->file));
        image_exr_error(err, errsz, what, rv, &self->stream);
        image_writer_destroy(self_p);
        return false;
    }
    bool ok = image_outfile_commit(&self->file, err, errsz);
    image_writer_destroy(self_p);
    return ok;
}

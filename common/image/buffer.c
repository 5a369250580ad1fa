/*
 * buffer.c: whole images as float planes: reading EXR files chunk by chunk
 * through OpenEXRCore, and the comparison used by determinism tests.
 */
#include "image/buffer.h"
#include "util/err.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/exr_io.h"
#include "util/xalloc.h"

/* Largest image read: 2^31 samples over all channels (8 GiB of floats). */
#define BUFFER_MAX_SAMPLES ((size_t) 1 << 31)

image_buffer *image_buffer_new(int width, int height, int channel_count,
                               const char *const *names)
{
    if (width < 1 || height < 1 || channel_count < 0
        || (size_t) width * (size_t) height * (size_t) (channel_count + 1)
           > BUFFER_MAX_SAMPLES)
        return NULL;
    image_buffer *self = try_calloc(1, sizeof *self);
    if (!self)
        return NULL;
    self->width = width;
    self->height = height;
    self->channel_count = channel_count;
    self->names = try_calloc((size_t) channel_count + 1, sizeof(char *));
    self->planes = try_calloc((size_t) channel_count + 1, sizeof(float *));
    bool ok = self->names && self->planes;
    size_t px = (size_t) width * (size_t) height;
    for (int c = 0; ok && c < channel_count; c++) {
        self->names[c] = try_strdup(names[c]);
        self->planes[c] = try_calloc(px, sizeof(float));
        ok = self->names[c] && self->planes[c];
    }
    if (!ok)
        image_buffer_destroy(&self);
    return self;
}

void image_buffer_destroy(image_buffer **self_p)
{
    if (!self_p || !*self_p)
        return;
    image_buffer *self = *self_p;
    for (int c = 0; c < self->channel_count; c++) {
        if (self->names)
            free(self->names[c]);
        if (self->planes)
            free(self->planes[c]);
    }
    free(self->names);
    free(self->planes);
    free(self);
    *self_p = NULL;
}

float *image_buffer_channel(const image_buffer *self, const char *name)
{
    for (int c = 0; c < self->channel_count; c++)
        if (strcmp(self->names[c], name) == 0)
            return self->planes[c];
    return NULL;
}

/* ---- reading ---- */

typedef struct reader {
    const char *path;
    exr_context_t ctxt;
    image_exr_stream stream;
    image_buffer *buf;
    const atomic_int *cancel;      /* looked at before each chunk, or NULL */
    char *err;
    size_t errsz;
} reader;

static bool fail(reader *r, const char *what, exr_result_t rv)
{
    char msg[512];
    snprintf(msg, sizeof msg, "%s: %s", r->path, what);
    image_exr_error(r->err, r->errsz, msg, rv, &r->stream);
    return false;
}

static bool fail_plain(reader *r, const char *what)
{
    return err_set(r->err, r->errsz, "%s: %s", r->path, what);
}

/* Checks the part and allocates the buffer for its data window. */
static bool make_buffer(reader *r)
{
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    exr_result_t rv = exr_get_storage(r->ctxt, 0, &storage);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_data_window(r->ctxt, 0, &dw);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_channels(r->ctxt, 0, &chl);
    if (rv != EXR_ERR_SUCCESS)
        return fail(r, "cannot read the header", rv);
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return fail_plain(r, "deep EXR files are not supported");
    const char *names[256];
    if (chl->num_channels > 256)
        return fail_plain(r, "more than 256 channels are not supported");
    for (int c = 0; c < chl->num_channels; c++) {
        if (chl->entries[c].x_sampling != 1 || chl->entries[c].y_sampling != 1)
            return fail_plain(r, "subsampled channels are not supported");
        names[c] = chl->entries[c].name.str;
    }
    int64_t w = (int64_t) dw.max.x - dw.min.x + 1;
    int64_t h = (int64_t) dw.max.y - dw.min.y + 1;
    if (w > INT32_MAX || h > INT32_MAX
        || !(r->buf = image_buffer_new((int) w, (int) h, chl->num_channels,
                                       names)))
        return fail_plain(r, "image too large to read into memory");
    r->buf->x0 = dw.min.x;
    r->buf->y0 = dw.min.y;
    return true;
}

/* Decodes one chunk whose top-left pixel is (x, y) relative to the data
 * window. */
static bool read_chunk(reader *r, const exr_chunk_info_t *ci, int x, int y)
{
    image_buffer *b = r->buf;
    if (r->cancel && atomic_load_explicit(r->cancel, memory_order_relaxed))
        return fail_plain(r, "interrupted (SIGINT/SIGTERM) while reading");
    if (x < 0 || y < 0 || ci->width < 0 || ci->height < 0
        || x + ci->width > b->width || y + ci->height > b->height)
        return fail_plain(r, "chunk outside the data window");
    float *dst[256];
    size_t at = (size_t) y * (size_t) b->width + (size_t) x;
    for (int c = 0; c < b->channel_count; c++)
        dst[c] = b->planes[c] + at;
    exr_result_t rv = image_exr_decode_chunk(r->ctxt, ci, dst,
                                             (size_t) b->width);
    return rv == EXR_ERR_SUCCESS || fail(r, "corrupt pixel data", rv);
}

static bool read_scanlines(reader *r)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(r->ctxt, 0, &lines);
    if (rv != EXR_ERR_SUCCESS || lines < 1)
        return fail(r, "cannot read the scanline layout", rv);
    image_buffer *b = r->buf;
    for (int64_t y = b->y0; y < (int64_t) b->y0 + b->height; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_read_scanline_chunk_info(r->ctxt, 0, (int) y, &ci);
        if (rv != EXR_ERR_SUCCESS)
            return fail(r, "missing or corrupt scanline chunk", rv);
        if (!read_chunk(r, &ci, 0, ci.start_y - b->y0))
            return false;
    }
    return true;
}

static bool read_tiles(reader *r)
{
    int32_t tw = 0, th = 0, lw = 0, lh = 0;
    exr_result_t rv = exr_get_tile_sizes(r->ctxt, 0, 0, 0, &tw, &th);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_level_sizes(r->ctxt, 0, 0, 0, &lw, &lh);
    if (rv != EXR_ERR_SUCCESS || tw < 1 || th < 1)
        return fail(r, "cannot read the tile layout", rv);
    int nx = (int) (((int64_t) lw + tw - 1) / tw);
    int ny = (int) (((int64_t) lh + th - 1) / th);
    for (int ty = 0; ty < ny; ty++) {
        for (int tx = 0; tx < nx; tx++) {
            exr_chunk_info_t ci;
            rv = exr_read_tile_chunk_info(r->ctxt, 0, tx, ty, 0, 0, &ci);
            if (rv != EXR_ERR_SUCCESS) {
                char what[96];
                snprintf(what, sizeof what, "missing or corrupt tile (%d,%d)",
                         tx, ty);
                return fail(r, what, rv);
            }
            if (!read_chunk(r, &ci, tx * tw, ty * th))
                return false;
        }
    }
    return true;
}

image_buffer *image_buffer_read_exr(const char *path, char *err, size_t errsz)
{
    return image_buffer_read_exr_cancel(path, NULL, err, errsz);
}

image_buffer *image_buffer_read_exr_cancel(const char *path, const atomic_int *cancel,
                                           char *err, size_t errsz)
{
    reader r;
    memset(&r, 0, sizeof r);
    r.path = path;
    r.cancel = cancel;
    r.err = err;
    r.errsz = errsz;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        err_set(err, errsz, "cannot open %s: %s", path, strerror(errno));
        return NULL;
    }
    image_exr_stream_fd(&r.stream, fd);
    exr_storage_t storage = EXR_STORAGE_SCANLINE;
    exr_result_t rv = image_exr_start_read(&r.ctxt, path, &r.stream);
    bool ok = rv == EXR_ERR_SUCCESS
              || fail(&r, "not a readable OpenEXR file", rv);
    ok = ok && make_buffer(&r);
    ok = ok && exr_get_storage(r.ctxt, 0, &storage) == EXR_ERR_SUCCESS;
    if (ok)
        ok = storage == EXR_STORAGE_TILED ? read_tiles(&r) : read_scanlines(&r);
    if (r.ctxt)
        exr_finish(&r.ctxt);
    close(fd);
    if (!ok)
        image_buffer_destroy(&r.buf);
    return r.buf;
}

/* ---- comparing ---- */

static bool same_layout(const image_buffer *a, const image_buffer *b,
                        char *err, size_t errsz)
{
    if (a->x0 != b->x0 || a->y0 != b->y0 || a->width != b->width
        || a->height != b->height) {
        return err_set(err, errsz, "images differ in size: %dx%d at (%d,%d) vs "
                       "%dx%d at (%d,%d)", a->width, a->height, a->x0, a->y0,
                       b->width, b->height, b->x0, b->y0);
    }
    if (a->channel_count != b->channel_count) {
        return err_set(err, errsz, "images differ in channels: %d vs %d channels",
                       a->channel_count, b->channel_count);
    }
    for (int c = 0; c < a->channel_count; c++) {
        if (strcmp(a->names[c], b->names[c]) != 0) {
            return err_set(err, errsz, "images differ in channels: '%s' vs '%s'",
                           a->names[c], b->names[c]);
        }
    }
    return true;
}

/* |a - b| under the equality rules of image_diff; 0 when equal. */
static double sample_difference(float a, float b)
{
    if (isnan(a) || isnan(b))
        return isnan(a) && isnan(b) ? 0.0 : INFINITY;
    if (a == b)
        return 0.0;
    return fabs((double) a - (double) b);
}

bool image_buffer_compare(const image_buffer *a, const image_buffer *b,
                          double tolerance, image_diff *diff,
                          char *err, size_t errsz)
{
    memset(diff, 0, sizeof *diff);
    if (!same_layout(a, b, err, errsz))
        return false;
    size_t px = (size_t) a->width * (size_t) a->height;
    for (int c = 0; c < a->channel_count; c++) {
        for (size_t i = 0; i < px; i++) {
            double d = sample_difference(a->planes[c][i], b->planes[c][i]);
            if (d <= tolerance)
                continue;
            diff->count++;
            if (d > diff->max_abs || diff->count == 1) {
                diff->max_abs = d;
                snprintf(diff->channel, sizeof diff->channel, "%s",
                         a->names[c]);
                diff->x = a->x0 + (int) (i % (size_t) a->width);
                diff->y = a->y0 + (int) (i / (size_t) a->width);
            }
        }
    }
    return true;
}

/*
 * exr_io.c: custom OpenEXRCore streams, context set-up, and the encoding and
 * decoding of one chunk (see exr_io.h for why these live together).
 *
 * OpenEXRCore's stream callbacks have pread/pwrite semantics (an offset
 * with every call; openexr_context.h). The memory writer therefore keeps
 * the furthest byte written as the file length and zero-fills any gap; the
 * readers return short counts past the end, which OpenEXRCore reports as a
 * read error, never as a crash.
 *
 * Error messages never go through exr_get_user_data(): OpenEXRCore calls
 * its error handler while it holds the context's lock (exr_write_header,
 * exr_write_tile_chunk, exr_finish), and exr_get_user_data() takes the
 * same non-recursive lock, so asking it from the handler deadlocks the
 * process the first time a header write fails (a full disk). Instead the
 * stream callbacks, which get their stream as an argument, note I/O errors
 * themselves (with errno), and the handler (tex_exr_on_error, shared with
 * common/tex: tex/codec_err.h) keeps OpenEXRCore's own text in a
 * per-thread buffer that image_exr_error() reads when the stream has no
 * message (image_exr_stream_reset_errors() empties both before an operation).
 */
#include "image/exr_io.h"
#include "util/err.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tex/codec_err.h"
#include "util/xalloc.h"

/* ---- streams ---- */

static void stream_reset(image_exr_stream *self)
{
    memset(self, 0, sizeof *self);
    self->fd = -1;
}

void image_exr_stream_memory_reader(image_exr_stream *self, const void *bytes,
                                    size_t len)
{
    stream_reset(self);
    self->in = bytes;
    self->in_len = len;
}

void image_exr_stream_memory_writer(image_exr_stream *self)
{
    stream_reset(self);
}

void image_exr_stream_fd(image_exr_stream *self, int fd)
{
    stream_reset(self);
    self->fd = fd;
}

void image_exr_stream_clear(image_exr_stream *self)
{
    free(self->out);
    self->out = NULL;
    self->out_len = self->out_cap = 0;
}

/* Keeps the first message of an operation: later ones are usually the
 * same failure reported again further up OpenEXRCore's call chain. */
static void stream_note(image_exr_stream *self, const char *msg)
{
    if (self->message[0] == '\0')
        snprintf(self->message, sizeof self->message, "%s", msg);
}

void image_exr_stream_reset_errors(image_exr_stream *self)
{
    self->message[0] = '\0';
    self->sys_errno = 0;
    tex_exr_clear();
}

static int64_t read_memory(image_exr_stream *self, void *buffer, uint64_t sz,
                           uint64_t offset)
{
    if (offset >= self->in_len)
        return 0;
    uint64_t n = self->in_len - offset;
    if (n > sz)
        n = sz;
    memcpy(buffer, self->in + offset, (size_t) n);
    return (int64_t) n;
}

static int64_t read_fd(image_exr_stream *self, void *buffer, uint64_t sz,
                       uint64_t offset)
{
    uint64_t done = 0;
    while (done < sz) {
        ssize_t n = pread(self->fd, (char *) buffer + done,
                          (size_t) (sz - done), (off_t) (offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            self->sys_errno = errno;
            return -1;
        }
        if (n == 0)
            break;
        done += (uint64_t) n;
    }
    return (int64_t) done;
}

static int64_t stream_read(exr_const_context_t ctxt, void *user, void *buffer,
                           uint64_t sz, uint64_t offset,
                           exr_stream_error_func_ptr_t error_cb)
{
    image_exr_stream *self = user;
    int64_t n = self->fd < 0 ? read_memory(self, buffer, sz, offset)
                             : read_fd(self, buffer, sz, offset);
    if (n < 0) {
        char msg[160];
        snprintf(msg, sizeof msg, "read failed: %s", strerror(self->sys_errno));
        stream_note(self, msg);
        if (error_cb)
            error_cb(ctxt, EXR_ERR_READ_IO, "%s", msg);
    }
    return n;
}

static int64_t stream_size(exr_const_context_t ctxt, void *user)
{
    (void) ctxt;
    image_exr_stream *self = user;
    if (self->fd < 0)
        return (int64_t) self->in_len;
    struct stat st;
    if (fstat(self->fd, &st) != 0)
        return -1;
    return (int64_t) st.st_size;
}

/* The buffer of a tile being encoded (a few MB at most): out of memory
 * aborts (util/xalloc.h). */
static void grow_memory(image_exr_stream *self, size_t need)
{
    if (need <= self->out_cap)
        return;
    size_t cap = self->out_cap ? self->out_cap : 4096;
    while (cap < need)
        cap = cap > SIZE_MAX / 2 ? need : cap * 2;
    self->out = xrealloc(self->out, cap);
    memset(self->out + self->out_cap, 0, cap - self->out_cap);
    self->out_cap = cap;
}

static int64_t write_memory(image_exr_stream *self, const void *buffer,
                            uint64_t sz, uint64_t offset)
{
    if (offset > SIZE_MAX - sz) {
        self->sys_errno = ENOMEM;
        return -1;
    }
    grow_memory(self, (size_t) (offset + sz));
    memcpy(self->out + offset, buffer, (size_t) sz);
    if (offset + sz > self->out_len)
        self->out_len = (size_t) (offset + sz);
    return (int64_t) sz;
}

static int64_t write_fd(image_exr_stream *self, const void *buffer,
                        uint64_t sz, uint64_t offset)
{
    uint64_t done = 0;
    while (done < sz) {
        ssize_t n = pwrite(self->fd, (const char *) buffer + done,
                           (size_t) (sz - done), (off_t) (offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            self->sys_errno = n < 0 ? errno : EIO;
            return -1;
        }
        done += (uint64_t) n;
    }
    return (int64_t) done;
}

static int64_t stream_write(exr_const_context_t ctxt, void *user,
                            const void *buffer, uint64_t sz, uint64_t offset,
                            exr_stream_error_func_ptr_t error_cb)
{
    image_exr_stream *self = user;
    if (self->discard)
        return (int64_t) sz;
    int64_t n = self->fd < 0 ? write_memory(self, buffer, sz, offset)
                             : write_fd(self, buffer, sz, offset);
    if (n < 0) {
        char msg[160];
        snprintf(msg, sizeof msg, "write failed: %s%s", strerror(self->sys_errno),
                 self->sys_errno == ENOSPC || self->sys_errno == EDQUOT
                 ? " (free some space on that file system)" : "");
        stream_note(self, msg);
        if (error_cb)
            error_cb(ctxt, EXR_ERR_WRITE_IO, "%s", msg);
    }
    return n;
}

/* ---- contexts ---- */

static exr_context_initializer_t initializer(image_exr_stream *stream)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = tex_exr_on_error;
    init.user_data = stream;
    init.zip_level = IMAGE_EXR_ZIP_LEVEL;
    return init;
}

exr_result_t image_exr_start_read(exr_context_t *ctxt, const char *name,
                                  image_exr_stream *stream)
{
    exr_context_initializer_t init = initializer(stream);
    image_exr_stream_reset_errors(stream);
    init.read_fn = stream_read;
    init.size_fn = stream_size;
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    return exr_start_read(ctxt, name, &init);
}

exr_result_t image_exr_start_write(exr_context_t *ctxt, const char *name,
                                   image_exr_stream *stream)
{
    exr_context_initializer_t init = initializer(stream);
    image_exr_stream_reset_errors(stream);
    init.write_fn = stream_write;
    return exr_start_write(ctxt, name, EXR_WRITE_FILE_DIRECTLY, &init);
}

/* ---- the part of an aafarm image ---- */

static exr_attr_box2i_t box_of(image_rect r)
{
    exr_attr_box2i_t b;
    b.min.x = r.x0;
    b.min.y = r.y0;
    b.max.x = r.x0 + r.w - 1;
    b.max.y = r.y0 + r.h - 1;
    return b;
}

static exr_pixel_type_t exr_type_of(image_pixel_type t)
{
    return t == IMAGE_PIXEL_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;
}

exr_result_t image_exr_define_part(exr_context_t ctxt, const image_format *fmt,
                                   image_rect data_window)
{
    image_rect whole = {0, 0, fmt->width, fmt->height};
    exr_attr_box2i_t display = box_of(whole), data = box_of(data_window);
    exr_attr_v2f_t center;
    center.x = 0.0f;
    center.y = 0.0f;
    int part = 0;
    exr_result_t rv = exr_add_part(ctxt, NULL, EXR_STORAGE_TILED, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr(ctxt, part, &display, &data, 1.0f,
                                          &center, 1.0f,
                                          EXR_LINEORDER_RANDOM_Y,
                                          EXR_COMPRESSION_ZIP);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_set_tile_descriptor(ctxt, part, (uint32_t) fmt->tile_size,
                                     (uint32_t) fmt->tile_size,
                                     EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN);
    for (int c = 0; rv == EXR_ERR_SUCCESS
                    && c < image_format_channel_count(fmt); c++) {
        const image_channel *ch = image_format_channel(fmt, c);
        rv = exr_add_channel(ctxt, part, ch->name, exr_type_of(ch->type),
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_set_zip_compression_level(ctxt, part, IMAGE_EXR_ZIP_LEVEL);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctxt);
    return rv;
}

static const image_channel *channel_named(const image_format *fmt,
                                          const char *name)
{
    for (int c = 0; c < image_format_channel_count(fmt); c++)
        if (strcmp(image_format_channel(fmt, c)->name, name) == 0)
            return image_format_channel(fmt, c);
    return NULL;
}

static const float *source_buffer(const image_tile *tile, image_source s)
{
    switch (s) {
    case IMAGE_SOURCE_RGBA: return tile->rgba;
    case IMAGE_SOURCE_Z: return tile->z;
    case IMAGE_SOURCE_N: return tile->n;
    case IMAGE_SOURCE_P: return tile->p;
    }
    return NULL;
}

/* Points every encoder channel at its values in the tile (planar input,
 * one float per value, converted to the file's type by OpenEXRCore). */
static exr_result_t bind_sources(exr_encode_pipeline_t *enc,
                                 const image_format *fmt,
                                 const image_tile *tile)
{
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *info = &enc->channels[c];
        const image_channel *ch = channel_named(fmt, info->channel_name);
        const float *base = ch ? source_buffer(tile, ch->source) : NULL;
        if (!base)
            return EXR_ERR_INVALID_ARGUMENT;
        int floats = image_source_floats(ch->source);
        info->encode_from_ptr = (const uint8_t *) (base + ch->component);
        info->user_pixel_stride = floats * (int32_t) sizeof(float);
        info->user_line_stride = floats * (int32_t) sizeof(float) * tile->w;
        info->user_data_type = EXR_PIXEL_FLOAT;
        info->user_bytes_per_element = (int16_t) sizeof(float);
    }
    return EXR_ERR_SUCCESS;
}

exr_result_t image_exr_write_tile(exr_context_t ctxt, const image_format *fmt,
                                  int tx, int ty, const image_tile *tile)
{
    exr_chunk_info_t cinfo;
    exr_result_t rv = exr_write_tile_chunk_info(ctxt, 0, tx, ty, 0, 0, &cinfo);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    if (cinfo.width != tile->w || cinfo.height != tile->h)
        return EXR_ERR_INVALID_ARGUMENT;
    exr_encode_pipeline_t enc;
    memset(&enc, 0, sizeof enc);
    rv = exr_encoding_initialize(ctxt, 0, &cinfo, &enc);
    if (rv == EXR_ERR_SUCCESS)
        rv = bind_sources(&enc, fmt, tile);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_encoding_choose_default_routines(ctxt, 0, &enc);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_encoding_run(ctxt, 0, &enc);
    exr_encoding_destroy(ctxt, &enc);
    return rv;
}

exr_result_t image_exr_decode_chunk(exr_const_context_t ctxt,
                                    const exr_chunk_info_t *cinfo,
                                    float *const *dst, size_t line_stride)
{
    exr_decode_pipeline_t dec;
    memset(&dec, 0, sizeof dec);
    exr_result_t rv = exr_decoding_initialize(ctxt, 0, cinfo, &dec);
    for (int c = 0; rv == EXR_ERR_SUCCESS && c < dec.channel_count; c++) {
        exr_coding_channel_info_t *info = &dec.channels[c];
        if (info->x_samples != 1 || info->y_samples != 1) {
            rv = EXR_ERR_FEATURE_NOT_IMPLEMENTED;
            break;
        }
        info->decode_to_ptr = (uint8_t *) dst[c];
        info->user_pixel_stride = (int32_t) sizeof(float);
        info->user_line_stride = (int32_t) (line_stride * sizeof(float));
        info->user_data_type = EXR_PIXEL_FLOAT;
        info->user_bytes_per_element = (int16_t) sizeof(float);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_decoding_choose_default_routines(ctxt, 0, &dec);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_decoding_run(ctxt, 0, &dec);
    exr_decoding_destroy(ctxt, &dec);
    return rv;
}

void image_exr_error(char *err, size_t errsz, const char *what,
                     exr_result_t rv, const image_exr_stream *stream)
{
    const char *reason = stream && stream->message[0] ? stream->message
                                                      : tex_exr_reason(rv);
    err_set(err, errsz, "%s: %s", what, reason);
    tex_exr_clear();
}

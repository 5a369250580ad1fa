/*
 * preview.c: the PNG preview (see preview.h for the conversion).
 *
 * libpng reports errors by longjmp; the setjmp lives in write_rows() alone
 * with no local state to clobber, and every error message is collected in
 * png_context so the caller gets one line naming the file.
 */
#include "image/preview.h"
#include "util/err.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/outfile.h"
#include "tex/codec_err.h"
#include "util/xalloc.h"

uint8_t image_preview_srgb8(float linear)
{
    double c = linear;
    if (!(c > 0.0))            /* negative, zero and NaN */
        return 0;
    if (c >= 1.0)
        return 255;
    double v = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
    long code = lround(v * 255.0);
    return (uint8_t) (code < 0 ? 0 : code > 255 ? 255 : code);
}

/* Where the R, G, B values of pixel i are: ch[c][i * stride], NULL = 0;
 * or, when rgb8 is set, the 8-bit codes already converted (3 per pixel). */
typedef struct pixel_source {
    const float *ch[3];
    size_t stride;
    const uint8_t *rgb8;
    int width, height;
    const atomic_int *cancel;      /* looked at before each row, or NULL */
} pixel_source;

/* Where the PNG goes: the file descriptor fd, or (fd < 0) memory. */
typedef struct png_context {
    int fd;
    uint8_t *mem;
    size_t len, cap;
    tex_png_error error;   /* libpng's error pointer (tex/codec_err.h) */
} png_context;

static void on_png_write(png_structp png, png_bytep data, size_t len)
{
    png_context *ctx = png_get_io_ptr(png);
    if (ctx->fd < 0) {
        if (ctx->cap - ctx->len < len) {
            ctx->cap = (ctx->cap + len) * 2;
            ctx->mem = xrealloc(ctx->mem, ctx->cap);
        }
        memcpy(ctx->mem + ctx->len, data, len);
        ctx->len += len;
        return;
    }
    while (len > 0) {
        ssize_t n = write(ctx->fd, data, len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            png_error(png, n < 0 ? strerror(errno) : "short write");
        data += n;
        len -= (size_t) n;
    }
}

static void on_png_flush(png_structp png)
{
    (void) png;
}

static void convert_row(const pixel_source *src, int y, uint8_t *row)
{
    if (src->rgb8) {
        memcpy(row, src->rgb8 + (size_t) y * (size_t) src->width * 3,
               (size_t) src->width * 3);
        return;
    }
    for (int x = 0; x < src->width; x++) {
        size_t i = ((size_t) y * (size_t) src->width + (size_t) x)
                   * src->stride;
        for (int c = 0; c < 3; c++)
            row[3 * x + c] = src->ch[c] ? image_preview_srgb8(src->ch[c][i])
                                        : 0;
    }
}

/* Returns 0 on success, 1 after a libpng error (message in ctx). */
static int write_rows(png_structp png, png_infop info,
                      const pixel_source *src, uint8_t *row)
{
    if (setjmp(png_jmpbuf(png)))
        return 1;
    png_set_IHDR(png, info, (png_uint_32) src->width,
                 (png_uint_32) src->height, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_set_compression_level(png, 6);
    png_write_info(png, info);
    for (int y = 0; y < src->height; y++) {
        if (src->cancel && atomic_load_explicit(src->cancel, memory_order_relaxed))
            png_error(png, "interrupted (SIGINT/SIGTERM)");
        convert_row(src, y, row);
        png_write_row(png, row);
    }
    png_write_end(png, NULL);
    return 0;
}

/* Encodes src into ctx's file or memory; 0, or 1 with the message in
 * ctx->error. */
static int encode_png(png_context *ctx, const pixel_source *src)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING,
                                              &ctx->error, tex_png_on_error,
                                              tex_png_on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    uint8_t *row = xmalloc((size_t) src->width * 3);
    int rc = 1;
    if (png && info) {
        png_set_write_fn(png, ctx, on_png_write, on_png_flush);
        rc = write_rows(png, info, src, row);
    } else {
        snprintf(ctx->error.message, sizeof ctx->error.message, "out of memory");
    }
    png_destroy_write_struct(&png, &info);
    free(row);
    return rc;
}

static bool write_png(image_outfile *file, const pixel_source *src,
                      char *err, size_t errsz)
{
    png_context ctx = {.fd = image_outfile_fd(file)};
    int rc = encode_png(&ctx, src);
    if (rc != 0)
        err_set(err, errsz, "cannot write PNG %s: %s",
                image_outfile_temp_path(file), ctx.error.message);
    return rc == 0;
}

static bool write_preview(const char *path, const pixel_source *src,
                          char *err, size_t errsz)
{
    if (src->width < 1 || src->height < 1
        || src->width > 1000000 || src->height > 1000000) {
        return err_set(err, errsz, "cannot write PNG %s: image size %dx%d out of "
                       "range", path, src->width, src->height);
    }
    image_outfile *file = image_outfile_new(path, err, errsz);
    if (!file)
        return false;
    if (!write_png(file, src, err, errsz)) {
        image_outfile_destroy(&file);
        return false;
    }
    return image_outfile_commit(&file, err, errsz);
}

bool image_preview_write_png(const char *path, const float *rgba, int width,
                             int height, char *err, size_t errsz)
{
    if (!rgba) {
        return err_set(err, errsz, "cannot write PNG %s: no pixels given", path);
    }
    pixel_source src = {.ch = {rgba, rgba + 1, rgba + 2}, .stride = 4, .width = width,
                        .height = height};
    return write_preview(path, &src, err, errsz);
}

static bool write_buffer(const char *path, const image_buffer *buf, const atomic_int *cancel,
                         char *err, size_t errsz)
{
    pixel_source src = {.ch = {image_buffer_channel(buf, "R"), image_buffer_channel(buf, "G"),
                               image_buffer_channel(buf, "B")},
                        .stride = 1, .width = buf->width, .height = buf->height,
                        .cancel = cancel};
    return write_preview(path, &src, err, errsz);
}

bool image_preview_write_png_buffer(const char *path, const image_buffer *buf,
                                    char *err, size_t errsz)
{
    return write_buffer(path, buf, NULL, err, errsz);
}

bool image_preview_write_png_exr(const char *png_path, const char *exr_path,
                                 char *err, size_t errsz)
{
    return image_preview_write_png_exr_cancel(png_path, exr_path, NULL, err, errsz);
}

bool image_preview_write_png_exr_cancel(const char *png_path, const char *exr_path,
                                        const atomic_int *cancel, char *err, size_t errsz)
{
    image_buffer *buf = image_buffer_read_exr_cancel(exr_path, cancel, err, errsz);
    bool ok = buf && write_buffer(png_path, buf, cancel, err, errsz);
    image_buffer_destroy(&buf);
    return ok;
}

bool image_preview_encode_png_rgb8(const uint8_t *rgb, int width, int height,
                                   void **png, size_t *len, char *err,
                                   size_t errsz)
{
    if (!rgb || width < 1 || height < 1 || width > 1000000 || height > 1000000) {
        return err_set(err, errsz, "cannot encode PNG: image size %dx%d out of "
                       "range", width, height);
    }
    pixel_source src = {.rgb8 = rgb, .width = width, .height = height};
    png_context ctx = {.fd = -1};
    if (encode_png(&ctx, &src) != 0) {
        free(ctx.mem);
        return err_set(err, errsz, "cannot encode PNG: %s", ctx.error.message);
    }
    *png = ctx.mem;
    *len = ctx.len;
    return true;
}

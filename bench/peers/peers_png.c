/*
 * peers_png.c: 16-bit linear RGBA PNG in and out for the peer benchmark
 * (peers_png.h), through libpng's classic API so that no gamma conversion
 * happens on the way: the samples are the linear values themselves (the
 * files say so with a gAMA chunk of 1.0, as POV-Ray's with File_Gamma=1.0).
 */
#include "peers_png.h"

#include <png.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct png_ctx {
    const char *path;
    char *err;
    int errsz;
} png_ctx;

static void on_error(png_structp png, png_const_charp msg)
{
    png_ctx *c = png_get_error_ptr(png);
    snprintf(c->err, (size_t)c->errsz, "%s: %s", c->path, msg);
    png_longjmp(png, 1);
}

static void on_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

bool peers_png_write(const char *path, int w, int h, const float *rgba,
                     char *err, int errsz)
{
    png_ctx c = {path, err, errsz};
    size_t row = (size_t)w * 8;
    unsigned char *volatile buf = malloc(row * (size_t)h);
    FILE *volatile f = NULL;
    if (!buf) {
        snprintf(err, (size_t)errsz, "%s: out of memory for a %dx%d image", path, w, h);
        return false;
    }
    for (size_t i = 0; i < (size_t)w * (size_t)h * 4; i++) {
        float v = rgba[i];
        if (!(v > 0)) v = 0;
        if (v > 1) v = 1;
        unsigned s = (unsigned)(v * 65535.0f + 0.5f);
        buf[2 * i] = (unsigned char)(s >> 8);      /* PNG: big endian */
        buf[2 * i + 1] = (unsigned char)(s & 0xff);
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &c, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        snprintf(err, (size_t)errsz, "%s: cannot start libpng", path);
        png_destroy_write_struct(&png, NULL);
        free(buf);
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        if (f) fclose(f);
        remove(path);                /* never a half-written file */
        free(buf);
        return false;
    }
    f = fopen(path, "wb");
    if (!f) {
        snprintf(err, (size_t)errsz, "%s: cannot write: check the directory exists", path);
        png_destroy_write_struct(&png, &info);
        free(buf);
        return false;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 16, PNG_COLOR_TYPE_RGB_ALPHA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_gAMA_fixed(png, info, PNG_FP_1);
    png_write_info(png, info);
    for (int y = 0; y < h; y++) png_write_row(png, buf + row * (size_t)y);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(buf);
    if (fclose(f) != 0) {
        snprintf(err, (size_t)errsz, "%s: write failed (disk full?)", path);
        remove(path);
        return false;
    }
    return true;
}

bool peers_png_read(const char *path, int *w, int *h, float **rgba, char *err, int errsz)
{
    png_ctx c = {path, err, errsz};
    *rgba = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, (size_t)errsz, "%s: cannot open (did the render that writes it fail?)", path);
        return false;
    }
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &c, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    float *volatile out = NULL;
    unsigned char *volatile buf = NULL;
    if (!info) {
        snprintf(err, (size_t)errsz, "%s: cannot start libpng", path);
        png_destroy_read_struct(&png, NULL, NULL);
        fclose(f);
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        free(out);
        free(buf);
        return false;
    }
    png_init_io(png, f);
    png_read_info(png, info);
    /* to 16-bit RGBA, samples untouched: no gamma handling asked for */
    png_set_expand(png);
    png_set_gray_to_rgb(png);
    png_set_add_alpha(png, 0xffff, PNG_FILLER_AFTER);
    png_set_expand_16(png);
    png_read_update_info(png, info);
    int W = (int)png_get_image_width(png, info), H = (int)png_get_image_height(png, info);
    size_t row = png_get_rowbytes(png, info);
    if (row != (size_t)W * 8) {
        snprintf(err, (size_t)errsz, "%s: unexpected PNG layout (%zu bytes per row)", path, row);
        png_longjmp(png, 1);
    }
    buf = malloc(row * (size_t)H);
    out = malloc(sizeof(float) * (size_t)W * (size_t)H * 4);
    if (!buf || !out) {
        snprintf(err, (size_t)errsz, "%s: out of memory for a %dx%d image", path, W, H);
        png_longjmp(png, 1);
    }
    for (int y = 0; y < H; y++) png_read_row(png, buf + row * (size_t)y, NULL);
    png_read_end(png, NULL);
    for (size_t i = 0; i < (size_t)W * (size_t)H * 4; i++)
        out[i] = (float)((buf[2 * i] << 8) | buf[2 * i + 1]) / 65535.0f;
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    free(buf);
    *w = W;
    *h = H;
    *rgba = out;
    return true;
}

/*
 * read_png.c: PNG textures through libpng: 1, 2, 4, 8 and 16 bit grey,
 * grey + alpha, RGB, RGBA and palette images (palettes and low bit depths
 * expanded to 8 bits). Texels are the stored values over 2^bits - 1, with
 * no gamma decoding: a height map's 65535 is 1.0 exactly.
 */
#include "tex/codec_err.h"
#include "tex/tex_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <png.h>

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool tex_read_png(const char *path, tex_pixels *out, char *err, size_t errsz)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        return err_set(err, errsz, "%s: cannot open the texture", path);
    }
    tex_png_error job = { "" };
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &job, tex_png_on_error,
                                             tex_png_on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    float *volatile data = NULL;
    png_bytep volatile row = NULL;
    png_bytep *volatile rows = NULL;
    if (!png || !info) {
        err_set(err, errsz, "%s: out of memory reading PNG", path);
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        err_set(err, errsz, "%s: not a readable PNG image: %s", path, job.message);
        free(data);
        free(row);
        free(rows);
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        return false;
    }
    png_init_io(png, f);
    png_set_user_limits(png, TEX_MAX_SIDE, TEX_MAX_SIDE);
    png_read_info(png, info);
    png_set_expand(png);                 /* palette -> RGB, low bits -> 8, tRNS -> alpha */
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    int w = (int)png_get_image_width(png, info), h = (int)png_get_image_height(png, info);
    int nch = png_get_channels(png, info), bits = png_get_bit_depth(png, info);
    int passes = png_set_interlace_handling(png);
    size_t rowbytes = png_get_rowbytes(png, info);
    data = try_calloc((size_t)w * (size_t)h * (size_t)nch, sizeof(float));
    row = try_malloc(rowbytes * (size_t)h);
    if (!data || !row)
        png_error(png, "out of memory for the pixels");
    rows = try_malloc((size_t)h * sizeof *rows);
    if (!rows)
        png_error(png, "out of memory for the pixels");
    for (int y = 0; y < h; y++)
        rows[y] = row + (size_t)y * rowbytes;
    (void)passes;
    png_read_image(png, rows);
    free(rows);
    rows = NULL;
    double scale = bits == 16 ? 1.0 / 65535.0 : 1.0 / 255.0;
    for (int y = 0; y < h; y++) {
        const png_byte *r = row + (size_t)y * rowbytes;
        for (int k = 0; k < w * nch; k++) {
            unsigned v = bits == 16 ? (unsigned)(r[2 * k] << 8 | r[2 * k + 1]) : r[k];
            data[(size_t)y * (size_t)w * (size_t)nch + (size_t)k] = (float)(v * scale);
        }
    }
    png_read_end(png, NULL);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    free(row);
    out->data = data;
    out->w = w;
    out->h = h;
    out->nch = nch;
    out->type = bits == 16 ? "uint16" : "uint8";
    return true;
}

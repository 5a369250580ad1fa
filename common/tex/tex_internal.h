/*
 * tex_internal.h: what the files of common/tex share: the texture
 * structure (its two pyramids, tex.h) and the image readers' entry points
 * (read_exr.c, read_png.c, read_tiff.c), each filling a tex_pixels.
 */
#ifndef TEX_TEX_INTERNAL_H
#define TEX_TEX_INTERNAL_H

#include "tex/tex.h"

#include <stdint.h>

enum { TEX_MAX_CHANNELS = 64, TEX_MAX_SIDE = 1 << 20 };

/* An image as read: w x h texels of nch channels, interleaved, row 0 the
 * top of the image (t = 0). */
typedef struct tex_pixels {
    float *data;
    int w, h, nch;
    const char *type;     /* "float", "uint8", ... */
} tex_pixels;

struct tex_texture {
    char *name;
    const char *type;
    int w, h, nch, nlevels;
    int *lw, *lh;         /* level k: ceil(w / 2^k) x ceil(h / 2^k) */
    float **avg;          /* level k's texels, interleaved; avg[0] the image */
    float **mn, **mx;     /* min-max pyramid; level 0 is avg[0] itself */
    double *lips, *lipt;  /* per channel: bounds of |d/ds|, |d/dt| */
    size_t bytes;
};

bool tex_read_exr(const char *path, tex_pixels *out, char *err, size_t errsz);
bool tex_read_png(const char *path, tex_pixels *out, char *err, size_t errsz);
bool tex_read_tiff(const char *path, tex_pixels *out, char *err, size_t errsz);

/* Builds the pyramids of an image (taking its pixels). NULL when out of
 * memory. */
tex_texture *tex_build(tex_pixels *px, const char *name);

#endif

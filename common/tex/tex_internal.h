/*
 * tex_internal.h: what the files of common/tex share: the texture
 * structure (its two pyramids, tex.h), the image readers' entry points
 * (read_exr.c, read_png.c, read_tiff.c), each filling a tex_pixels, the
 * reader of aafarm-maketx files (read_tiled.c) and the texel access that
 * goes to a tile loaded on demand where a level is not in memory
 * (tiles.c).
 */
#ifndef TEX_TEX_INTERNAL_H
#define TEX_TEX_INTERNAL_H

#include "tex/tex.h"

#include <stdint.h>

enum { TEX_MAX_CHANNELS = 64, TEX_MAX_SIDE = 1 << 20 };

/* The attributes of part 0 that mark an aafarm-maketx file with its
 * min-max pyramid (write_exr.c, read_tiled.c) and the layout version this
 * reader knows. */
#define TEX_ATTR_VERSION "aafarmTexture"
#define TEX_ATTR_LIPSCHITZ "aafarmLipschitz"
#define TEX_ATTR_TYPE "aafarmType"
enum { TEX_FILE_VERSION = 1 };

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
    size_t bytes;         /* texels in memory for good (not the tiles) */
    struct tex_tiled *tiled;  /* levels whose avg/mn/mx are NULL load in tiles */
};

/* Texel (i, j) of channel c of level k of part p (0 the mean pyramid, 1
 * the min, 2 the max): from memory, or from its tile (tiles.c). */
float tex_tile_texel(const tex_texture *t, int p, int k, int c, int i, int j);

/* out[b * ni + a] = texel (wi[a], wj[b]) of channel c of level k of part
 * p, a tiled level (tex_at's NULL table), for ni, nj <= TEX_BLOCK_MAX
 * valid indexes (tiles.c). */
enum { TEX_BLOCK_MAX = 4 };
void tex_tile_block(const tex_texture *t, int p, int k, int c, const int *wi, int ni,
                    const int *wj, int nj, float *out);

static inline float tex_at(const tex_texture *t, int p, int k, int c, int i, int j)
{
    const float *lv = p == 0 ? t->avg[k] : p == 1 ? t->mn[k] : t->mx[k];
    if (lv)
        return lv[((size_t)j * (size_t)t->lw[k] + (size_t)i) * (size_t)t->nch + (size_t)c];
    return tex_tile_texel(t, p, k, c, i, j);
}

/* Lets go of the tiles this thread holds (tiles.c): each public lookup
 * ends with it, so that a tile is pinned only while a lookup reads it. */
void tex_tiles_unpin(void);

/* An aafarm-maketx file (read_tiled.c): true with *out the texture (or
 * NULL when the file is not one: no TEX_ATTR_VERSION, or no min-max
 * pyramid; then read it as an image); false with err when it claims to be
 * one and is not right. */
bool tex_open_tiled(const char *path, struct tex_tiles *pool, tex_texture **out, char *err,
                    size_t errsz);
/* The name aafarm-maketx gives channel c of nch (write_exr.c): Y; Y A;
 * R G B (A); c00 c01 ... */
void tex_channel_name(int nch, int c, char *out, size_t size);
/* Frees what tex_open_tiled added to a texture (tiles.c) and sets
 * *tiled_p to NULL. */
void tex_tiled_destroy(struct tex_tiled **tiled_p);

bool tex_read_exr(const char *path, tex_pixels *out, char *err, size_t errsz);
bool tex_read_png(const char *path, tex_pixels *out, char *err, size_t errsz);
bool tex_read_tiff(const char *path, tex_pixels *out, char *err, size_t errsz);

/* A texture of w x h texels of nch channels with its levels' sizes
 * (ceil(w / 2^k) x ceil(h / 2^k), down to 1 x 1) and empty level tables
 * (pyramid.c; tex_build and read_tiled.c fill them). */
tex_texture *tex_new_levels(const char *name, const char *type, int w, int h, int nch);

/* Builds the pyramids of an image (taking its pixels). */
tex_texture *tex_build(tex_pixels *px, const char *name);

#endif

/*
 * tiles.h: the tiles of a texture read on demand, as tiles.c (the pool,
 * loading, eviction, the texel access) and read_tiled.c (opening an
 * aafarm-maketx file) share them.
 */
#ifndef TEX_TILES_H
#define TEX_TILES_H

#include "tex/tex_internal.h"

#include <stdatomic.h>

typedef struct tex_tiled tex_tiled;

/* One tile of one level of one part: its texels (tw x th x nch floats,
 * interleaved, row stride tw; NULL when not loaded), the lookups reading
 * it now, and whether it was touched since the clock last passed. */
typedef struct tex_tile {
    _Atomic(float *) data;
    atomic_uint pins;
    atomic_bool used;
    int at;                        /* index in the pool's loaded tiles; -1: none (lock) */
    int part, level, tx, ty;
    tex_tiled *owner;
} tex_tile;

struct tex_tiled {
    void *exr;                     /* the file's OpenEXRCore read context */
    struct tex_tiles *pool;
    bool own_pool;
    const tex_texture *tex;
    int tw, th;                    /* the file's tile size */
    int resident;                  /* levels k < resident load in tiles, the rest are in memory */
    int *ntx;                      /* per tiled level: tiles across */
    tex_tile **tiles;              /* [p * resident + k]: part p's tiles of level k, row by row */
    int slot[TEX_MAX_CHANNELS];    /* the file's channel c is the texture's slot[c] */
    atomic_bool warned;            /* a tile that could not be read was reported */
};

/* A texture's tiled levels 0 .. resident - 1 over the open file exr (taken:
 * closed by tex_tiled_destroy); pool NULL: a pool of its own without budget.
 * Fill slot[] before the first read. */
tex_tiled *tex_tiled_new(void *exr, struct tex_tiles *pool, const tex_texture *t, int tw,
                         int th, int resident);
/* Decodes tile (tx, ty) of level k of part p into dst (its first texel;
 * rows `line` texels apart). */
bool tex_tiled_decode(const tex_tiled *tl, int p, int k, int tx, int ty, float *dst,
                      size_t line);

#endif

/*
 * tex.h: textures for the shading language's texture(), environment(),
 * bump() and textureinfo() (RI Spec 3.2 §15.7; issue 16): images read from
 * OpenEXR, PNG and TIFF files, the two pyramids built from them, the one
 * filter that float and dual lookups evaluate, the bound of that filter
 * over a range of lookups that interval and affine runs use, and the
 * per-process cache that opens textures by name through a resolver.
 *
 * The filter (docs/textures.md, "The filter"): a texture of W x H texels
 * has levels k = 0, 1, ... of ceil(W / 2^k) x ceil(H / 2^k) texels, each
 * texel of level k the mean of the level-0 texels of its 2^k x 2^k block
 * (the block cut at the image's edge). A lookup at (s, t) with footprint
 * (ws, wt) (widths in s and t units) takes l = log2(max(ws W, wt H)),
 * clamped to [0, last level], and blends the bilinear interpolations of
 * levels floor(l) and floor(l) + 1 (trilinear mip-mapping). Level k's
 * texel (i, j) has its centre at s = (i + 1/2) / W_k; texels outside the
 * image follow the wrap mode: periodic, clamp (the edge texel) or black
 * (0). Derivatives (dual mode) are those of the blend at fixed footprint.
 *
 * The bound (Thonat et al. 2021, "Tessellation-free displacement mapping
 * for ray tracing", §4: a min-max hierarchy; Logie 1995 bounds height
 * fields the same way): level m of the min-max pyramid holds the min and
 * max of the level-0 texels of each 2^m x 2^m block. A lookup at any (s, t)
 * of a rectangle with any footprint of a range is a convex combination of
 * the level-0 texels under the blocks of the texels its bilinear cells
 * touch at the levels its footprints select (widened by the wrap mode: the
 * other edge for periodic, 0 for black), so the min and max of those
 * texels bound it; the min-max pyramid answers that at the level where
 * the rectangle spans a few texels.
 *
 * Memory (util/xalloc.h): the image readers (read_exr.c, read_png.c,
 * read_tiff.c) survive out of memory: the texel buffer of the size a file
 * states is a try_* allocation, and when it fails tex_open returns NULL
 * with "path: out of memory ..." (tests/tex/test_tex_read.c drives it with
 * a PNG that claims 2^20 x 2^20 texels). Everything else (the pyramids, the
 * tiles, the cache) aborts naming the size.
 */
#ifndef TEX_TEX_H
#define TEX_TEX_H

#include <stdbool.h>
#include <stddef.h>

typedef enum tex_wrap { TEX_WRAP_PERIODIC = 0, TEX_WRAP_CLAMP = 1, TEX_WRAP_BLACK = 2 } tex_wrap;

/* "periodic" (also "repeat"), "clamp", "black": the mode, or -1. */
int tex_wrap_find(const char *name);

typedef struct tex_texture tex_texture;

/* Reads an image file (OpenEXR half/float/uint, PNG 8/16 bit, TIFF 8/16/32
 * bit integer or float, any number of channels; the format from the file's
 * first bytes, not its name) and builds its pyramids. Integer texels map to
 * [0, 1]; non-finite texels read as 0. On failure returns NULL and writes
 * "path: what went wrong" into err. */
tex_texture *tex_open(const char *path, char *err, size_t errsz);

/* Tiles loaded on demand (tiles.c; docs/textures.md "Memory"): an
 * aafarm-maketx file (read_tiled.c) keeps its small levels (up to
 * TEX_RESIDENT_TEXELS texels each) in memory and reads the texels of the
 * larger ones, of the mean and the min-max pyramid, in the file's tiles on
 * first touch. A pool holds the tiles of the textures opened with it under
 * one byte budget: beyond it the least recently used tiles that no lookup
 * is reading are evicted (a clock sweep), and read again when touched. */
enum { TEX_RESIDENT_TEXELS = 256 * 256 };
typedef struct tex_tiles tex_tiles;
/* budget: bytes of loaded tiles (0: no limit). A tile some lookup is
 * reading is never evicted, so the pool may pass its budget by the tiles
 * being read at once (a few per thread). */
tex_tiles *tex_tiles_new(size_t budget);
/* Only after every texture opened with it is freed. */
void tex_tiles_destroy(tex_tiles **pool_p);
/* The pool a process's caches use unless told otherwise (budget
 * TEX_DEFAULT_TILE_BYTES until set; aafarm-worker --texture-bytes). */
#define TEX_DEFAULT_TILE_BYTES ((size_t)512 << 20)
tex_tiles *tex_tiles_process(void);
void tex_tiles_set_budget(tex_tiles *pool, size_t budget);
typedef struct tex_tile_stats {
    size_t budget, bytes, peak_bytes;   /* bytes of tiles: the budget, now, the most */
    unsigned long long loads, evictions, failures;  /* failures: tiles that could not be read */
} tex_tile_stats;
void tex_tiles_stats(tex_tiles *pool, tex_tile_stats *out);
/* Where the pool reports a tile that cannot be read (a damaged or
 * truncated file after it was opened; its texels are then the map's mean
 * and bounds), once per texture: one line without a newline. Called with
 * the pool's lock held (it must not call into the pool). NULL (the
 * default): only counted in tex_tile_stats.failures; the worker prints
 * them on stderr. */
typedef void (*tex_warn_fn)(void *ctx, const char *message);
void tex_tiles_set_warn(tex_tiles *pool, tex_warn_fn fn, void *ctx);
/* tex_open with the tiles of an aafarm-maketx file in pool (NULL: a pool
 * of its own without a budget). */
tex_texture *tex_open_in(const char *path, tex_tiles *pool, char *err, size_t errsz);
/* The levels read in tiles (0: all in memory). */
int tex_tiled_levels(const tex_texture *t);
/* A texture from memory: w x h texels of nch channels, interleaved (for
 * tests and tools). */
tex_texture *tex_from_pixels(const float *pixels, int w, int h, int nch, const char *name);
void tex_destroy(tex_texture **t_p);

int tex_width(const tex_texture *t);
int tex_height(const tex_texture *t);
int tex_channels(const tex_texture *t);
int tex_levels(const tex_texture *t);
const char *tex_name(const tex_texture *t);
/* "float" for float or half files, "uint8"/"uint16"/"uint32" else (the
 * type the file stored). */
const char *tex_type(const tex_texture *t);
/* Bytes held by the texels of the two pyramids in memory for good (a
 * texture read in tiles: its resident levels; the tiles are its pool's). */
size_t tex_bytes(const tex_texture *t);
/* Level k's texel (i, j) of channel c (no wrapping: in range only). */
float tex_texel(const tex_texture *t, int level, int c, int i, int j);

/* The footprint's level: log2(max(ws W, wt H)) clamped to [0, levels - 1]. */
double tex_level_of(const tex_texture *t, double ws, double wt);

/* The filter at (s, t) with footprint (ws, wt) for channel c, with d/ds
 * and d/dt (may be NULL). A channel the texture lacks gives `fill`; a
 * non-finite s or t gives 0. */
double tex_sample(const tex_texture *t, int c, double s, double tt, double ws, double wt,
                  tex_wrap swrap, tex_wrap twrap, double fill, double *dds, double *ddt);

/* The ranges of a lookup: s, t, and the footprint widths (each [lo, hi];
 * a NaN or infinite end means anything). */
typedef struct tex_range {
    double s[2], t[2], ws[2], wt[2];
} tex_range;

/* lo <= filter <= hi for every lookup of range r (channel c, or fill). */
void tex_bound(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
               tex_wrap twrap, double fill, double *lo, double *hi);

/* One bilinear cell of one level: the filter's part from it is weight *
 * bilerp(v, s w - 1/2 - oi, t h - 1/2 - oj), v[0] = texel (oi, oj), v[1] =
 * (oi+1, oj), v[2] = (oi, oj+1), v[3] = (oi+1, oj+1) (wrapped). */
typedef struct tex_cell {
    double weight, oi, oj, v[4];
    int w, h;
} tex_cell;

/* Where every lookup of r blends the same cells (a footprint of one level
 * blend, s and t inside one cell of each level used): their number (1 or
 * 2) into out; 0 elsewhere. The filter is then the sum of the cells'
 * parts, which affine runs write as an affine form of s and t. */
int tex_cells(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
              tex_wrap twrap, tex_cell out[2]);
/* tex_cells where it gives cells (returns their number, out filled), else
 * tex_bound (returns 0, [*lo, *hi]): the same results as the two calls,
 * with the filter's levels computed once (issue 24: the affine lookup's
 * path). */
int tex_cells_or_bound(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
                       tex_wrap twrap, double fill, tex_cell out[2], double *lo, double *hi);

/* Slope bounds of the filter over a range of lookups, for proofs that
 * need them (trace/prove.c): ds[0] <= d filter / ds <= ds[1] and dt
 * likewise, at every (s, t) of r where the filter is differentiable. At
 * one level blend the filter is continuous in (s, t) under every wrap
 * (bilinear cells meet at their edges; a clamped coordinate is constant),
 * so these are its Lipschitz slopes. True where the blend is one over r:
 * the widths' levels agree, or fixed_widths (the caller knows the widths
 * are constant over r, their ranges only rounding) and the levels share
 * their pair. False elsewhere, or where r spans too many cells. A channel
 * the texture lacks: 0. */
bool tex_slopes(const tex_texture *t, int c, const tex_range *r, tex_wrap swrap,
                tex_wrap twrap, bool fixed_widths, double ds[2], double dt[2]);
/* Bounds of |d filter / ds| and |d filter / dt| of channel c over all
 * lookups at any footprint (0 for a missing channel). */
void tex_lipschitz(const tex_texture *t, int c, double *ls, double *lt);

/* Writes t as a tiled, mip-mapped OpenEXR file: part "mean" with the mean
 * pyramid as its levels, and with minmax also parts "min" and "max"
 * (write_exr.c; docs/textures.md). Atomic: a temporary file renamed into
 * place. false with "path: reason" in err. */
bool tex_write_exr(const char *path, const tex_texture *t, bool minmax, char *err,
                   size_t errsz);

/* ---- the per-process cache ---- */

/* Finds the file of texture `name`: true with its path, or false with a
 * reason in err ("not found on the texture search path a:b"). */
typedef bool (*tex_resolve_fn)(void *ctx, const char *name, char *path, size_t path_size,
                               char *err, size_t errsz);

typedef struct tex_cache tex_cache;

/* A cache of open textures by name, shared by threads: resolve and open
 * happen once per name, under a lock; lookups of open names take the lock
 * only to read the table. budget: bytes of texels before opening another
 * texture fails (0: no limit); tiles loaded on demand count against their
 * pool's budget instead (tex_cache_set_tiles). */
tex_cache *tex_cache_new(size_t budget);
void tex_cache_destroy(tex_cache **self_p);
/* The tile pool of the textures it opens from now on (default: the
 * process's, tex_tiles_process). */
void tex_cache_set_tiles(tex_cache *self, tex_tiles *pool);
/* Installs the resolver (NULL: names are paths). */
void tex_cache_set_resolver(tex_cache *self, tex_resolve_fn fn, void *ctx);
/* The texture called name, opening it on first use; NULL with err. */
const tex_texture *tex_cache_get(tex_cache *self, const char *name, char *err, size_t errsz);
/* Puts a texture (made in memory) under name; the cache owns it. */
bool tex_cache_put(tex_cache *self, const char *name, tex_texture *t);
size_t tex_cache_bytes(const tex_cache *self);

/* The default resolver: a texture search path ("dir:dir"; "&" the
 * previous path, here the base folder; "@" the base folder) and a base
 * folder (the scene file's) for relative names. */
typedef struct tex_searchpath {
    char path[4096];
    char base[4096];
} tex_searchpath;
bool tex_searchpath_resolve(void *ctx, const char *name, char *path, size_t path_size,
                            char *err, size_t errsz);

#endif

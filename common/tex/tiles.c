/*
 * tiles.c: the levels of a texture that are read in tiles on demand (tex.h
 * "Tiles loaded on demand"; docs/textures.md "Memory"): the tile pool and
 * its byte budget, the texel access of a tiled level, loading a tile from
 * the aafarm-maketx file (OpenEXRCore tiled reads) and evicting the least
 * recently used ones.
 *
 * Thread safety without a lock on the hot path: each tile has an atomic
 * data pointer and an atomic count of the lookups reading it (pins). A
 * reader counts itself in first and then reads the pointer; the evictor,
 * under the pool's mutex, swaps the pointer for NULL first and then reads
 * the count, and puts the pointer back when it is not 0. With sequentially
 * consistent atomics one of the two always sees the other: either the
 * evictor sees the pin (and keeps the tile), or the reader sees NULL (and
 * loads the tile under the mutex). So a tile is freed only when nobody
 * reads it. A thread keeps the few tiles it touched during one lookup
 * pinned (a small per-thread table) and lets go of them when the lookup
 * returns (tex_tiles_unpin).
 *
 * Recency is a clock: a touch sets the tile's `used` flag (a relaxed
 * store, only when it is clear); the sweep clears flags and evicts the
 * first unpinned tile whose flag is clear, an approximation of least
 * recently used that costs the readers no shared writes.
 *
 * A tile that cannot be read (a disk error after the file was opened and
 * its hash checked) holds the top level's texels (the map's mean, min and
 * max: its bound stays true); the pool counts it, and the first one of a
 * texture is handed to the pool's warning callback (tex_tiles_set_warn:
 * the program decides where it goes; this library prints nothing).
 */
#include "tex/tex_internal.h"
#include "tex/tiles.h"

#include <openexr.h>

#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

struct tex_tiles {
    pthread_mutex_t lock;
    size_t budget, bytes, peak;
    unsigned long long loads, evictions, failures;
    tex_tile **loaded;       /* the tiles with data, in no order; the clock's ring */
    int n, cap, hand;
    tex_warn_fn warn;        /* a tile that cannot be read; NULL: counted only */
    void *warn_ctx;
};

tex_tiles *tex_tiles_new(size_t budget)
{
    tex_tiles *pool = xcalloc(1, sizeof *pool);
    pthread_mutex_init(&pool->lock, NULL);
    pool->budget = budget;
    return pool;
}

void tex_tiles_destroy(tex_tiles **pool_p)
{
    tex_tiles *pool = *pool_p;
    if (!pool)
        return;
    /* every texture opened with it is gone, and with it its tiles */
    assert(pool->n == 0 && pool->bytes == 0);
    free(pool->loaded);
    pthread_mutex_destroy(&pool->lock);
    free(pool);
    *pool_p = NULL;
}

static tex_tiles *process_pool;
static pthread_once_t process_once = PTHREAD_ONCE_INIT;

static void make_process_pool(void)
{
    process_pool = tex_tiles_new(TEX_DEFAULT_TILE_BYTES);
}

tex_tiles *tex_tiles_process(void)
{
    pthread_once(&process_once, make_process_pool);
    return process_pool;
}

static void evict_to_budget(tex_tiles *pool, const tex_tile *keep);

void tex_tiles_set_budget(tex_tiles *pool, size_t budget)
{
    pthread_mutex_lock(&pool->lock);
    pool->budget = budget;
    evict_to_budget(pool, NULL);
    pthread_mutex_unlock(&pool->lock);
}

void tex_tiles_set_warn(tex_tiles *pool, tex_warn_fn fn, void *ctx)
{
    pthread_mutex_lock(&pool->lock);
    pool->warn = fn;
    pool->warn_ctx = ctx;
    pthread_mutex_unlock(&pool->lock);
}

void tex_tiles_stats(tex_tiles *pool, tex_tile_stats *out)
{
    pthread_mutex_lock(&pool->lock);
    out->budget = pool->budget;
    out->bytes = pool->bytes;
    out->peak_bytes = pool->peak;
    out->loads = pool->loads;
    out->evictions = pool->evictions;
    out->failures = pool->failures;
    pthread_mutex_unlock(&pool->lock);
}

/* ---- a texture's tiles ---- */

tex_tiled *tex_tiled_new(void *exr, tex_tiles *pool, const tex_texture *t, int tw, int th,
                         int resident)
{
    tex_tiled *tl = xcalloc(1, sizeof *tl);
    tl->exr = exr;
    tl->own_pool = pool == NULL;
    tl->pool = pool ? pool : tex_tiles_new(0);
    tl->tex = t;
    tl->tw = tw;
    tl->th = th;
    tl->resident = resident;
    tl->ntx = xcalloc((size_t)resident + 1, sizeof *tl->ntx);
    tl->tiles = xcalloc(3 * ((size_t)resident + 1), sizeof *tl->tiles);
    for (int k = 0; k < resident; k++) {
        int nx = (t->lw[k] + tw - 1) / tw, ny = (t->lh[k] + th - 1) / th;
        tl->ntx[k] = nx;
        for (int p = 0; p < 3; p++) {
            if (k == 0 && p > 0)
                continue;              /* level 0's min and max are the image */
            tex_tile *v = xcalloc((size_t)nx * (size_t)ny, sizeof *v);
            tl->tiles[p * resident + k] = v;
            for (int y = 0; y < ny; y++)
                for (int x = 0; x < nx; x++) {
                    tex_tile *tile = &v[(size_t)y * nx + x];
                    atomic_init(&tile->data, NULL);
                    atomic_init(&tile->pins, 0);
                    atomic_init(&tile->used, false);
                    tile->at = -1;
                    tile->part = p;
                    tile->level = k;
                    tile->tx = x;
                    tile->ty = y;
                    tile->owner = tl;
                }
        }
    }
    atomic_init(&tl->warned, false);
    return tl;
}

static size_t tile_bytes(const tex_tiled *tl)
{
    return (size_t)tl->tw * (size_t)tl->th * (size_t)tl->tex->nch * sizeof(float);
}

static void drop(tex_tiles *pool, tex_tile *tile)
{
    assert(tile->at >= 0 && tile->at < pool->n && pool->loaded[tile->at] == tile);
    assert(pool->bytes >= tile_bytes(tile->owner));
    pool->loaded[tile->at] = pool->loaded[pool->n - 1];
    pool->loaded[tile->at]->at = tile->at;
    pool->n--;
    if (pool->hand >= pool->n)
        pool->hand = 0;
    tile->at = -1;
    pool->bytes -= tile_bytes(tile->owner);
}

void tex_tiled_destroy(tex_tiled **tl_p)
{
    tex_tiled *tl = *tl_p;
    if (!tl)
        return;
    if (tl->pool && tl->tiles) {
        pthread_mutex_lock(&tl->pool->lock);
        for (int q = 0; q < 3 * tl->resident; q++) {
            tex_tile *v = tl->tiles[q];
            int k = q % tl->resident;
            int ny = v ? (tl->tex->lh[k] + tl->th - 1) / tl->th : 0;
            for (size_t e = 0; v && e < (size_t)tl->ntx[k] * (size_t)ny; e++) {
                if (v[e].at >= 0)
                    drop(tl->pool, &v[e]);
                free(atomic_load(&v[e].data));
            }
            free(v);
        }
        pthread_mutex_unlock(&tl->pool->lock);
    }
    if (tl->own_pool)
        tex_tiles_destroy(&tl->pool);
    if (tl->exr) {
        exr_context_t ctx = tl->exr;
        exr_finish(&ctx);
    }
    free(tl->tiles);
    free(tl->ntx);
    free(tl);
    *tl_p = NULL;
}

int tex_tiled_levels(const tex_texture *t)
{
    return t->tiled ? t->tiled->resident : 0;
}

/* ---- reading a tile ---- */

bool tex_tiled_decode(const tex_tiled *tl, int p, int k, int tx, int ty, float *dst,
                      size_t line)
{
    exr_context_t ctx = tl->exr;
    exr_chunk_info_t ci;
    exr_result_t rv = exr_read_tile_chunk_info(ctx, p, tx, ty, k, k, &ci);
    if (rv != EXR_ERR_SUCCESS)
        return false;
    int nch = tl->tex->nch;
    exr_decode_pipeline_t dec;
    memset(&dec, 0, sizeof dec);
    rv = exr_decoding_initialize(ctx, p, &ci, &dec);
    if (rv == EXR_ERR_SUCCESS && dec.channel_count != nch)
        rv = EXR_ERR_BAD_CHUNK_LEADER;
    for (int c = 0; rv == EXR_ERR_SUCCESS && c < dec.channel_count; c++) {
        exr_coding_channel_info_t *info = &dec.channels[c];
        info->decode_to_ptr = (uint8_t *)(dst + tl->slot[c]);
        info->user_pixel_stride = (int32_t)((size_t)nch * sizeof(float));
        info->user_line_stride = (int32_t)(line * (size_t)nch * sizeof(float));
        info->user_data_type = EXR_PIXEL_FLOAT;
        info->user_bytes_per_element = (int16_t)sizeof(float);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_decoding_choose_default_routines(ctx, p, &dec);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_decoding_run(ctx, p, &dec);
    exr_decoding_destroy(ctx, &dec);
    return rv == EXR_ERR_SUCCESS;
}

/* The tile's texels, read from the file (or the top level's where that
 * fails). */
static float *read_tile(tex_tiles *pool, tex_tile *tile)
{
    tex_tiled *tl = tile->owner;
    const tex_texture *t = tl->tex;
    size_t count = (size_t)tl->tw * (size_t)tl->th * (size_t)t->nch;
    float *d = xmalloc(count * sizeof *d);
    if (!tex_tiled_decode(tl, tile->part, tile->level, tile->tx, tile->ty, d, (size_t)tl->tw)) {
        const float *top = tile->part == 0 ? t->avg[t->nlevels - 1]
                         : tile->part == 1 ? t->mn[t->nlevels - 1] : t->mx[t->nlevels - 1];
        for (size_t e = 0; e < count; e++)
            d[e] = top[e % (size_t)t->nch];
        pool->failures++;
        if (pool->warn && !atomic_exchange(&tl->warned, true)) {
            char msg[ERR_LEN];
            err_set(msg, sizeof msg, "texture %s: tile %d,%d of level %d (part %d) cannot be "
                    "read (damaged or truncated file?); its texels are the map's mean and "
                    "bounds; check the disk and make the file again with aafarm-maketx",
                    t->name, tile->tx, tile->ty, tile->level, tile->part);
            pool->warn(pool->warn_ctx, msg);
        }
    }
    return d;
}

/* Under the lock: evicts unpinned tiles, least recently used first, until
 * the pool fits its budget or every tile is pinned (or is keep). */
static void evict_to_budget(tex_tiles *pool, const tex_tile *keep)
{
    int passes = 0;
    while (pool->budget && pool->bytes > pool->budget && pool->n > 0 && passes < 2 * pool->n + 2) {
        passes++;
        if (pool->hand >= pool->n)
            pool->hand = 0;
        tex_tile *tile = pool->loaded[pool->hand];
        if (tile == keep || atomic_load_explicit(&tile->used, memory_order_relaxed)) {
            atomic_store_explicit(&tile->used, false, memory_order_relaxed);
            pool->hand++;
            continue;
        }
        float *d = atomic_exchange(&tile->data, NULL);
        if (atomic_load(&tile->pins) != 0) {
            atomic_store(&tile->data, d);       /* a lookup reads it: keep it */
            pool->hand++;
            continue;
        }
        assert(d != NULL);                       /* a loaded tile has its texels */
        free(d);
        drop(pool, tile);
        pool->evictions++;
        passes = 0;
    }
}

/* Loads the tile (the caller holds a pin on it): its data. */
static const float *load(tex_tile *tile)
{
    tex_tiles *pool = tile->owner->pool;
    pthread_mutex_lock(&pool->lock);
    float *d = atomic_load(&tile->data);
    if (!d) {
        if (pool->n == pool->cap) {
            int cap = pool->cap ? 2 * pool->cap : 256;
            pool->loaded = xreallocarray(pool->loaded, (size_t)cap, sizeof *pool->loaded);
            pool->cap = cap;
        }
        d = read_tile(pool, tile);
        assert(tile->at == -1 && pool->n < pool->cap);
        tile->at = pool->n;
        pool->loaded[pool->n++] = tile;
        pool->bytes += tile_bytes(tile->owner);
        pool->loads++;
        evict_to_budget(pool, tile);
        if (pool->bytes > pool->peak)
            pool->peak = pool->bytes;
        atomic_store(&tile->data, d);
    }
    pthread_mutex_unlock(&pool->lock);
    return d;
}

/* ---- the texel access ---- */

enum { PINS = 16 };

static _Thread_local struct {
    int n;
    tex_tile *tile[PINS];
    const float *data[PINS];
} pinned;

void tex_tiles_unpin(void)
{
    for (int q = 0; q < pinned.n; q++) {
        unsigned before = atomic_fetch_sub(&pinned.tile[q]->pins, 1);
        assert(before > 0);                      /* each pin taken once, let go once */
        (void)before;
    }
    pinned.n = 0;
}

/* The texels of a tile, pinned by this thread until the lookup returns. */
static const float *pin(tex_tile *tile)
{
    for (int q = 0; q < pinned.n; q++)
        if (pinned.tile[q] == tile)
            return pinned.data[q];
    if (pinned.n == PINS)
        tex_tiles_unpin();
    atomic_fetch_add(&tile->pins, 1);
    const float *d = atomic_load(&tile->data);
    if (!d)
        d = load(tile);
    if (!atomic_load_explicit(&tile->used, memory_order_relaxed))
        atomic_store_explicit(&tile->used, true, memory_order_relaxed);
    pinned.tile[pinned.n] = tile;
    pinned.data[pinned.n++] = d;
    return d;
}

float tex_tile_texel(const tex_texture *t, int p, int k, int c, int i, int j)
{
    const tex_tiled *tl = t->tiled;
    if (k == 0)
        p = 0;
    int tx = i / tl->tw, ty = j / tl->th;
    tex_tile *tile = &tl->tiles[p * tl->resident + k][(size_t)ty * tl->ntx[k] + tx];
    size_t at = ((size_t)(j - ty * tl->th) * (size_t)tl->tw + (size_t)(i - tx * tl->tw)) *
                    (size_t)t->nch + (size_t)c;
    return pin(tile)[at];
}

/* The same texels as tex_tile_texel at (wi[a], wj[b]), a block at a time
 * (issue 24: a bound reads up to 4 x 4 texels, and each texel's tile
 * division and pin search was most of its cost): the divisions once per
 * column and row, the pin search once per tile the block touches. */
void tex_tile_block(const tex_texture *t, int p, int k, int c, const int *wi, int ni,
                    const int *wj, int nj, float *out)
{
    assert(ni >= 1 && ni <= TEX_BLOCK_MAX && nj >= 1 && nj <= TEX_BLOCK_MAX);
    const tex_tiled *tl = t->tiled;
    if (k == 0)
        p = 0;
    int tx[TEX_BLOCK_MAX], ox[TEX_BLOCK_MAX], ty[TEX_BLOCK_MAX], oy[TEX_BLOCK_MAX];
    for (int a = 0; a < ni; a++) {
        tx[a] = wi[a] / tl->tw;
        ox[a] = wi[a] - tx[a] * tl->tw;
    }
    for (int b = 0; b < nj; b++) {
        ty[b] = wj[b] / tl->th;
        oy[b] = wj[b] - ty[b] * tl->th;
    }
    tex_tile *row = tl->tiles[p * tl->resident + k], *last = NULL;
    const float *d = NULL;
    for (int b = 0; b < nj; b++)
        for (int a = 0; a < ni; a++) {
            tex_tile *tile = &row[(size_t)ty[b] * tl->ntx[k] + tx[a]];
            if (tile != last) {
                d = pin(tile);
                last = tile;
            }
            size_t at = ((size_t)oy[b] * (size_t)tl->tw + (size_t)ox[a]) * (size_t)t->nch +
                        (size_t)c;
            out[b * ni + a] = d[at];
        }
}

/*
 * read_tiled.c: opening an aafarm-maketx file (write_exr.c) with its
 * stored pyramids, so that opening it builds nothing: the layout checked
 * (version, parts "mean", "min" and "max", tiled mip-map levels of the
 * image's size, the channels aafarm-maketx names, 32-bit float, the
 * derivative bounds and the source type in part 0's attributes), the small
 * levels read into memory, the large ones left to tiles.c to read on
 * demand (docs/textures.md "Memory").
 *
 * A file without the TEX_ATTR_VERSION attribute (any other OpenEXR, or
 * aafarm-maketx --no-minmax) is not one: tex_open reads its level 0 as an
 * image and builds the pyramids. A file that has it and is wrong in any
 * other way is refused with what is wrong and what to do (make it again).
 */
#include "tex/codec_err.h"
#include "tex/tex_internal.h"
#include "util/err.h"
#include "tex/tiles.h"
#include "util/xalloc.h"

#include <openexr.h>

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const part_names[3] = { "mean", "min", "max" };

/* Checks part p's layout against part 0's (w, h, tw, th, levels, nch). */
static bool check_part(exr_context_t ctx, int p, int w, int h, uint32_t tw, uint32_t th,
                       int nlevels, int nch, char *err, size_t errsz)
{
    const char *name = NULL;
    exr_storage_t storage;
    exr_attr_box2i_t box;
    uint32_t x, y;
    exr_tile_level_mode_t mode;
    exr_tile_round_mode_t round;
    int32_t lx = 0, ly = 0;
    const exr_attr_chlist_t *ch = NULL;
    if (exr_get_name(ctx, p, &name) != EXR_ERR_SUCCESS || !name ||
        strcmp(name, part_names[p]) != 0) {
        return err_set(err, errsz, "part %d is not named \"%s\"", p, part_names[p]);
    }
    if (exr_get_storage(ctx, p, &storage) != EXR_ERR_SUCCESS || storage != EXR_STORAGE_TILED ||
        exr_get_tile_descriptor(ctx, p, &x, &y, &mode, &round) != EXR_ERR_SUCCESS ||
        mode != EXR_TILE_MIPMAP_LEVELS || round != EXR_TILE_ROUND_UP || x != tw || y != th ||
        exr_get_tile_levels(ctx, p, &lx, &ly) != EXR_ERR_SUCCESS || lx != nlevels) {
        return err_set(err, errsz, "part \"%s\" is not tiled in %u x %u mip-map levels rounded up "
                       "(%d levels)", name, tw, th, nlevels);
    }
    if (exr_get_data_window(ctx, p, &box) != EXR_ERR_SUCCESS || box.min.x != 0 ||
        box.min.y != 0 || box.max.x != w - 1 || box.max.y != h - 1) {
        return err_set(err, errsz, "part \"%s\"'s data window is not [0, %d] x [0, %d]", name, w - 1,
                       h - 1);
    }
    if (exr_get_channels(ctx, p, &ch) != EXR_ERR_SUCCESS || ch->num_channels != nch) {
        return err_set(err, errsz, "part \"%s\" has not the %d channels of part \"mean\"", name, nch);
    }
    for (int c = 0; c < nch; c++) {
        bool known = false;
        for (int q = 0; q < nch; q++) {
            char cn[16];
            tex_channel_name(nch, q, cn, sizeof cn);
            known = known || strcmp(cn, ch->entries[c].name.str) == 0;
        }
        if (!known || ch->entries[c].pixel_type != EXR_PIXEL_FLOAT ||
            ch->entries[c].x_sampling != 1 || ch->entries[c].y_sampling != 1) {
            return err_set(err, errsz, "part \"%s\"'s channel '%s' is not one aafarm-maketx writes "
                           "(32-bit float, full resolution, named for %d channels)", name,
                           ch->entries[c].name.str, nch);
        }
    }
    return true;
}

/* Reads level k of part p whole (it is resident). */
static float *read_level(const tex_tiled *tl, const tex_texture *t, int p, int k)
{
    int w = t->lw[k], h = t->lh[k];
    size_t count = (size_t)w * (size_t)h * (size_t)t->nch;
    float *v = xmalloc(count * sizeof *v);
    for (int ty = 0; ty * tl->th < h; ty++)
        for (int tx = 0; tx * tl->tw < w; tx++) {
            float *dst = v + ((size_t)ty * tl->th * (size_t)w + (size_t)tx * tl->tw) * t->nch;
            if (!tex_tiled_decode(tl, p, k, tx, ty, dst, (size_t)w)) {
                free(v);
                return NULL;
            }
        }
    for (size_t e = 0; e < count; e++)
        if (!isfinite(v[e])) {
            free(v);
            return NULL;
        }
    return v;
}

static bool refuse(char *err, size_t errsz, const char *path, const char *what)
{
    err_set(err, errsz, "%s: an aafarm-maketx texture (version %d) whose %s%s%s; make it "
            "again with aafarm-maketx", path, TEX_FILE_VERSION, what,
            tex_exr_message()[0] ? ": " : "", tex_exr_message());
    tex_exr_clear();
    return false;
}

bool tex_open_tiled(const char *path, tex_tiles *pool, tex_texture **out, char *err,
                    size_t errsz)
{
    *out = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = tex_exr_on_error;
    exr_context_t ctx = NULL;
    tex_exr_clear();
    int32_t version = 0;
    if (exr_start_read(&ctx, path, &init) != EXR_ERR_SUCCESS ||
        exr_attr_get_int(ctx, 0, TEX_ATTR_VERSION, &version) != EXR_ERR_SUCCESS) {
        exr_finish(&ctx);            /* not ours: read as an image (read.c) */
        tex_exr_clear();
        return true;
    }
    char what[ERR_LEN];
    if (version != TEX_FILE_VERSION) {
        err_set(err, errsz, "%s: made by an aafarm-maketx of texture layout version %d; this "
                "aafarm reads version %d: make it again with this aafarm-maketx", path,
                (int)version, TEX_FILE_VERSION);
        exr_finish(&ctx);
        return false;
    }
    int nparts = 0;
    exr_attr_box2i_t box;
    const exr_attr_chlist_t *ch = NULL;
    uint32_t tw = 0, th = 0;
    exr_tile_level_mode_t mode;
    exr_tile_round_mode_t round;
    if (exr_get_count(ctx, &nparts) != EXR_ERR_SUCCESS || nparts != 3) {
        snprintf(what, sizeof what, "file has %d parts, not 3 (mean, min, max)", nparts);
        exr_finish(&ctx);
        return refuse(err, errsz, path, what);
    }
    if (exr_get_data_window(ctx, 0, &box) != EXR_ERR_SUCCESS ||
        exr_get_channels(ctx, 0, &ch) != EXR_ERR_SUCCESS ||
        exr_get_tile_descriptor(ctx, 0, &tw, &th, &mode, &round) != EXR_ERR_SUCCESS) {
        exr_finish(&ctx);
        return refuse(err, errsz, path, "part \"mean\" is not a tiled image");
    }
    long w = (long)box.max.x - box.min.x + 1, h = (long)box.max.y - box.min.y + 1;
    int nch = ch->num_channels;
    if (w < 1 || h < 1 || w > TEX_MAX_SIDE || h > TEX_MAX_SIDE || nch < 1 ||
        nch > TEX_MAX_CHANNELS || tw < 1 || th < 1 || tw > 4096 || th > 4096) {
        snprintf(what, sizeof what, "image is %ld x %ld with %d channels in %u x %u tiles "
                 "(sides 1 to %d, 1 to %d channels, tiles of 1 to 4096)", w, h, nch, tw, th,
                 TEX_MAX_SIDE, TEX_MAX_CHANNELS);
        exr_finish(&ctx);
        return refuse(err, errsz, path, what);
    }
    int nlevels = 1;
    for (long a = w, b = h; a > 1 || b > 1; nlevels++) {
        a = (a + 1) / 2;
        b = (b + 1) / 2;
    }
    for (int p = 0; p < 3; p++)
        if (!check_part(ctx, p, (int)w, (int)h, tw, th, nlevels, nch, what, sizeof what)) {
            exr_finish(&ctx);
            return refuse(err, errsz, path, what);
        }
    /* the derivative bounds: 2 nch numbers (s, t per channel) */
    const char *lip = NULL, *type = NULL;
    int32_t liplen = 0, typelen = 0;
    double lips[TEX_MAX_CHANNELS], lipt[TEX_MAX_CHANNELS];
    bool lip_ok = exr_attr_get_string(ctx, 0, TEX_ATTR_LIPSCHITZ, &liplen, &lip) ==
                  EXR_ERR_SUCCESS && lip;
    char *buf = lip_ok ? xstrndup(lip, (size_t)liplen) : NULL;
    if (buf) {
        char *s = buf, *end;
        for (int c = 0; lip_ok && c < 2 * nch; c++) {
            double v = strtod(s, &end);
            lip_ok = end != s && isfinite(v) && v >= 0;
            (c % 2 ? lipt : lips)[c / 2] = v;
            s = end;
        }
        while (lip_ok && *s == ' ')
            s++;
        lip_ok = lip_ok && *s == '\0';
    }
    free(buf);
    if (!buf || !lip_ok) {
        exr_finish(&ctx);
        return refuse(err, errsz, path, "attribute " TEX_ATTR_LIPSCHITZ " (two derivative "
                      "bounds per channel) is missing or malformed");
    }
    static const char *const types[] = { "float", "uint8", "uint16", "uint32" };
    const char *ttype = NULL;
    if (exr_attr_get_string(ctx, 0, TEX_ATTR_TYPE, &typelen, &type) == EXR_ERR_SUCCESS && type)
        for (int q = 0; q < 4; q++)
            if ((size_t)typelen == strlen(types[q]) && memcmp(type, types[q], typelen) == 0)
                ttype = types[q];
    if (!ttype) {
        exr_finish(&ctx);
        return refuse(err, errsz, path, "attribute " TEX_ATTR_TYPE " is missing or not one "
                      "of float, uint8, uint16, uint32");
    }

    tex_texture *t = tex_new_levels(path, ttype, (int)w, (int)h, nch);
    assert(t->nlevels == nlevels);
    memcpy(t->lips, lips, (size_t)nch * sizeof *lips);
    memcpy(t->lipt, lipt, (size_t)nch * sizeof *lipt);
    int resident = nlevels;
    for (int k = 0; k < nlevels; k++) {
        if (resident == nlevels && (size_t)t->lw[k] * (size_t)t->lh[k] <= TEX_RESIDENT_TEXELS)
            resident = k;
    }
    tex_tiled *tl = tex_tiled_new(ctx, pool, t, (int)tw, (int)th, resident);
    t->tiled = tl;
    for (int c = 0; c < nch; c++)
        for (int q = 0; q < nch; q++) {
            char cn[16];
            tex_channel_name(nch, q, cn, sizeof cn);
            if (strcmp(cn, ch->entries[c].name.str) == 0)
                tl->slot[c] = q;
        }
    for (int k = resident; k < nlevels; k++)
        for (int p = 0; p < 3; p++) {
            float *v = k == 0 && p > 0 ? t->avg[0] : read_level(tl, t, p, k);
            if (!v) {
                snprintf(what, sizeof what, "level %d of part \"%s\" cannot be read (damaged "
                         "or truncated file, or non-finite texels)", k, part_names[p]);
                tex_destroy(&t);
                return refuse(err, errsz, path, what);
            }
            (p == 0 ? t->avg : p == 1 ? t->mn : t->mx)[k] = v;
            if (k > 0 || p == 0)
                t->bytes += (size_t)t->lw[k] * (size_t)t->lh[k] * (size_t)nch * sizeof(float);
        }
    if (resident == 0) {             /* all of it in memory: the file is done with */
        tex_tiled_destroy(&t->tiled);
    }
    *out = t;
    return true;
}

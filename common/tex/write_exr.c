/*
 * write_exr.c: a texture as a tiled, mip-mapped OpenEXR file (what
 * aafarm-maketx writes; docs/textures.md "aafarm-maketx"): part "mean"
 * holds the mean pyramid as the file's mip-map levels (round-up sizes,
 * ceil(W / 2^k), the levels aafarm's filter reads), parts "min" and "max"
 * the min-max pyramid with the same levels (their level 0 repeats the
 * image). Channels: Y for one channel, Y A for two, R G B (A) for three
 * (four), c00 c01 ... beyond; 32-bit float, ZIP, 64 x 64 tiles. With
 * the min-max parts, part 0's attributes mark the file as an aafarm
 * texture (layout version, derivative bounds, source type) so that
 * read_tiled.c opens it without rebuilding anything. The file
 * is written under a temporary name and renamed into place, so a failure
 * never leaves a half-written texture.
 */
#include "tex/codec_err.h"
#include "tex/tex_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <openexr.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { TILE = 64 };

void tex_channel_name(int nch, int c, char *out, size_t size)
{
    static const char *const rgba[] = { "R", "G", "B", "A" };
    if (nch == 1)
        snprintf(out, size, "Y");
    else if (nch == 2)
        snprintf(out, size, "%s", c == 0 ? "Y" : "A");
    else if (nch <= 4)
        snprintf(out, size, "%s", rgba[c]);
    else
        snprintf(out, size, "c%02d", c);
}

static exr_result_t define_part(exr_context_t ctx, const char *name, const tex_texture *t)
{
    int part = 0;
    exr_result_t rv = exr_add_part(ctx, name, EXR_STORAGE_TILED, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, t->w, t->h, EXR_COMPRESSION_ZIP);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_set_tile_descriptor(ctx, part, TILE, TILE, EXR_TILE_MIPMAP_LEVELS,
                                     EXR_TILE_ROUND_UP);
    for (int c = 0; rv == EXR_ERR_SUCCESS && c < t->nch; c++) {
        char cn[16];
        tex_channel_name(t->nch, c, cn, sizeof cn);
        rv = exr_add_channel(ctx, part, cn, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    }
    return rv;
}

/* OpenEXRCore 3.1.5's ZIP compressor keeps its zlib output when that is
 * exactly as long as the raw bytes, and readers then take it for the raw
 * bytes (OpenEXR issue 2306, fixed after 3.4): where the output is not
 * shorter, store the raw bytes, as the format says. */
static _Thread_local exr_result_t (*zip_compress)(exr_encode_pipeline_t *);

static exr_result_t compress_or_raw(exr_encode_pipeline_t *enc)
{
    exr_result_t rv = zip_compress(enc);
    if (rv == EXR_ERR_SUCCESS && enc->compressed_bytes >= enc->packed_bytes &&
        enc->compressed_buffer != enc->packed_buffer) {
        memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
        enc->compressed_bytes = enc->packed_bytes;
    }
    return rv;
}

/* Level k of part p (0 mean, 1 min, 2 max), tile by tile: each tile's
 * texels gathered from memory or from the texture's own tiles (a texture
 * read from an aafarm-maketx file) into buf (TILE x TILE x nch). */
static exr_result_t write_level(exr_context_t ctx, int p, const tex_texture *t, int k,
                                float *buf)
{
    int w = t->lw[k], h = t->lh[k];
    exr_result_t rv = EXR_ERR_SUCCESS;
    for (int ty = 0; rv == EXR_ERR_SUCCESS && ty * TILE < h; ty++)
        for (int tx = 0; rv == EXR_ERR_SUCCESS && tx * TILE < w; tx++) {
            int cw = w - tx * TILE < TILE ? w - tx * TILE : TILE;
            int chh = h - ty * TILE < TILE ? h - ty * TILE : TILE;
            for (int j = 0; j < chh; j++)
                for (int i = 0; i < cw; i++)
                    for (int c = 0; c < t->nch; c++)
                        buf[((size_t)j * TILE + i) * t->nch + c] =
                            tex_at(t, p, k, c, tx * TILE + i, ty * TILE + j);
            tex_tiles_unpin();
            exr_chunk_info_t ci;
            rv = exr_write_tile_chunk_info(ctx, p, tx, ty, k, k, &ci);
            if (rv != EXR_ERR_SUCCESS)
                break;
            /* OpenEXRCore 3.1.5 sizes a level's edge tiles by level 0's
             * width and height (a 64 x 64 tile where the level ends after
             * 47 texels), which readers then reject: the tile's real size */
            ci.width = cw;
            ci.height = chh;
            ci.unpacked_size = (uint64_t)cw * (uint64_t)chh * (uint64_t)t->nch * sizeof(float);
            exr_encode_pipeline_t enc;
            memset(&enc, 0, sizeof enc);
            rv = exr_encoding_initialize(ctx, p, &ci, &enc);
            for (int c = 0; rv == EXR_ERR_SUCCESS && c < enc.channel_count; c++) {
                exr_coding_channel_info_t *info = &enc.channels[c];
                int src = 0;
                for (int q = 0; q < t->nch; q++) {
                    char cn[16];
                    tex_channel_name(t->nch, q, cn, sizeof cn);
                    if (strcmp(cn, info->channel_name) == 0)
                        src = q;
                }
                info->encode_from_ptr = (const uint8_t *)(buf + src);
                info->user_pixel_stride = (int32_t)(t->nch * sizeof(float));
                info->user_line_stride = (int32_t)((size_t)TILE * t->nch * sizeof(float));
                info->user_data_type = EXR_PIXEL_FLOAT;
                info->user_bytes_per_element = (int16_t)sizeof(float);
            }
            if (rv == EXR_ERR_SUCCESS)
                rv = exr_encoding_choose_default_routines(ctx, p, &enc);
            if (rv == EXR_ERR_SUCCESS && enc.compress_fn) {
                zip_compress = enc.compress_fn;
                enc.compress_fn = compress_or_raw;
            }
            if (rv == EXR_ERR_SUCCESS)
                rv = exr_encoding_run(ctx, p, &enc);
            exr_encoding_destroy(ctx, &enc);
        }
    return rv;
}

/* Part 0's attributes that make the file an aafarm texture with stored
 * pyramids (read_tiled.c): the layout version, the derivative bounds
 * (exact, as hexadecimal floats) and the type of the source. */
static exr_result_t mark_texture(exr_context_t ctx, const tex_texture *t)
{
    size_t size = (size_t)t->nch * 2 * 32 + 1;
    char *lip = xmalloc(size), *s = lip;
    lip[0] = '\0';
    for (int c = 0; c < t->nch; c++)
        s += snprintf(s, size - (size_t)(s - lip), "%s%a %a", c ? " " : "", t->lips[c],
                      t->lipt[c]);
    exr_result_t rv = exr_attr_set_int(ctx, 0, TEX_ATTR_VERSION, TEX_FILE_VERSION);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_attr_set_string(ctx, 0, TEX_ATTR_LIPSCHITZ, lip);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_attr_set_string(ctx, 0, TEX_ATTR_TYPE, t->type);
    free(lip);
    return rv;
}

bool tex_write_exr(const char *path, const tex_texture *t, bool minmax, char *err, size_t errsz)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = tex_exr_on_error;
    exr_context_t ctx = NULL;
    tex_exr_clear();
    exr_result_t rv = exr_start_write(&ctx, tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = define_part(ctx, "mean", t);
    if (rv == EXR_ERR_SUCCESS && minmax)
        rv = define_part(ctx, "min", t);
    if (rv == EXR_ERR_SUCCESS && minmax)
        rv = define_part(ctx, "max", t);
    if (rv == EXR_ERR_SUCCESS && minmax)
        rv = mark_texture(ctx, t);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctx);
    int32_t levels = 0;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_tile_levels(ctx, 0, &levels, NULL);
    if (rv == EXR_ERR_SUCCESS && levels != t->nlevels) {
        char msg[96];
        snprintf(msg, sizeof msg, "OpenEXR counts %d mip-map levels, the texture %d", levels,
                 t->nlevels);
        tex_exr_note(msg);
        rv = EXR_ERR_INVALID_ARGUMENT;
    }
    float *buf = xmalloc((size_t)TILE * TILE * (size_t)t->nch * sizeof *buf);
    for (int part = 0; rv == EXR_ERR_SUCCESS && part < (minmax ? 3 : 1); part++)
        for (int k = 0; rv == EXR_ERR_SUCCESS && k < t->nlevels; k++)
            rv = write_level(ctx, part, t, k, buf);
    free(buf);
    exr_result_t fin = exr_finish(&ctx);
    if (rv == EXR_ERR_SUCCESS)
        rv = fin;
    if (rv != EXR_ERR_SUCCESS) {
        err_set(err, errsz, "%s: cannot write the texture: %s", path, tex_exr_reason(rv));
        unlink(tmp);
        return false;
    }
    if (rename(tmp, path) != 0) {
        err_set(err, errsz, "%s: cannot put the texture in place: %s", path, strerror(errno));
        unlink(tmp);
        return false;
    }
    return true;
}

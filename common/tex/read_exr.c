/*
 * read_exr.c: OpenEXR textures through OpenEXRCore (the C API of OpenEXR
 * 3): part 0 of a scanline or tiled file, level 0, every channel converted
 * to float (half, float and uint channels; uint values as they are). The
 * channels come R, G, B, A first (by the last part of their names, so
 * "diffuse.R" counts as R) when the file has R, G and B, then the rest in
 * the file's (alphabetical) order; without colour Y first, A last (so
 * aafarm-maketx's "Y A" reads back in order); a single-channel file is
 * channel 0 whatever its name ("Y", "Z", "height").
 */
#include "tex/codec_err.h"
#include "tex/tex_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <openexr.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void fail(char *err, size_t errsz, const char *path, const char *what, exr_result_t rv)
{
    err_set(err, errsz, "%s: %s: %s", path, what, tex_exr_reason(rv));
    tex_exr_clear();
}

/* The order rank of a channel name: R G B A first, then the rest. */
static int rank_of(const char *name)
{
    const char *dot = strrchr(name, '.');
    const char *last = dot ? dot + 1 : name;
    static const char *const first[] = { "R", "G", "B", "A" };
    for (int k = 0; k < 4; k++)
        if (strcmp(last, first[k]) == 0)
            return k;
    return 4;
}

/* Decodes a chunk whose first pixel is (x, y) of the data window (tile
 * chunks give tile indexes in start_x/start_y, scanline chunks rows). */
static exr_result_t decode(exr_context_t ctx, const exr_chunk_info_t *ci, float *data, int w,
                           int x, int y, int nch, const int *slot)
{
    exr_decode_pipeline_t dec;
    memset(&dec, 0, sizeof dec);
    exr_result_t rv = exr_decoding_initialize(ctx, 0, ci, &dec);
    float *base = data + ((size_t)y * (size_t)w + (size_t)x) * (size_t)nch;
    for (int c = 0; rv == EXR_ERR_SUCCESS && c < dec.channel_count; c++) {
        exr_coding_channel_info_t *info = &dec.channels[c];
        info->decode_to_ptr = (uint8_t *)(base + slot[c]);
        info->user_pixel_stride = (int32_t)((size_t)nch * sizeof(float));
        info->user_line_stride = (int32_t)((size_t)w * (size_t)nch * sizeof(float));
        info->user_data_type = EXR_PIXEL_FLOAT;
        info->user_bytes_per_element = (int16_t)sizeof(float);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_decoding_choose_default_routines(ctx, 0, &dec);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_decoding_run(ctx, 0, &dec);
    exr_decoding_destroy(ctx, &dec);
    return rv;
}

bool tex_read_exr(const char *path, tex_pixels *out, char *err, size_t errsz)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = tex_exr_on_error;
    exr_context_t ctx = NULL;
    tex_exr_clear();
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        fail(err, errsz, path, "cannot read the OpenEXR header", rv);
        exr_finish(&ctx);
        return false;
    }
    exr_attr_box2i_t box;
    const exr_attr_chlist_t *ch = NULL;
    exr_storage_t storage;
    bool ok = false;
    float *data = NULL;
    int slot[TEX_MAX_CHANNELS];
    if ((rv = exr_get_data_window(ctx, 0, &box)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_channels(ctx, 0, &ch)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_storage(ctx, 0, &storage)) != EXR_ERR_SUCCESS) {
        fail(err, errsz, path, "cannot read part 0", rv);
        goto done;
    }
    int w = box.max.x - box.min.x + 1, h = box.max.y - box.min.y + 1, nch = ch->num_channels;
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        err_set(err, errsz, "%s: deep OpenEXR images are not textures; write a flat "
                "(scanline or tiled) image", path);
        goto done;
    }
    if (w < 1 || h < 1 || w > TEX_MAX_SIDE || h > TEX_MAX_SIDE || nch < 1 ||
        nch > TEX_MAX_CHANNELS) {
        err_set(err, errsz, "%s: the image is %d x %d with %d channels (a texture has 1 to "
                "%d channels and sides of 1 to %d texels)", path, w, h, nch, TEX_MAX_CHANNELS,
                TEX_MAX_SIDE);
        goto done;
    }
    bool rgb = false;
    for (int c = 0; c < nch; c++) {
        if (ch->entries[c].x_sampling != 1 || ch->entries[c].y_sampling != 1) {
            err_set(err, errsz, "%s: channel '%s' is subsampled; textures need every channel "
                    "at full resolution", path, ch->entries[c].name.str);
            goto done;
        }
        rgb = rgb || rank_of(ch->entries[c].name.str) == 2;
    }
    int n = 0;          /* R G B A first when there is colour, else Y, the rest, A */
    for (int r = 0; r <= 4; r++)
        for (int c = 0; c < nch; c++) {
            const char *cn = ch->entries[c].name.str, *dot = strrchr(cn, '.');
            const char *last = dot ? dot + 1 : cn;
            int k = rgb ? rank_of(cn) : strcmp(last, "Y") == 0 ? 0
                  : strcmp(last, "A") == 0 ? 4 : 1;
            if (k == r)
                slot[c] = n++;
        }
    data = try_calloc((size_t)w * (size_t)h * (size_t)nch, sizeof *data);
    if (!data) {
        err_set(err, errsz, "%s: out of memory for %d x %d x %d texels", path, w, h, nch);
        goto done;
    }
    exr_chunk_info_t ci;
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t per = 1;
        rv = exr_get_scanlines_per_chunk(ctx, 0, &per);
        for (int y = box.min.y; rv == EXR_ERR_SUCCESS && y <= box.max.y; y += per) {
            rv = exr_read_scanline_chunk_info(ctx, 0, y, &ci);
            if (rv == EXR_ERR_SUCCESS)
                rv = decode(ctx, &ci, data, w, 0, ci.start_y - box.min.y, nch, slot);
        }
    } else {
        int32_t tw = 1, th = 1, cx = 0, cy = 0;
        rv = exr_get_tile_sizes(ctx, 0, 0, 0, &tw, &th);
        if (rv == EXR_ERR_SUCCESS && tw > 0 && th > 0) {
            cx = (w + tw - 1) / tw;
            cy = (h + th - 1) / th;
        }
        for (int ty = 0; rv == EXR_ERR_SUCCESS && ty < cy; ty++)
            for (int tx = 0; rv == EXR_ERR_SUCCESS && tx < cx; tx++) {
                rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci);
                if (rv == EXR_ERR_SUCCESS)
                    rv = decode(ctx, &ci, data, w, tx * tw, ty * th, nch, slot);
            }
    }
    if (rv != EXR_ERR_SUCCESS) {
        fail(err, errsz, path, "cannot decode the pixels (truncated or damaged file?)", rv);
        goto done;
    }
    bool any_float = false;
    for (int c = 0; c < nch; c++)
        any_float = any_float || ch->entries[c].pixel_type != EXR_PIXEL_UINT;
    out->data = data;
    out->w = w;
    out->h = h;
    out->nch = nch;
    out->type = any_float ? "float" : "uint32";
    data = NULL;
    ok = true;
done:
    free(data);
    exr_finish(&ctx);
    return ok;
}

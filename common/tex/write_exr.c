/*
 * write_exr.c: a texture as a tiled, mip-mapped OpenEXR file (what
 * aafarm-maketx writes; docs/textures.md "aafarm-maketx"): part "mean"
 * holds the mean pyramid as the file's mip-map levels (round-up sizes,
 * ceil(W / 2^k), the levels aafarm's filter reads), parts "min" and "max"
 * the min-max pyramid with the same levels (their level 0 repeats the
 * image). Channels: Y for one channel, Y A for two, R G B (A) for three
 * (four), c00 c01 ... beyond; 32-bit float, ZIP, 64 x 64 tiles. The file
 * is written under a temporary name and renamed into place, so a failure
 * never leaves a half-written texture.
 */
#include "tex/tex_internal.h"

#include <openexr.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { TILE = 64 };

static _Thread_local char write_message[256];

static void on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    (void)code;
    snprintf(write_message, sizeof write_message, "%s", msg ? msg : "");
}

static void channel_name(int nch, int c, char *out, size_t size)
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
        channel_name(t->nch, c, cn, sizeof cn);
        rv = exr_add_channel(ctx, part, cn, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    }
    return rv;
}

static exr_result_t write_level(exr_context_t ctx, int part, const tex_texture *t, int k,
                                const float *data)
{
    int w = t->lw[k], h = t->lh[k];
    exr_result_t rv = EXR_ERR_SUCCESS;
    for (int ty = 0; rv == EXR_ERR_SUCCESS && ty * TILE < h; ty++)
        for (int tx = 0; rv == EXR_ERR_SUCCESS && tx * TILE < w; tx++) {
            exr_chunk_info_t ci;
            rv = exr_write_tile_chunk_info(ctx, part, tx, ty, k, k, &ci);
            if (rv != EXR_ERR_SUCCESS)
                break;
            exr_encode_pipeline_t enc;
            memset(&enc, 0, sizeof enc);
            rv = exr_encoding_initialize(ctx, part, &ci, &enc);
            for (int c = 0; rv == EXR_ERR_SUCCESS && c < enc.channel_count; c++) {
                exr_coding_channel_info_t *info = &enc.channels[c];
                int src = 0;
                for (int q = 0; q < t->nch; q++) {
                    char cn[16];
                    channel_name(t->nch, q, cn, sizeof cn);
                    if (strcmp(cn, info->channel_name) == 0)
                        src = q;
                }
                const float *base = data + ((size_t)ty * TILE * w + (size_t)tx * TILE) *
                                               t->nch + src;   /* start_x/y: tile indexes */
                info->encode_from_ptr = (const uint8_t *)base;
                info->user_pixel_stride = (int32_t)(t->nch * sizeof(float));
                info->user_line_stride = (int32_t)((size_t)w * t->nch * sizeof(float));
                info->user_data_type = EXR_PIXEL_FLOAT;
                info->user_bytes_per_element = (int16_t)sizeof(float);
            }
            if (rv == EXR_ERR_SUCCESS)
                rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            if (rv == EXR_ERR_SUCCESS)
                rv = exr_encoding_run(ctx, part, &enc);
            exr_encoding_destroy(ctx, &enc);
        }
    return rv;
}

bool tex_write_exr(const char *path, const tex_texture *t, bool minmax, char *err, size_t errsz)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_error;
    exr_context_t ctx = NULL;
    write_message[0] = '\0';
    exr_result_t rv = exr_start_write(&ctx, tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = define_part(ctx, "mean", t);
    if (rv == EXR_ERR_SUCCESS && minmax)
        rv = define_part(ctx, "min", t);
    if (rv == EXR_ERR_SUCCESS && minmax)
        rv = define_part(ctx, "max", t);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctx);
    int32_t levels = 0;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_tile_levels(ctx, 0, &levels, NULL);
    if (rv == EXR_ERR_SUCCESS && levels != t->nlevels) {
        snprintf(write_message, sizeof write_message, "OpenEXR counts %d mip-map levels, the "
                 "texture %d", levels, t->nlevels);
        rv = EXR_ERR_INVALID_ARGUMENT;
    }
    for (int part = 0; rv == EXR_ERR_SUCCESS && part < (minmax ? 3 : 1); part++)
        for (int k = 0; rv == EXR_ERR_SUCCESS && k < t->nlevels; k++)
            rv = write_level(ctx, part, t, k, part == 0 ? t->avg[k] : part == 1 ? t->mn[k]
                                                                               : t->mx[k]);
    exr_result_t fin = exr_finish(&ctx);
    if (rv == EXR_ERR_SUCCESS)
        rv = fin;
    if (rv != EXR_ERR_SUCCESS) {
        snprintf(err, errsz, "%s: cannot write the texture: %s", path,
                 write_message[0] ? write_message : exr_get_default_error_message(rv));
        unlink(tmp);
        return false;
    }
    if (rename(tmp, path) != 0) {
        snprintf(err, errsz, "%s: cannot put the texture in place: %s", path, strerror(errno));
        unlink(tmp);
        return false;
    }
    return true;
}

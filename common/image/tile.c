/*
 * tile.c: image_tile buffers, the one-tile EXR encoder and its validator.
 *
 * Layout of a tile file (OpenEXR file layout, single-part tiled):
 *
 *     magic 76 2f 31 01 | version 2, flags 0x200 (tiled)
 *     header attributes (name\0 type\0 int32 size, data)... \0
 *     chunk offset table: 1 x uint64 (the one tile)
 *     chunk: int32 tile x, tile y, level x, level y (all 0), int32 size,
 *            `size` bytes of ZIP-compressed pixel data
 *
 * Validation pins all of it. Instead of checking header attributes one by
 * one through OpenEXRCore's parser (which would see the untrusted bytes
 * first), it builds the header this code would write for the expected
 * tile and requires the received header to be byte-identical; a small
 * bounds-checked walker over both headers names the first attribute that
 * differs. Only then is OpenEXRCore asked to decode the chunk, into
 * scratch buffers sized from the expected rectangle, which proves the
 * compressed data is intact.
 */
#include "image/tile.h"
#include "util/err.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/exr_io.h"
#include "util/xalloc.h"

/* ---- the tile ---- */

image_tile *image_tile_new(int x0, int y0, int w, int h, unsigned layers)
{
    if (w < 1 || h < 1 || w > IMAGE_MAX_TILE_SIZE || h > IMAGE_MAX_TILE_SIZE
        || (layers & ~(unsigned) IMAGE_LAYERS_ALL) != 0)
        return NULL;
    image_tile *self = xcalloc(1, sizeof *self);
    size_t px = (size_t) w * (size_t) h;
    self->x0 = x0;
    self->y0 = y0;
    self->w = w;
    self->h = h;
    self->layers = layers;
    self->rgba = xcalloc(4 * px, sizeof(float));
    self->z = xcalloc(px, sizeof(float));
    if (layers & IMAGE_LAYER_N)
        self->n = xcalloc(3 * px, sizeof(float));
    if (layers & IMAGE_LAYER_P)
        self->p = xcalloc(3 * px, sizeof(float));
    return self;
}

void image_tile_destroy(image_tile **self_p)
{
    if (!self_p || !*self_p)
        return;
    image_tile *self = *self_p;
    free(self->rgba);
    free(self->z);
    free(self->n);
    free(self->p);
    free(self);
    *self_p = NULL;
}

image_rect image_tile_rect(const image_tile *self)
{
    image_rect r = {self->x0, self->y0, self->w, self->h};
    return r;
}

/* ---- encoding ---- */

static bool tile_fits_format(const image_tile *self, const image_format *fmt,
                             char *err, size_t errsz)
{
    int tx, ty;
    if (!image_format_check(fmt, err, errsz)
        || !image_format_tile_index(fmt, image_tile_rect(self), &tx, &ty,
                                    err, errsz))
        return false;
    if (self->layers != fmt->layers) {
        return err_set(err, errsz, "tile has layers 0x%x but the image has 0x%x",
                       self->layers, fmt->layers);
    }
    if (!self->rgba || !self->z || (fmt->layers & IMAGE_LAYER_N && !self->n)
        || (fmt->layers & IMAGE_LAYER_P && !self->p)) {
        return err_set(err, errsz, "tile at (%d,%d) lacks a buffer for one of its "
                       "layers", self->x0, self->y0);
    }
    return true;
}

static size_t clear_plane(const image_tile *t, float *v, int per_pixel, bool depth, size_t *first)
{
    if (!v) return 0;
    size_t n = 0, count = (size_t)t->w * (size_t)t->h * (size_t)per_pixel;
    for (size_t i = 0; i < count; i++) {
        float x = v[i];
        if (depth ? !(x == x) || x == -INFINITY : !isfinite(x)) {
            v[i] = depth ? INFINITY : 0.0f;
            if (*first > i / (size_t)per_pixel) *first = i / (size_t)per_pixel;
            n++;
        }
    }
    return n;
}

size_t image_tile_clear_nonfinite(image_tile *self, int *first_x, int *first_y)
{
    /* a tile has the buffers of its layers and no others (image_tile_new) */
    assert(self->rgba && self->z);
    assert(!(self->layers & IMAGE_LAYER_N) == !self->n);
    assert(!(self->layers & IMAGE_LAYER_P) == !self->p);
    size_t first = SIZE_MAX;
    size_t n = clear_plane(self, self->rgba, 4, false, &first)
               + clear_plane(self, self->z, 1, true, &first)
               + clear_plane(self, self->n, 3, false, &first)
               + clear_plane(self, self->p, 3, false, &first);
    if (n) {
        *first_x = self->x0 + (int) (first % (size_t) self->w);
        *first_y = self->y0 + (int) (first / (size_t) self->w);
    }
    return n;
}

bool image_tile_encode_exr(const image_tile *self, const image_format *fmt,
                           void **bytes, size_t *len, char *err, size_t errsz)
{
    *bytes = NULL;
    *len = 0;
    if (!tile_fits_format(self, fmt, err, errsz))
        return false;
    image_exr_stream out;
    image_exr_stream_memory_writer(&out);
    exr_context_t ctxt = NULL;
    exr_result_t rv = image_exr_start_write(&ctxt, "tile", &out);
    if (rv == EXR_ERR_SUCCESS)
        rv = image_exr_define_part(ctxt, fmt, image_tile_rect(self));
    if (rv == EXR_ERR_SUCCESS)
        rv = image_exr_write_tile(ctxt, fmt, 0, 0, self);
    exr_result_t fin = ctxt ? exr_finish(&ctxt) : EXR_ERR_SUCCESS;
    if (rv == EXR_ERR_SUCCESS)
        rv = fin;
    if (rv != EXR_ERR_SUCCESS) {
        char what[96];
        snprintf(what, sizeof what, "cannot encode tile at (%d,%d) as EXR",
                 self->x0, self->y0);
        image_exr_error(err, errsz, what, rv, &out);
        image_exr_stream_clear(&out);
        return false;
    }
    *bytes = out.out;
    *len = out.out_len;
    return true;
}

/* ---- reading the header without trusting it ---- */

typedef struct header_attr {
    const char *name;
    const char *type;
    const uint8_t *data;
    uint32_t size;
} header_attr;

static uint32_t read_u32(const uint8_t *p)
{
    return (uint32_t) p[0] | (uint32_t) p[1] << 8 | (uint32_t) p[2] << 16
           | (uint32_t) p[3] << 24;
}

static uint64_t read_u64(const uint8_t *p)
{
    return (uint64_t) read_u32(p) | (uint64_t) read_u32(p + 4) << 32;
}

/* A NUL-terminated string of 1..255 bytes at b[*pos]; NULL if it does not
 * end inside the buffer. */
static const char *read_name(const uint8_t *b, size_t len, size_t *pos)
{
    size_t start = *pos;
    for (size_t i = start; i < len && i - start < 256; i++) {
        if (b[i] == 0) {
            *pos = i + 1;
            return (const char *) b + start;
        }
    }
    return NULL;
}

/* Next header attribute (OpenEXR file layout, "Header"): 1 and *a filled,
 * 0 at the end of the header (*pos past its final NUL), -1 truncated. */
static int next_attr(const uint8_t *b, size_t len, size_t *pos,
                     header_attr *a)
{
    if (*pos >= len)
        return -1;
    if (b[*pos] == 0) {
        (*pos)++;
        return 0;
    }
    a->name = read_name(b, len, pos);
    a->type = a->name ? read_name(b, len, pos) : NULL;
    if (!a->type || len - *pos < 4)
        return -1;
    a->size = read_u32(b + *pos);
    *pos += 4;
    if (a->size > len - *pos)
        return -1;
    a->data = b + *pos;
    *pos += a->size;
    return 1;
}

/* Length of the header (magic to final NUL); 0 if truncated. */
static size_t header_length(const uint8_t *b, size_t len)
{
    size_t pos = 8;
    header_attr a;
    int r;
    while ((r = next_attr(b, len, &pos, &a)) == 1)
        ;
    return r == 0 ? pos : 0;
}

static void describe_box(const header_attr *a, char *buf, size_t n)
{
    const uint8_t *d = a->data;
    snprintf(buf, n, "(%d,%d)-(%d,%d)", (int32_t) read_u32(d),
             (int32_t) read_u32(d + 4), (int32_t) read_u32(d + 8),
             (int32_t) read_u32(d + 12));
}

static void describe_channels(const header_attr *a, char *buf, size_t n)
{
    static const char *types[] = {"uint", "half", "float"};
    size_t pos = 0, used = 0;
    buf[0] = '\0';
    while (pos < a->size && a->data[pos] != 0 && used + 1 < n) {
        const char *name = read_name(a->data, a->size, &pos);
        if (!name || a->size - pos < 16)
            break;
        uint32_t t = read_u32(a->data + pos);
        pos += 16;
        int k = snprintf(buf + used, n - used, "%s%s:%s", used ? " " : "",
                         name, t < 3 ? types[t] : "?");
        if (k < 0)
            break;
        used += (size_t) k;
    }
}

/* "value" of an attribute for messages, for the attributes that matter. */
static void describe_attr(const header_attr *a, char *buf, size_t n)
{
    if (strcmp(a->type, "box2i") == 0 && a->size == 16)
        describe_box(a, buf, n);
    else if (strcmp(a->type, "tiledesc") == 0 && a->size == 9)
        snprintf(buf, n, "%ux%u level mode %u", read_u32(a->data),
                 read_u32(a->data + 4), a->data[8] & 0xfu);
    else if (strcmp(a->type, "compression") == 0 && a->size == 1)
        snprintf(buf, n, "%u (ZIP is %d)", a->data[0], EXR_COMPRESSION_ZIP);
    else if (strcmp(a->type, "chlist") == 0)
        describe_channels(a, buf, n);
    else
        snprintf(buf, n, "%u bytes of type %s", a->size, a->type);
}

static bool attrs_equal(const header_attr *a, const header_attr *b)
{
    return strcmp(a->name, b->name) == 0 && strcmp(a->type, b->type) == 0
           && a->size == b->size && memcmp(a->data, b->data, a->size) == 0;
}

/* Names the first difference between the received header `got` and the
 * expected one (both known to be complete). */
static void explain_header(const uint8_t *got, size_t got_len,
                           const uint8_t *want, size_t want_len,
                           char *err, size_t errsz)
{
    size_t gp = 8, wp = 8;
    header_attr ga, wa;
    for (;;) {
        int gr = next_attr(got, got_len, &gp, &ga);
        int wr = next_attr(want, want_len, &wp, &wa);
        if (gr != 1 && wr != 1)
            break;
        if (gr != 1) {
            err_set(err, errsz, "header lacks attribute '%s'", wa.name);
            return;
        }
        if (wr != 1 || strcmp(ga.name, wa.name) != 0) {
            err_set(err, errsz, "header has unexpected attribute '%s'",
                    ga.name);
            return;
        }
        if (!attrs_equal(&ga, &wa)) {
            char g[160], w[160];
            describe_attr(&ga, g, sizeof g);
            describe_attr(&wa, w, sizeof w);
            err_set(err, errsz, "header attribute '%s' is %s, expected %s",
                    ga.name, g, w);
            return;
        }
    }
    err_set(err, errsz, "header differs from the one aafarm writes");
}

/* ---- validation ---- */

static const uint8_t exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};

static bool check_preamble(const uint8_t *b, size_t len, const uint8_t *want,
                           char *err, size_t errsz)
{
    if (len < 4) {
        return err_set(err, errsz, "truncated: %zu bytes cannot hold an EXR magic "
                       "number", len);
    }
    if (memcmp(b, exr_magic, 4) != 0) {
        return err_set(err, errsz, "not an OpenEXR file (bad magic number)");
    }
    if (len < 8) {
        return err_set(err, errsz, "truncated: %zu bytes, the EXR version field "
                       "is missing", len);
    }
    if (memcmp(b + 4, want + 4, 4) != 0) {
        return err_set(err, errsz, "EXR version/flags 0x%08x, expected 0x%08x "
                       "(version 2, single-part tiled)", read_u32(b + 4),
                       read_u32(want + 4));
    }
    return true;
}

static bool check_header(const uint8_t *b, size_t len, const uint8_t *want,
                         size_t want_len, size_t *hlen, char *err,
                         size_t errsz)
{
    size_t want_hlen = header_length(want, want_len);
    *hlen = header_length(b, len);
    if (*hlen == 0) {
        return err_set(err, errsz, "truncated: the EXR header does not end within "
                       "the %zu bytes received", len);
    }
    if (*hlen != want_hlen || memcmp(b, want, want_hlen) != 0) {
        explain_header(b, len, want, want_len, err, errsz);
        return false;
    }
    return true;
}

/* Offset table and chunk leader: exactly one chunk, for tile (0,0) level
 * (0,0), right after the table, filling the rest of the bytes. */
static bool check_chunk_frame(const uint8_t *b, size_t len, size_t hlen,
                              size_t unpacked, size_t *data_len, char *err,
                              size_t errsz)
{
    if (len - hlen < 8 + 20) {
        return err_set(err, errsz, "truncated: %zu bytes end before the chunk "
                       "offset table and chunk header", len);
    }
    uint64_t offset = read_u64(b + hlen);
    if (offset != hlen + 8) {
        return err_set(err, errsz, "chunk offset table points at byte %llu, "
                       "expected %zu", (unsigned long long) offset, hlen + 8);
    }
    const uint8_t *leader = b + hlen + 8;
    int32_t tx = (int32_t) read_u32(leader), ty = (int32_t) read_u32(leader + 4);
    int32_t lx = (int32_t) read_u32(leader + 8),
            ly = (int32_t) read_u32(leader + 12);
    if (tx != 0 || ty != 0 || lx != 0 || ly != 0) {
        return err_set(err, errsz, "chunk is for tile (%d,%d) level (%d,%d), "
                       "expected tile (0,0) level (0,0)", tx, ty, lx, ly);
    }
    uint32_t size = read_u32(leader + 16);
    size_t rest = len - hlen - 8 - 20;
    if (size != rest || size == 0) {
        return err_set(err, errsz, "chunk data is %u bytes but %zu bytes follow "
                       "its header (truncated or trailing bytes)", size, rest);
    }
    if (size > unpacked) {
        return err_set(err, errsz, "chunk data of %u bytes is larger than the "
                       "uncompressed tile (%zu bytes)", size, unpacked);
    }
    *data_len = size;
    return true;
}

/* The chunk must decompress to exactly the tile's unpacked size (zlib's
 * own checks catch a damaged stream). The samples are not converted to
 * float: any bit pattern is a valid half or float, so converting would
 * find nothing more, and it cost a w x h x channels float buffer. */
static bool check_decodes(const uint8_t *b, size_t len,
                          const image_format *fmt, image_rect r,
                          size_t packed, char *err, size_t errsz)
{
    size_t px = (size_t) r.w * (size_t) r.h;
    float *const none[IMAGE_MAX_CHANNELS] = {NULL};
    image_exr_stream in;
    image_exr_stream_memory_reader(&in, b, len);
    exr_context_t ctxt = NULL;
    exr_chunk_info_t ci;
    exr_result_t rv = image_exr_start_read(&ctxt, "tile", &in);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_read_tile_chunk_info(ctxt, 0, 0, 0, 0, 0, &ci);
    if (rv == EXR_ERR_SUCCESS
        && (ci.width != r.w || ci.height != r.h || ci.packed_size != packed
            || ci.unpacked_size != px * image_format_pixel_bytes(fmt)))
        rv = EXR_ERR_CORRUPT_CHUNK;
    if (rv == EXR_ERR_SUCCESS)
        rv = image_exr_decode_chunk(ctxt, &ci, none, (size_t) r.w);
    if (ctxt)
        exr_finish(&ctxt);
    if (rv != EXR_ERR_SUCCESS)
        image_exr_error(err, errsz, "tile chunk does not decode", rv, &in);
    return rv == EXR_ERR_SUCCESS;
}

/* The header this code writes for rectangle r (written by OpenEXRCore
 * into memory, the context then abandoned: no pixels are encoded, which
 * used to cost as much as the decoding). Only the header bytes are used. */
static bool expected_file(const image_format *fmt, image_rect r, void **bytes,
                          size_t *len, char *err, size_t errsz)
{
    image_exr_stream out;
    image_exr_stream_memory_writer(&out);
    exr_context_t ctxt = NULL;
    exr_result_t rv = image_exr_start_write(&ctxt, "tile", &out);
    if (rv == EXR_ERR_SUCCESS)
        rv = image_exr_define_part(ctxt, fmt, r);
    if (ctxt) {
        out.discard = true;   /* nothing more: the header is in out */
        exr_finish(&ctxt);
    }
    if (rv != EXR_ERR_SUCCESS || header_length(out.out, out.out_len) == 0) {
        image_exr_error(err, errsz, "cannot make the expected tile header", rv,
                        &out);
        image_exr_stream_clear(&out);
        return false;
    }
    *bytes = out.out;
    *len = out.out_len;
    return true;
}

bool image_tile_exr_chunk(const void *bytes, size_t len,
                          const image_format *fmt, image_rect expect,
                          const void **chunk, size_t *chunk_len,
                          char *err, size_t errsz)
{
    int tx, ty;
    if (!image_format_check(fmt, err, errsz)
        || !image_format_tile_index(fmt, expect, &tx, &ty, err, errsz))
        return false;
    if (!bytes && len > 0) {
        return err_set(err, errsz, "no tile bytes given");
    }
    const uint8_t *b = bytes;
    void *want = NULL;
    size_t want_len = 0, hlen = 0, data_len = 0;
    size_t unpacked = (size_t) expect.w * (size_t) expect.h
                      * image_format_pixel_bytes(fmt);
    bool ok = expected_file(fmt, expect, &want, &want_len, err, errsz)
              && check_preamble(b, len, want, err, errsz)
              && check_header(b, len, want, want_len, &hlen, err, errsz)
              && check_chunk_frame(b, len, hlen, unpacked, &data_len, err,
                                   errsz)
              && check_decodes(b, len, fmt, expect, data_len, err, errsz);
    free(want);
    /* the chunk is the file's tail, after header, offset table and leader */
    assert(!ok || hlen + 8 + 20 + data_len == len);
    if (ok && chunk) {
        *chunk = b + hlen + 8 + 20;
        *chunk_len = data_len;
    }
    return ok;
}

bool image_tile_encode_chunk(const image_tile *self, const image_format *fmt,
                             void **bytes, size_t *len, const void **chunk,
                             size_t *chunk_len, char *err, size_t errsz)
{
    if (!image_tile_encode_exr(self, fmt, bytes, len, err, errsz))
        return false;
    /* our own encoder's one-tile file: header, the offset table's one
     * entry (8 bytes), the chunk's leader (tile and level: 16 bytes, data
     * size: 4), the data */
    const uint8_t *b = *bytes;
    size_t hlen = header_length(b, *len);
    assert(hlen > 0 && hlen + 8 + 20 <= *len);
    assert(read_u64(b + hlen) == hlen + 8);
    uint32_t size = read_u32(b + hlen + 8 + 16);
    assert(hlen + 8 + 20 + size == *len);
    *chunk = b + hlen + 8 + 20;
    *chunk_len = size;
    return true;
}

bool image_tile_validate_exr(const void *bytes, size_t len,
                             const image_format *fmt, image_rect expect,
                             char *err, size_t errsz)
{
    return image_tile_exr_chunk(bytes, len, fmt, expect, NULL, NULL, err,
                                errsz);
}

/* ---- decoding a chunk (the master's live image) ---- */

static void put_le(uint8_t *p, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++)
        p[i] = (uint8_t) (v >> (8 * i));
}

bool image_tile_decode_rgba(const image_format *fmt, image_rect r,
                            const void *chunk, size_t chunk_len, float *rgba,
                            char *err, size_t errsz)
{
    int tx, ty;
    if (!image_format_check(fmt, err, errsz)
        || !image_format_tile_index(fmt, r, &tx, &ty, err, errsz))
        return false;
    if (!chunk || chunk_len == 0 || chunk_len > UINT32_MAX)
        return err_set(err, errsz, "no tile chunk to decode");
    void *want = NULL;
    size_t want_len = 0;
    if (!expected_file(fmt, r, &want, &want_len, err, errsz))
        return false;
    /* the one-tile file around the chunk: header, offset table, leader */
    size_t hlen = header_length(want, want_len);
    size_t len = hlen + 8 + 20 + chunk_len;
    uint8_t *file = xmalloc(len);
    memcpy(file, want, hlen);
    free(want);
    put_le(file + hlen, hlen + 8, 8);
    memset(file + hlen + 8, 0, 16);                 /* tile (0,0) level (0,0) */
    put_le(file + hlen + 8 + 16, chunk_len, 4);
    memcpy(file + hlen + 8 + 20, chunk, chunk_len);
    size_t px = (size_t) r.w * (size_t) r.h;
    float *planes = xcalloc(4 * px, sizeof(float));   /* R G B A */
    float *dst[IMAGE_MAX_CHANNELS] = {NULL};
    int nch = image_format_channel_count(fmt);
    for (int c = 0; c < nch; c++) {
        const image_channel *ch = image_format_channel(fmt, c);
        if (ch->source == IMAGE_SOURCE_RGBA)
            dst[c] = planes + (size_t) ch->component * px;
    }
    image_exr_stream in;
    image_exr_stream_memory_reader(&in, file, len);
    exr_context_t ctxt = NULL;
    exr_chunk_info_t ci;
    exr_result_t rv = image_exr_start_read(&ctxt, "tile", &in);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_read_tile_chunk_info(ctxt, 0, 0, 0, 0, 0, &ci);
    if (rv == EXR_ERR_SUCCESS && (ci.width != r.w || ci.height != r.h))
        rv = EXR_ERR_CORRUPT_CHUNK;
    if (rv == EXR_ERR_SUCCESS)
        rv = image_exr_decode_chunk(ctxt, &ci, dst, (size_t) r.w);
    if (ctxt)
        exr_finish(&ctxt);
    if (rv != EXR_ERR_SUCCESS)
        image_exr_error(err, errsz, "tile chunk does not decode", rv, &in);
    else
        for (size_t i = 0; i < px; i++)
            for (int c = 0; c < 4; c++)
                rgba[4 * i + (size_t) c] = planes[(size_t) c * px + i];
    free(planes);
    free(file);
    return rv == EXR_ERR_SUCCESS;
}

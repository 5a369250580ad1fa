/*
 * tests/tex/test_tex_read.c: the image readers of common/tex. Each case
 * writes a small file with libpng or libtiff (random texels of a known
 * depth), opens it with tex_open and compares every texel with the value
 * written over 2^bits - 1 (floats as written); OpenEXR files written by
 * tex_write_exr (tiled, mip-mapped, 1 to 5 channels, odd sizes) and by
 * OpenEXRCore here (scanline, half, channels B G R Z read as R G B Z)
 * read back exactly; then broken inputs: a
 * missing file, a file of another format, a truncated PNG, an unsupported
 * TIFF sample format: NULL and a message naming the file; a PNG that
 * claims 10^6 x 10^6 texels read in a child process with little address
 * space left: NULL and "out of memory", not an abort (tex.h "Memory").
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <openexr.h>
#include <png.h>
#include <tiffio.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "death.h"
#include "tex/tex.h"

static char dir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/test_tex_read.XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static uint32_t rng = 12345;
static uint32_t next(void)
{
    rng = rng * 1664525u + 1013904223u;
    return rng >> 8;
}

static void write_png(const char *path, int w, int h, int nch, int bits, uint16_t *vals)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    int type = nch == 1 ? PNG_COLOR_TYPE_GRAY : nch == 2 ? PNG_COLOR_TYPE_GRAY_ALPHA
             : nch == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA;
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, bits, type, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_bytep row = malloc((size_t)w * nch * 2);
    for (int y = 0; y < h; y++) {
        for (int k = 0; k < w * nch; k++) {
            uint16_t v = vals[y * w * nch + k];
            if (bits == 16) {
                row[2 * k] = (png_byte)(v >> 8);
                row[2 * k + 1] = (png_byte)(v & 255);
            } else {
                row[k] = (png_byte)v;
            }
        }
        png_write_row(png, row);
    }
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    free(row);
    fclose(f);
}

static void test_png(void **state)
{
    (void)state;
    static const int cases[][2] = { { 1, 8 }, { 3, 16 }, { 4, 8 }, { 2, 16 } };
    for (size_t n = 0; n < sizeof cases / sizeof cases[0]; n++) {
        int nch = cases[n][0], bits = cases[n][1], w = 5, h = 3;
        uint16_t vals[5 * 3 * 4];
        for (int k = 0; k < w * h * nch; k++)
            vals[k] = (uint16_t)(next() % (bits == 16 ? 65536 : 256));
        char path[300], err[512];
        snprintf(path, sizeof path, "%s/t%zu.png", dir, n);
        write_png(path, w, h, nch, bits, vals);
        tex_texture *t = tex_open(path, err, sizeof err);
        if (!t)
            fail_msg("%s", err);
        assert_int_equal(tex_width(t), w);
        assert_int_equal(tex_height(t), h);
        assert_int_equal(tex_channels(t), nch);
        assert_string_equal(tex_type(t), bits == 16 ? "uint16" : "uint8");
        double scale = bits == 16 ? 65535.0 : 255.0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                for (int c = 0; c < nch; c++)
                    assert_float_equal(tex_texel(t, 0, c, x, y),
                                       vals[(y * w + x) * nch + c] / scale, 1e-7);
        tex_destroy(&t);
    }
}

static void write_tiff(const char *path, int w, int h, int nch, int bits, int format,
                       bool tiled, const double *vals)
{
    TIFF *tif = TIFFOpen(path, "w");
    assert_non_null(tif);
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, (uint32_t)w);
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, (uint32_t)h);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, (uint16_t)nch);
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, (uint16_t)bits);
    TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, (uint16_t)format);
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, nch >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
    int bps = bits / 8;
    unsigned char *buf;
    if (tiled) {
        TIFFSetField(tif, TIFFTAG_TILEWIDTH, 16u);
        TIFFSetField(tif, TIFFTAG_TILELENGTH, 16u);
        buf = calloc(16 * 16 * (size_t)nch, (size_t)bps);
    } else {
        TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, 2u);
        buf = calloc((size_t)w * nch, (size_t)bps);
    }
    for (int y0 = 0; y0 < h; y0 += tiled ? 16 : 1)
        for (int x0 = 0; x0 < w; x0 += tiled ? 16 : w) {
            int tw = tiled ? 16 : w, th = tiled ? 16 : 1;
            for (int y = y0; y < y0 + th && y < h; y++)
                for (int x = x0; x < x0 + tw && x < w; x++)
                    for (int c = 0; c < nch; c++) {
                        double v = vals[(y * w + x) * nch + c];
                        size_t k = ((size_t)(y - y0) * tw + (x - x0)) * nch + c;
                        if (format == SAMPLEFORMAT_IEEEFP) {
                            float f = (float)v;
                            memcpy(buf + 4 * k, &f, 4);
                        } else if (bits == 8) {
                            buf[k] = (unsigned char)v;
                        } else if (bits == 16) {
                            uint16_t u = (uint16_t)v;
                            memcpy(buf + 2 * k, &u, 2);
                        } else {
                            uint32_t u = (uint32_t)v;
                            memcpy(buf + 4 * k, &u, 4);
                        }
                    }
            if (tiled)
                assert_true(TIFFWriteTile(tif, buf, (uint32_t)x0, (uint32_t)y0, 0, 0) > 0);
            else
                assert_true(TIFFWriteScanline(tif, buf, (uint32_t)y0, 0) == 1);
        }
    free(buf);
    TIFFClose(tif);
}

static void test_tiff(void **state)
{
    (void)state;
    static const int cases[][4] = {     /* nch, bits, format, tiled */
        { 1, 8, SAMPLEFORMAT_UINT, 0 }, { 3, 16, SAMPLEFORMAT_UINT, 0 },
        { 1, 32, SAMPLEFORMAT_UINT, 0 }, { 1, 32, SAMPLEFORMAT_IEEEFP, 0 },
        { 4, 32, SAMPLEFORMAT_IEEEFP, 1 }, { 1, 16, SAMPLEFORMAT_UINT, 1 },
    };
    for (size_t n = 0; n < sizeof cases / sizeof cases[0]; n++) {
        int nch = cases[n][0], bits = cases[n][1], format = cases[n][2], w = 21, h = 18;
        double *vals = malloc((size_t)w * h * nch * sizeof *vals);
        double top = bits == 8 ? 255 : bits == 16 ? 65535 : 4294967295.0;
        for (int k = 0; k < w * h * nch; k++)
            vals[k] = format == SAMPLEFORMAT_IEEEFP ? (double)(float)((next() % 20000) / 1000.0 - 7)
                                                    : floor((next() / 16777216.0) * top);
        char path[300], err[512];
        snprintf(path, sizeof path, "%s/t%zu.tif", dir, n);
        write_tiff(path, w, h, nch, bits, format, cases[n][3], vals);
        tex_texture *t = tex_open(path, err, sizeof err);
        if (!t)
            fail_msg("%s", err);
        assert_int_equal(tex_width(t), w);
        assert_int_equal(tex_height(t), h);
        assert_int_equal(tex_channels(t), nch);
        for (int k = 0; k < w * h * nch; k++) {
            double want = format == SAMPLEFORMAT_IEEEFP ? vals[k] : vals[k] / top;
            double got = tex_texel(t, 0, k % nch, (k / nch) % w, k / nch / w);
            if (fabs(got - want) > 1e-6 * (1 + fabs(want)))
                fail_msg("case %zu texel %d: %g, wrote %g", n, k, got, want);
        }
        tex_destroy(&t);
        free(vals);
    }
}

/* tex_write_exr (tiled, mip-mapped, three parts) read back by tex_open */
static void test_exr_roundtrip(void **state)
{
    (void)state;
    static const int cases[][3] = { { 1, 1, 1 }, { 70, 65, 1 }, { 33, 129, 3 }, { 64, 64, 4 },
                                    { 9, 5, 5 }, { 130, 3, 2 } };
    for (size_t n = 0; n < sizeof cases / sizeof cases[0]; n++) {
        int w = cases[n][0], h = cases[n][1], nch = cases[n][2];
        float *px = malloc((size_t)w * h * nch * sizeof *px);
        for (int k = 0; k < w * h * nch; k++)
            px[k] = (float)((int)(next() % 100000) - 50000) / 977.0f;
        tex_texture *t = tex_from_pixels(px, w, h, nch, "mem");
        char path[300], err[512];
        snprintf(path, sizeof path, "%s/rt%zu.exr", dir, n);
        if (!tex_write_exr(path, t, n % 2 == 0, err, sizeof err))
            fail_msg("%s", err);
        tex_texture *u = tex_open(path, err, sizeof err);
        if (!u)
            fail_msg("%s", err);
        assert_int_equal(tex_width(u), w);
        assert_int_equal(tex_height(u), h);
        assert_int_equal(tex_channels(u), nch);
        assert_int_equal(tex_levels(u), tex_levels(t));
        assert_string_equal(tex_type(u), "float");
        for (int k = 0; k < w * h * nch; k++)
            assert_true(tex_texel(u, 0, k % nch, (k / nch) % w, k / nch / w) == px[k]);
        tex_destroy(&u);
        tex_destroy(&t);
        free(px);
    }
}

/* a scanline OpenEXR file of half channels named B, G, R, Z (stored in
 * that order): read as R, G, B, then Z, rounded to half */
static void test_exr_half_scanline(void **state)
{
    (void)state;
    char path[300], err[512];
    snprintf(path, sizeof path, "%s/half.exr", dir);
    int w = 19, h = 23;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx;
    assert_int_equal(exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init), 0);
    int part;
    assert_int_equal(exr_add_part(ctx, "img", EXR_STORAGE_SCANLINE, &part), 0);
    assert_int_equal(exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP),
                     0);
    const char *names[4] = { "B", "G", "R", "Z" };
    for (int c = 0; c < 4; c++)
        assert_int_equal(exr_add_channel(ctx, part, names[c], EXR_PIXEL_HALF,
                                         EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), 0);
    assert_int_equal(exr_write_header(ctx), 0);
    float *px = malloc((size_t)w * h * 4 * sizeof *px);    /* B G R Z per pixel */
    for (int k = 0; k < w * h * 4; k++)
        px[k] = (float)(next() % 2048) / 256.0f;             /* exact in half */
    int32_t per = 1;
    exr_get_scanlines_per_chunk(ctx, part, &per);
    for (int y = 0; y < h; y += per) {
        exr_chunk_info_t ci;
        assert_int_equal(exr_write_scanline_chunk_info(ctx, part, y, &ci), 0);
        exr_encode_pipeline_t enc;
        memset(&enc, 0, sizeof enc);
        assert_int_equal(exr_encoding_initialize(ctx, part, &ci, &enc), 0);
        for (int c = 0; c < enc.channel_count; c++) {
            int src = 0;
            for (int q = 0; q < 4; q++)
                if (strcmp(names[q], enc.channels[c].channel_name) == 0)
                    src = q;
            enc.channels[c].encode_from_ptr = (const uint8_t *)(px + (size_t)y * w * 4 + src);
            enc.channels[c].user_pixel_stride = 4 * sizeof(float);
            enc.channels[c].user_line_stride = w * 4 * sizeof(float);
            enc.channels[c].user_data_type = EXR_PIXEL_FLOAT;
            enc.channels[c].user_bytes_per_element = sizeof(float);
        }
        assert_int_equal(exr_encoding_choose_default_routines(ctx, part, &enc), 0);
        assert_int_equal(exr_encoding_run(ctx, part, &enc), 0);
        exr_encoding_destroy(ctx, &enc);
    }
    assert_int_equal(exr_finish(&ctx), 0);
    tex_texture *t = tex_open(path, err, sizeof err);
    if (!t)
        fail_msg("%s", err);
    assert_int_equal(tex_channels(t), 4);
    static const int from[4] = { 2, 1, 0, 3 };       /* R G B Z <- B G R Z */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 4; c++)
                assert_true(tex_texel(t, 0, c, x, y) == px[((size_t)y * w + x) * 4 + from[c]]);
    tex_destroy(&t);
    free(px);
}

static void expect_error(const char *path, const char *words)
{
    char err[512] = "";
    tex_texture *t = tex_open(path, err, sizeof err);
    assert_null(t);
    if (!strstr(err, path) || !strstr(err, words))
        fail_msg("message for %s: '%s' (wanted the path and '%s')", path, err, words);
}

static void test_errors(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/missing.exr", dir);
    expect_error(path, "cannot open");
    snprintf(path, sizeof path, "%s/text.png", dir);
    FILE *f = fopen(path, "w");
    fputs("this is not an image at all\n", f);
    fclose(f);
    expect_error(path, "not an OpenEXR, PNG or TIFF file");
    uint16_t vals[64 * 64];
    for (int k = 0; k < 64 * 64; k++)
        vals[k] = (uint16_t)(next() % 256);
    snprintf(path, sizeof path, "%s/cut.png", dir);
    write_png(path, 64, 64, 1, 8, vals);
    assert_int_equal(truncate(path, 200), 0);
    expect_error(path, "not a readable PNG");
    snprintf(path, sizeof path, "%s/signed.tif", dir);
    double dv[4] = { 1, 2, 3, 4 };
    write_tiff(path, 2, 2, 1, 16, SAMPLEFORMAT_INT, false, dv);
    expect_error(path, "not supported");
}

/* Under AddressSanitizer an allocation that fails returns NULL as malloc
 * does, instead of ending the process (the path test_out_of_memory takes). */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

/* PNG's CRC-32 (ISO 3309) of n bytes. */
static uint32_t png_crc(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xffffffffu;
}

static void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

/* A PNG of w x h grey 8-bit texels cut in its first IDAT: the header the
 * reader sizes its buffers by, and the start of its pixels. */
static void write_png_start(const char *path, uint32_t w, uint32_t h)
{
    uint8_t b[8 + 25 + 12 + 4];
    memcpy(b, "\x89PNG\r\n\x1a\n", 8);
    uint8_t *ihdr = b + 8;              /* length, type, 13 bytes, CRC */
    put_be32(ihdr, 13);
    memcpy(ihdr + 4, "IHDR", 4);
    put_be32(ihdr + 8, w);
    put_be32(ihdr + 12, h);
    memcpy(ihdr + 16, "\x08\x00\x00\x00\x00", 5);   /* 8 bits, grey, no interlace */
    put_be32(ihdr + 21, png_crc(ihdr + 4, 17));
    uint8_t *idat = ihdr + 25;          /* 4 bytes of zlib stream, CRC */
    put_be32(idat, 4);
    memcpy(idat + 4, "IDAT\x78\x9c\x00\x00", 8);
    put_be32(idat + 12, png_crc(idat + 4, 8));
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, sizeof b, f), sizeof b);
    fclose(f);
}

static int open_huge(void *arg)
{
    const char *path = arg;
    char err[512] = "";
    tex_texture *t = tex_open(path, err, sizeof err);
    fprintf(stderr, "child: %s\n", t ? "opened the texture" : err);
    return t ? 1 : strstr(err, path) && strstr(err, "out of memory") ? 0 : 2;
}

/* In a child with 256 MiB more address space than it has: a PNG that
 * states 10^6 x 10^6 pixels is refused with a message, not an abort. */
static void test_out_of_memory(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/huge.png", dir);
    write_png_start(path, 1000000, 1000000);
    assert_starved_ok(open_huge, path, 256ul << 20);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_png),
        cmocka_unit_test(test_tiff),
        cmocka_unit_test(test_exr_roundtrip),
        cmocka_unit_test(test_exr_half_scanline),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_out_of_memory),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

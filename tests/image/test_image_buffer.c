/*
 * tests/image/test_image_buffer.c: reading EXR files into float planes and
 * comparing images (common/image/buffer.h).
 *
 *   scanline file   a scanline ZIP file written here with OpenEXRCore
 *                   directly (data window not at the origin, FLOAT, HALF
 *                   and UINT channels, chunks of 16 lines, a short last
 *                   chunk) reads back to the values written
 *   read errors     missing file, not an EXR, every truncation of a real
 *                   output file: NULL with a message naming the file
 *   out of memory   a file whose header asks for more memory than the
 *                   process may have (a child under RLIMIT_AS) is refused
 *                   with a message, not an abort (buffer.h "Memory")
 *   compare         equal images; one changed sample found with its
 *                   channel, pixel and size; NaN equals NaN, NaN vs number
 *                   is infinite; tolerance; layouts that differ refused
 */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/buffer.h"
#include "image/writer.h"
#include "death.h"
#include "image_testutil.h"

static char err[512];

enum { SW = 13, SH = 37, SX0 = 5, SY0 = -3 };

static float value_y(int x, int y) { return (float) x * 0.37f - (float) y * 1.1f; }
static float value_h(int x, int y) { return (float) (x + y) / 3.0f; }
static uint32_t value_u(int x, int y) { return (uint32_t) (x * 1000 + y + 100); }

static exr_result_t encode_chunk(exr_context_t ctxt, int y, const float *fy,
                                 const float *fh, const uint32_t *fu)
{
    exr_chunk_info_t ci;
    exr_encode_pipeline_t enc;
    memset(&enc, 0, sizeof enc);
    exr_result_t rv = exr_write_scanline_chunk_info(ctxt, 0, y, &ci);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_encoding_initialize(ctxt, 0, &ci, &enc);
    size_t row0 = (size_t) (ci.start_y - SY0) * SW;
    for (int c = 0; rv == EXR_ERR_SUCCESS && c < enc.channel_count; c++) {
        exr_coding_channel_info_t *ch = &enc.channels[c];
        const char *n = ch->channel_name;
        bool is_u = strcmp(n, "u") == 0;
        ch->encode_from_ptr = is_u ? (const uint8_t *) (fu + row0)
                              : (const uint8_t *) ((strcmp(n, "Y") ? fh : fy)
                                                   + row0);
        ch->user_pixel_stride = 4;
        ch->user_line_stride = 4 * SW;
        ch->user_data_type = (uint16_t) (is_u ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT);
        ch->user_bytes_per_element = 4;
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_encoding_choose_default_routines(ctxt, 0, &enc);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_encoding_run(ctxt, 0, &enc);
    exr_encoding_destroy(ctxt, &enc);
    return rv;
}

static void write_scanline_file(const char *path)
{
    static float fy[SW * SH], fh[SW * SH];
    static uint32_t fu[SW * SH];
    for (int y = 0; y < SH; y++)
        for (int x = 0; x < SW; x++) {
            fy[y * SW + x] = value_y(x, y);
            fh[y * SW + x] = value_h(x, y);
            fu[y * SW + x] = value_u(x, y);
        }
    exr_context_t ctxt;
    int part;
    exr_attr_box2i_t dw;
    dw.min.x = SX0;
    dw.min.y = SY0;
    dw.max.x = SX0 + SW - 1;
    dw.max.y = SY0 + SH - 1;
    exr_attr_v2f_t center;
    center.x = center.y = 0.0f;
    assert_int_equal(exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, NULL),
                     EXR_ERR_SUCCESS);
    assert_int_equal(exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part), 0);
    assert_int_equal(exr_initialize_required_attr(ctxt, part, &dw, &dw, 1.0f,
                                                  &center, 1.0f,
                                                  EXR_LINEORDER_INCREASING_Y,
                                                  EXR_COMPRESSION_ZIP), 0);
    assert_int_equal(exr_add_channel(ctxt, part, "Y", EXR_PIXEL_FLOAT,
                                     EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), 0);
    assert_int_equal(exr_add_channel(ctxt, part, "h", EXR_PIXEL_HALF,
                                     EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), 0);
    assert_int_equal(exr_add_channel(ctxt, part, "u", EXR_PIXEL_UINT,
                                     EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1), 0);
    assert_int_equal(exr_write_header(ctxt), 0);
    for (int y = SY0; y < SY0 + SH; y += 16)
        assert_int_equal(encode_chunk(ctxt, y, fy, fh, fu), EXR_ERR_SUCCESS);
    assert_int_equal(exr_finish(&ctxt), EXR_ERR_SUCCESS);
}

static void test_scanline_file(void **state)
{
    const char *path = tu_path(*state, "scan.exr");
    write_scanline_file(path);
    image_buffer *img = image_buffer_read_exr(path, err, sizeof err);
    if (!img)
        fail_msg("%s", err);
    assert_int_equal(img->x0, SX0);
    assert_int_equal(img->y0, SY0);
    assert_int_equal(img->width, SW);
    assert_int_equal(img->height, SH);
    assert_int_equal(img->channel_count, 3);
    assert_string_equal(img->names[0], "Y");
    assert_string_equal(img->names[1], "h");
    assert_string_equal(img->names[2], "u");
    const float *y_ = image_buffer_channel(img, "Y");
    const float *h_ = image_buffer_channel(img, "h");
    const float *u_ = image_buffer_channel(img, "u");
    assert_null(image_buffer_channel(img, "R"));
    for (int y = 0; y < SH; y++) {
        for (int x = 0; x < SW; x++) {
            int i = y * SW + x;
            assert_true(y_[i] == value_y(x, y));
            assert_true(h_[i] == tu_half_round(value_h(x, y)));
            assert_true(u_[i] == (float) value_u(x, y));
        }
    }
    image_buffer_destroy(&img);
}

static void test_read_errors(void **state)
{
    const char *dir = *state;
    const char *missing = tu_path(dir, "missing.exr");
    assert_null(image_buffer_read_exr(missing, err, sizeof err));
    assert_non_null(strstr(err, missing));
    assert_non_null(strstr(err, "No such file"));

    const char *text = tu_path(dir, "text.exr");
    assert_true(tu_write_file(text, "hello, this is not an image\n", 28));
    assert_null(image_buffer_read_exr(text, err, sizeof err));
    assert_non_null(strstr(err, text));
    assert_non_null(strstr(err, "not a readable OpenEXR file"));

    /* every truncation of a real output file (dense sample) */
    image_format fmt = {40, 30, 16, IMAGE_LAYER_N};
    const char *full = tu_path(dir, "full.exr");
    image_writer *w = image_writer_new(full, &fmt, err, sizeof err);
    for (int ty = 0; ty < 2; ty++)
        for (int tx = 0; tx < 3; tx++) {
            image_tile *t = tu_tile(&fmt, tx, ty, 1, tx == 1);
            assert_true(image_writer_put_tile(w, t, err, sizeof err));
            image_tile_destroy(&t);
        }
    assert_true(image_writer_finish(&w, err, sizeof err));
    size_t len;
    uint8_t *bytes = tu_read_file(full, &len);
    assert_non_null(bytes);
    const char *cut = tu_path(dir, "cut.exr");
    for (size_t n = 0; n < len; n += (n < 800 ? 1 : 13)) {
        assert_true(tu_write_file(cut, bytes, n));
        image_buffer *img = image_buffer_read_exr(cut, err, sizeof err);
        if (img)
            fail_msg("file cut to %zu of %zu bytes was read", n, len);
        assert_non_null(strstr(err, cut));
    }
    free(bytes);
}

/* Under AddressSanitizer an allocation that fails returns NULL as malloc
 * does, instead of ending the process (the path tested below). */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

/* The scanline file of test_scanline_file with its data window grown to
 * w x h in the header (the pixels are never reached). */
static void write_huge_header(const char *path, int w, int h)
{
    write_scanline_file(path);
    size_t len;
    uint8_t *bytes = tu_read_file(path, &len);
    assert_non_null(bytes);
    static const char key[] = "dataWindow\0box2i\0";
    uint8_t *at = memmem(bytes, len, key, sizeof key - 1);
    assert_non_null(at);
    int32_t box[4] = {SX0, SY0, SX0 + w - 1, SY0 + h - 1};   /* little-endian host */
    memcpy(at + sizeof key - 1 + 4, box, sizeof box);
    assert_true(tu_write_file(path, bytes, len));
    free(bytes);
}

/* In a child limited to 256 MiB more address space than it has: reading
 * a 16384 x 16384 file of three channels (3 GiB of planes) fails its
 * allocation, and the reader says so instead of aborting. */
static int read_huge(void *arg)
{
    const char *path = arg;
    char msg[512] = "";
    image_buffer *img = image_buffer_read_exr(path, msg, sizeof msg);
    fprintf(stderr, "child: %s\n", img ? "read the image" : msg);
    return img ? 1 : strstr(msg, path) && strstr(msg, "image too large to read into memory") ? 0 : 2;
}

static void test_out_of_memory(void **state)
{
    const char *path = tu_path(*state, "huge.exr");
    write_huge_header(path, 16384, 16384);
    assert_starved_ok(read_huge, (void *)path, 256ul << 20);
}

static image_buffer *small_image(void)
{
    const char *names[] = {"G", "R"};
    image_buffer *b = image_buffer_new(4, 3, 2, names);
    assert_non_null(b);
    b->x0 = 10;
    b->y0 = 20;
    for (int c = 0; c < 2; c++)
        for (int i = 0; i < 12; i++)
            b->planes[c][i] = (float) (c * 100 + i);
    return b;
}

static void test_compare(void **state)
{
    (void) state;
    image_buffer *a = small_image(), *b = small_image();
    image_diff d;
    assert_true(image_buffer_compare(a, b, 0.0, &d, err, sizeof err));
    assert_int_equal(d.count, 0);
    assert_true(d.max_abs == 0.0);

    b->planes[1][6] += 0.25f;                   /* R at (12, 21) */
    assert_true(image_buffer_compare(a, b, 0.0, &d, err, sizeof err));
    assert_int_equal(d.count, 1);
    assert_true(d.max_abs == 0.25);
    assert_string_equal(d.channel, "R");
    assert_int_equal(d.x, 12);
    assert_int_equal(d.y, 21);
    assert_true(image_buffer_compare(a, b, 0.25, &d, err, sizeof err));
    assert_int_equal(d.count, 0);

    a->planes[0][0] = b->planes[0][0] = NAN;    /* NaN == NaN */
    a->planes[0][1] = b->planes[0][1] = INFINITY;
    assert_true(image_buffer_compare(a, b, 0.25, &d, err, sizeof err));
    assert_int_equal(d.count, 0);
    b->planes[0][0] = 1.0f;                     /* NaN vs number */
    assert_true(image_buffer_compare(a, b, 1e30, &d, err, sizeof err));
    assert_int_equal(d.count, 1);
    assert_true(isinf(d.max_abs));
    assert_string_equal(d.channel, "G");

    b->y0 = 0;
    assert_false(image_buffer_compare(a, b, 0.0, &d, err, sizeof err));
    assert_non_null(strstr(err, "size"));
    b->y0 = 20;
    free(b->names[1]);
    b->names[1] = strdup("Q");
    assert_false(image_buffer_compare(a, b, 0.0, &d, err, sizeof err));
    assert_non_null(strstr(err, "'R' vs 'Q'"));
    image_buffer_destroy(&a);
    image_buffer_destroy(&b);
    assert_null(b);
    assert_null(image_buffer_new(0, 3, 1, NULL));
}

static int make_dir(void **state)
{
    *state = tu_make_dir();
    return *state ? 0 : -1;
}

static int remove_dir(void **state)
{
    char *dir = *state;
    tu_remove_dir(&dir);
    return 0;
}

#define T(fn) cmocka_unit_test_setup_teardown(fn, make_dir, remove_dir)

int main(void)
{
    const struct CMUnitTest tests[] = {
        T(test_scanline_file),
        T(test_read_errors),
        T(test_out_of_memory),
        T(test_compare),
    };
    return cmocka_run_group_tests_name("image_buffer", tests, NULL, NULL);
}

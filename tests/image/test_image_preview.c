/*
 * tests/image/test_image_preview.c: the PNG preview (common/image/
 * preview.h), read back with libpng.
 *
 *   known values    0 -> 0, 0.5 -> 188, 1 -> 255, >1 -> 255 (clamp),
 *                   negative, NaN -> 0, +inf -> 255, the linear segment
 *                   (0.001 -> 3): hand-computed from the sRGB definition
 *   transfer curve  every code value for 4096 inputs against the sRGB
 *                   formula computed here in long double
 *   format          8-bit RGB, no alpha (composited over black), sRGB
 *                   chunk, rows top to bottom, the buffer variant equal to
 *                   the interleaved one, same pixels -> same bytes
 *   files           no temporary file left; a bad directory is an error
 *                   that names the file and leaves nothing behind
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/buffer.h"
#include "image/preview.h"
#include "image_testutil.h"

static char err[512];

typedef struct decoded {
    png_uint_32 w, h;
    int bit_depth, color_type, has_srgb;
    uint8_t *px;    /* w*h*channels */
    int channels;
} decoded;

static decoded read_png(const char *path)
{
    decoded d;
    memset(&d, 0, sizeof d);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL,
                                             NULL);
    png_infop info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png)))
        fail_msg("libpng could not read %s", path);
    png_init_io(png, f);
    png_read_info(png, info);
    d.w = png_get_image_width(png, info);
    d.h = png_get_image_height(png, info);
    d.bit_depth = png_get_bit_depth(png, info);
    d.color_type = png_get_color_type(png, info);
    d.has_srgb = png_get_valid(png, info, PNG_INFO_sRGB) != 0;
    d.channels = png_get_channels(png, info);
    d.px = malloc((size_t) d.w * d.h * (size_t) d.channels);
    for (png_uint_32 y = 0; y < d.h; y++)
        png_read_row(png, d.px + (size_t) y * d.w * (size_t) d.channels, NULL);
    png_read_end(png, NULL);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    return d;
}

static void test_known_values(void **state)
{
    const char *dir = *state;
    /* 4x2: row 0 = 0, 0.5, 1, 2 (grey); row 1 = -1, NaN, +inf, 0.001 */
    float in[8] = {0.0f, 0.5f, 1.0f, 2.0f, -1.0f, NAN, INFINITY, 0.001f};
    uint8_t want[8] = {0, 188, 255, 255, 0, 0, 255, 3};
    float rgba[8 * 4];
    for (int i = 0; i < 8; i++) {
        for (int c = 0; c < 3; c++)
            rgba[4 * i + c] = in[i];
        rgba[4 * i + 3] = 0.25f;               /* alpha is not applied */
    }
    const char *path = tu_path(dir, "p.png");
    assert_true(image_preview_write_png(path, rgba, 4, 2, err, sizeof err));
    decoded d = read_png(path);
    assert_int_equal(d.w, 4);
    assert_int_equal(d.h, 2);
    assert_int_equal(d.bit_depth, 8);
    assert_int_equal(d.color_type, PNG_COLOR_TYPE_RGB);
    assert_int_equal(d.channels, 3);
    assert_true(d.has_srgb);
    for (int i = 0; i < 8; i++)
        for (int c = 0; c < 3; c++)
            if (d.px[3 * i + c] != want[i])
                fail_msg("input %g: got %u want %u", in[i], d.px[3 * i + c],
                         want[i]);
    free(d.px);
    assert_int_equal(tu_dir_entries(dir), 1);
}

static void test_transfer_curve(void **state)
{
    (void) state;
    for (int i = 0; i <= 4096; i++) {
        long double c = (long double) i / 4096.0L;
        long double v = c <= 0.0031308L ? 12.92L * c
                        : 1.055L * powl(c, 1.0L / 2.4L) - 0.055L;
        long want = lroundl(v * 255.0L);
        assert_int_equal(image_preview_srgb8((float) c), want);
    }
}

static void test_channels_and_buffer(void **state)
{
    const char *dir = *state;
    enum { W = 7, H = 5 };
    float rgba[W * H * 4];
    const char *names[] = {"A", "B", "G", "R"};
    image_buffer *buf = image_buffer_new(W, H, 4, names);
    for (int i = 0; i < W * H; i++) {
        float r = (float) i / (W * H), g = 1.0f - r, b = (float) (i % 3) / 2.0f;
        float v[4] = {r, g, b, 1.0f};
        memcpy(rgba + 4 * i, v, sizeof v);
        image_buffer_channel(buf, "R")[i] = r;
        image_buffer_channel(buf, "G")[i] = g;
        image_buffer_channel(buf, "B")[i] = b;
        image_buffer_channel(buf, "A")[i] = 1.0f;
    }
    const char *p1 = tu_path(dir, "a.png"), *p2 = tu_path(dir, "b.png");
    const char *p3 = tu_path(dir, "c.png");
    assert_true(image_preview_write_png(p1, rgba, W, H, err, sizeof err));
    assert_true(image_preview_write_png_buffer(p2, buf, err, sizeof err));
    assert_true(image_preview_write_png(p3, rgba, W, H, err, sizeof err));
    decoded d = read_png(p1);
    for (int i = 0; i < W * H; i++) {          /* R G B in order, rows top first */
        assert_int_equal(d.px[3 * i + 0], image_preview_srgb8(rgba[4 * i + 0]));
        assert_int_equal(d.px[3 * i + 1], image_preview_srgb8(rgba[4 * i + 1]));
        assert_int_equal(d.px[3 * i + 2], image_preview_srgb8(rgba[4 * i + 2]));
    }
    assert_int_equal(d.px[0], 0);                          /* R of pixel 0 */
    assert_int_equal(d.px[3 * (W * H - 1) + 1], image_preview_srgb8(1.0f / (W * H)));
    free(d.px);
    size_t l1, l2, l3;
    uint8_t *f1 = tu_read_file(p1, &l1), *f2 = tu_read_file(p2, &l2);
    uint8_t *f3 = tu_read_file(p3, &l3);
    assert_int_equal(l1, l2);
    assert_memory_equal(f1, f2, l1);
    assert_int_equal(l1, l3);
    assert_memory_equal(f1, f3, l1);
    free(f1);
    free(f2);
    free(f3);
    image_buffer_destroy(&buf);
    assert_int_equal(tu_dir_entries(dir), 3);
}

static void test_file_errors(void **state)
{
    const char *dir = *state;
    float px[4] = {1, 1, 1, 1};
    assert_false(image_preview_write_png("/nonexistent-aafarm-dir/p.png", px,
                                         1, 1, err, sizeof err));
    assert_non_null(strstr(err, "/nonexistent-aafarm-dir/p.png.tmp-"));
    const char *p = tu_path(dir, "p.png");
    assert_false(image_preview_write_png(p, px, 0, 1, err, sizeof err));
    assert_non_null(strstr(err, "out of range"));
    assert_false(image_preview_write_png(p, NULL, 1, 1, err, sizeof err));
    assert_int_equal(tu_dir_entries(dir), 0);
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
        T(test_known_values),
        T(test_transfer_curve),
        T(test_channels_and_buffer),
        T(test_file_errors),
    };
    return cmocka_run_group_tests_name("image_preview", tests, NULL, NULL);
}

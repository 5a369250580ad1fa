/*
 * tests/bench/test_peers_diff.c: the pixel comparison of the peer benchmark
 * (bench/peers/peers_diff.h) and its image files (peers_png.h), whose
 * counts are the "differ" column of `make bench-peers`.
 *
 *   counts      a hole, an extra pixel, a colour step over the tolerance and
 *               one under it, a NaN channel: each counted once where it
 *               belongs; pixels missed by both never count; the picture
 *               marks each kind in its colour
 *   png         a 16-bit linear RGBA file reads back within half a step of
 *               what was written (no gamma on the way), clamped to [0, 1];
 *               compared with the original: nothing differs
 *   errors      writing into a missing folder or reading a missing or
 *               non-PNG file: false, a message naming the file, no file left
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "peers_diff.h"
#include "peers_png.h"

enum { W = 7, H = 5 };

/* A smooth test image: the left two columns are background (alpha 0). */
static void fill(float *img)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *p = &img[(y * W + x) * 4];
            p[0] = (float)x / W;
            p[1] = (float)y / H;
            p[2] = 0.25f + 0.01f * (float)(x + y);
            p[3] = x >= 2 ? 1.0f : 0.0f;
            if (x < 2) p[0] = p[1] = p[2] = 0;
        }
}

static float *px(float *img, int x, int y) { return &img[(y * W + x) * 4]; }

static void test_counts(void **state)
{
    (void)state;
    float ref[W * H * 4], test[W * H * 4], pic[W * H * 4];
    fill(ref);
    fill(test);
    peers_diff d = peers_diff_images(test, ref, W, H, 8.0 / 255.0, NULL);
    assert_int_equal(d.holes + d.extra + d.colour, 0);

    px(test, 3, 1)[3] = 0;                  /* hole */
    px(test, 0, 4)[3] = 1;                  /* extra */
    px(test, 5, 2)[1] += 0.05f;             /* over 8/255 = 0.031 */
    px(test, 6, 3)[2] += 0.02f;             /* under */
    px(test, 4, 4)[0] = NAN;                /* a NaN colour is a difference */
    px(test, 1, 1)[0] = 0.9f;               /* colour behind a miss in both: no */
    d = peers_diff_images(test, ref, W, H, 8.0 / 255.0, pic);
    assert_int_equal(d.holes, 1);
    assert_int_equal(d.extra, 1);
    assert_int_equal(d.colour, 2);
    assert_true(px(pic, 3, 1)[0] == 1 && px(pic, 3, 1)[1] == 0 && px(pic, 3, 1)[2] == 0);
    assert_true(px(pic, 0, 4)[0] == 0 && px(pic, 0, 4)[1] == 0 && px(pic, 0, 4)[2] == 1);
    assert_true(px(pic, 5, 2)[0] == 1 && px(pic, 5, 2)[1] == 1 && px(pic, 5, 2)[2] == 0);
    /* an unchanged pixel shows the test's grey level */
    float grey = (px(test, 2, 0)[0] + px(test, 2, 0)[1] + px(test, 2, 0)[2]) / 3;
    assert_float_equal(px(pic, 2, 0)[1], grey, 1e-7);
    /* a looser tolerance forgives the 0.05 step, not the NaN */
    d = peers_diff_images(test, ref, W, H, 0.06, NULL);
    assert_int_equal(d.colour, 1);
}

static void test_png_round_trip(void **state)
{
    (void)state;
    char path[] = "/tmp/test_peers_diff_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    float img[W * H * 4];
    fill(img);
    img[(2 * W + 4) * 4 + 0] = 1.5f;        /* clamped to 1 */
    img[(2 * W + 4) * 4 + 1] = -0.5f;       /* clamped to 0 */
    char err[512] = "";
    assert_true(peers_png_write(path, W, H, img, err, sizeof err));
    int w = 0, h = 0;
    float *back = NULL;
    assert_true(peers_png_read(path, &w, &h, &back, err, sizeof err));
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    for (int i = 0; i < W * H * 4; i++) {
        float want = img[i] < 0 ? 0 : img[i] > 1 ? 1 : img[i];
        assert_float_equal(back[i], want, 0.5 / 65535.0 + 1e-7);
    }
    img[(2 * W + 4) * 4 + 0] = 1.0f;
    img[(2 * W + 4) * 4 + 1] = 0.0f;
    peers_diff d = peers_diff_images(back, img, W, H, 1e-4, NULL);
    assert_int_equal(d.holes + d.extra + d.colour, 0);
    free(back);
    unlink(path);
}

static void test_errors(void **state)
{
    (void)state;
    float img[W * H * 4];
    fill(img);
    char err[512] = "";
    const char *missing = "/tmp/test_peers_diff_no_such_dir/out.png";
    assert_false(peers_png_write(missing, W, H, img, err, sizeof err));
    assert_non_null(strstr(err, missing));
    assert_int_equal(access(missing, F_OK), -1);

    int w, h;
    float *back = (float *)1;
    err[0] = 0;
    assert_false(peers_png_read(missing, &w, &h, &back, err, sizeof err));
    assert_null(back);
    assert_non_null(strstr(err, missing));

    char path[] = "/tmp/test_peers_diff_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, "P6\n1 1\n255\nabc", 14), 14);
    close(fd);
    err[0] = 0;
    assert_false(peers_png_read(path, &w, &h, &back, err, sizeof err));
    assert_null(back);
    assert_non_null(strstr(err, path));
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counts),
        cmocka_unit_test(test_png_round_trip),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

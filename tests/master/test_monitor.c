/*
 * test_monitor.c: the live monitor's state between the master's loop and
 * the HTTP thread (master/monitor.h), without sockets:
 *   - a tile put is in the PNG as 8-bit sRGB (image_preview_srgb8), the
 *     rest black; the PNG is cached (same bytes) until the next tile;
 *   - a frame over MONITOR_MAX_SIDE keeps every k-th pixel;
 *   - beyond MONITOR_MAX_IMAGES images the earliest complete frame's is
 *     dropped (its PNG refused with the reason), an unknown frame is
 *     "missing";
 *   - documents are copied whole; a reader thread taking PNGs and
 *     documents while the loop puts tiles and publishes sees whole
 *     documents only (run it under -DAAFARM_SANITIZE=ON or TSan).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "http_testutil.h"
#include "image/preview.h"
#include "monitor.h"
#include "util/err.h"

/* A w x h tile of one colour (RGBA floats). */
static float *solid(int w, int h, float r, float g, float b)
{
    float *p = malloc((size_t)w * (size_t)h * 4 * sizeof *p);
    for (int i = 0; i < w * h; i++) {
        p[4 * i] = r;
        p[4 * i + 1] = g;
        p[4 * i + 2] = b;
        p[4 * i + 3] = 1;
    }
    return p;
}

static uint8_t *png_of(monitor *m, int frame, int *w, int *h, void **png, size_t *len)
{
    bool missing = true;
    char err[ERR_LEN];
    assert_true(monitor_png(m, frame, png, len, &missing, err, sizeof err));
    assert_false(missing);
    uint8_t *rgb = ht_png_rgb(*png, *len, w, h);
    assert_non_null(rgb);
    return rgb;
}

static void test_tiles_into_the_png(void **state)
{
    (void)state;
    monitor *m = monitor_new();
    assert_int_equal(monitor_add_frame(m, 40, 20), 0);
    void *png0 = NULL, *png1 = NULL, *png2 = NULL;
    size_t len0, len1, len2;
    int w, h;
    uint8_t *rgb = png_of(m, 0, &w, &h, &png0, &len0);   /* nothing yet: black */
    assert_int_equal(w, 40);
    assert_int_equal(h, 20);
    for (int i = 0; i < 40 * 20 * 3; i++) assert_int_equal(rgb[i], 0);
    free(rgb);
    float *tile = solid(16, 16, 0.5f, 0.25f, 1.0f);
    monitor_put_tile(m, 0, (image_rect){16, 0, 16, 16}, tile);
    rgb = png_of(m, 0, &w, &h, &png1, &len1);
    uint8_t want[3] = {image_preview_srgb8(0.5f), image_preview_srgb8(0.25f), 255};
    for (int y = 0; y < 20; y++)
        for (int x = 0; x < 40; x++)
            for (int c = 0; c < 3; c++)
                assert_int_equal(rgb[3 * (y * 40 + x) + c],
                                 x >= 16 && x < 32 && y < 16 ? want[c] : 0);
    free(rgb);
    rgb = png_of(m, 0, &w, &h, &png2, &len2);   /* cached: the same bytes */
    assert_int_equal(len1, len2);
    assert_memory_equal(png1, png2, len1);
    assert_true(len0 != len1 || memcmp(png0, png1, len0) != 0);
    free(rgb);
    free(png0);
    free(png1);
    free(png2);
    free(tile);
    monitor_destroy(&m);
    assert_null(m);
}

static void test_large_frame_is_decimated(void **state)
{
    (void)state;
    monitor *m = monitor_new();
    int side = 2 * MONITOR_MAX_SIDE + 10;   /* k = 3 */
    monitor_add_frame(m, side, 8);
    float *tile = solid(32, 8, 1, 1, 1);
    monitor_put_tile(m, 0, (image_rect){32, 0, 32, 8}, tile);   /* x 32..63: kept 33..63 by 3 */
    void *png;
    size_t len;
    int w, h;
    uint8_t *rgb = png_of(m, 0, &w, &h, &png, &len);
    assert_int_equal(w, (side + 2) / 3);
    assert_int_equal(h, 3);
    for (int x = 0; x < w; x++)   /* kept pixel x is pixel 3x: lit for 33 <= 3x < 64 */
        assert_int_equal(rgb[3 * x], 3 * x >= 32 && 3 * x < 64 ? 255 : 0);
    free(rgb);
    free(png);
    free(tile);
    monitor_destroy(&m);
}

static void test_images_dropped_oldest_complete_first(void **state)
{
    (void)state;
    monitor *m = monitor_new();
    int n = MONITOR_MAX_IMAGES + 1;
    for (int i = 0; i < n; i++) monitor_add_frame(m, 8, 8);
    float *tile = solid(8, 8, 1, 0, 0);
    for (int i = 0; i < n - 1; i++) monitor_put_tile(m, i, (image_rect){0, 0, 8, 8}, tile);
    monitor_frame_complete(m, 3);
    monitor_frame_complete(m, 1);
    monitor_put_tile(m, n - 1, (image_rect){0, 0, 8, 8}, tile);   /* frame 3 goes */
    void *png = NULL;
    size_t len;
    bool missing = true;
    char err[ERR_LEN];
    assert_false(monitor_png(m, 3, &png, &len, &missing, err, sizeof err));
    assert_false(missing);
    assert_string_equal(err, "frame 3 is complete and its image was dropped from the monitor's "
                        "memory (it keeps 16): read its output file");
    assert_true(monitor_png(m, 1, &png, &len, &missing, err, sizeof err));
    free(png);
    assert_false(monitor_png(m, n, &png, &len, &missing, err, sizeof err));
    assert_true(missing);
    free(tile);
    monitor_destroy(&m);
}

/* The HTTP thread's side, while the loop writes. */
typedef struct reader_arg {
    monitor *m;
    int rounds, whole;
} reader_arg;

static void *reader(void *p)
{
    reader_arg *a = p;
    for (int i = 0; i < a->rounds; i++) {
        size_t len = 0;
        char *doc = monitor_doc_copy(a->m, MONITOR_STATUS, &len);
        if (doc) {
            a->whole += len == strlen(doc) && doc[0] == '{' && doc[len - 1] == '}';
            free(doc);
        } else {
            a->whole++;
        }
        void *png = NULL;
        bool missing;
        char err[ERR_LEN];
        if (monitor_png(a->m, 0, &png, &len, &missing, err, sizeof err)) free(png);
    }
    return NULL;
}

static void test_reader_thread(void **state)
{
    (void)state;
    monitor *m = monitor_new();
    monitor_add_frame(m, 64, 64);
    reader_arg a = {m, 300, 0};
    pthread_t t;
    assert_int_equal(pthread_create(&t, NULL, reader, &a), 0);
    float *tile = solid(8, 8, 0.3f, 0.6f, 0.9f);
    for (int i = 0; i < 64; i++) {
        monitor_put_tile(m, 0, (image_rect){i % 8 * 8, i / 8 * 8, 8, 8}, tile);
        char *doc = malloc(1024);
        int n = snprintf(doc, 1024, "{\"done\": %d, \"pad\": \"%0*d\"}", i, 10 + i * 7, 0);
        assert_true(n > 0 && n < 1024);
        monitor_publish(m, MONITOR_STATUS, doc, (size_t)n);
    }
    pthread_join(t, NULL);
    assert_int_equal(a.whole, a.rounds);
    free(tile);
    monitor_destroy(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tiles_into_the_png),
        cmocka_unit_test(test_large_frame_is_decimated),
        cmocka_unit_test(test_images_dropped_oldest_complete_first),
        cmocka_unit_test(test_reader_thread),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

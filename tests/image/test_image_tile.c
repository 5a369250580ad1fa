/*
 * tests/image/test_image_tile.c: one-tile EXR files (common/image/tile.h)
 * and the image format they follow (format.h).
 *
 *   grid            tile rectangles cover the image exactly once, edge
 *                   tiles are smaller; tile_index accepts exactly the grid
 *   deterministic   the same pixels encode to the same bytes; other pixels
 *                   to other bytes
 *   accepts own     every tile of several formats (edge tiles, 1-pixel
 *                   tiles, all layers) validates against its rectangle
 *   wrong tile      position, tile size, image size, channels (layers)
 *                   other than expected are rejected, naming the attribute
 *   truncation      every prefix of a real tile file is rejected
 *   byte flips      thousands of single-byte changes never crash; a change
 *                   in the header or framing is always rejected; accepted
 *                   files decode cleanly
 *   garbage         random bytes, with and without the EXR magic, rejected
 *   encode errors   a tile off the grid or with other layers is refused
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

#include "image/format.h"
#include "image/tile.h"
#include "image_testutil.h"

static char err[512];

/* Encodes tile (tx, ty) of fmt; asserts success. */
static uint8_t *encode(const image_format *fmt, int tx, int ty, uint64_t seed,
                       bool smooth, size_t *len)
{
    image_tile *t = tu_tile(fmt, tx, ty, seed, smooth);
    assert_non_null(t);
    void *bytes = NULL;
    bool ok = image_tile_encode_exr(t, fmt, &bytes, len, err, sizeof err);
    if (!ok)
        fail_msg("encode failed: %s", err);
    image_tile_destroy(&t);
    return bytes;
}

static void test_grid(void **state)
{
    (void) state;
    image_format fmt = {100, 70, 32, 0};
    assert_true(image_format_check(&fmt, err, sizeof err));
    assert_int_equal(image_format_tiles_x(&fmt), 4);
    assert_int_equal(image_format_tiles_y(&fmt), 3);
    static unsigned char covered[70][100];
    memset(covered, 0, sizeof covered);
    for (int ty = 0; ty < 3; ty++) {
        for (int tx = 0; tx < 4; tx++) {
            image_rect r = image_format_tile_rect(&fmt, tx, ty);
            assert_int_equal(r.w, tx == 3 ? 4 : 32);
            assert_int_equal(r.h, ty == 2 ? 6 : 32);
            for (int y = r.y0; y < r.y0 + r.h; y++)
                for (int x = r.x0; x < r.x0 + r.w; x++)
                    covered[y][x]++;
            int ix = -1, iy = -1;
            assert_true(image_format_tile_index(&fmt, r, &ix, &iy, err,
                                                sizeof err));
            assert_int_equal(ix, tx);
            assert_int_equal(iy, ty);
        }
    }
    for (int y = 0; y < 70; y++)
        for (int x = 0; x < 100; x++)
            assert_int_equal(covered[y][x], 1);
    image_rect off = {16, 0, 32, 32}, big = {96, 0, 32, 32};
    int ix, iy;
    assert_false(image_format_tile_index(&fmt, off, &ix, &iy, err, sizeof err));
    assert_false(image_format_tile_index(&fmt, big, &ix, &iy, err, sizeof err));
    assert_non_null(strstr(err, "expected 4x32"));
    /* the channel list is sorted, as EXR requires */
    image_format all = {8, 8, 8, IMAGE_LAYERS_ALL};
    assert_int_equal(image_format_channel_count(&all), 11);
    assert_int_equal(image_format_channel_count(&fmt), 5);
    for (int c = 1; c < 11; c++)
        assert_true(strcmp(image_format_channel(&all, c - 1)->name,
                           image_format_channel(&all, c)->name) < 0);
    image_format bad = {100, 70, 0, 0};
    assert_false(image_format_check(&bad, err, sizeof err));
    assert_non_null(strstr(err, "tile size 0"));
}

static void test_deterministic(void **state)
{
    (void) state;
    image_format fmt = {100, 70, 32, IMAGE_LAYERS_ALL};
    size_t n1, n2, n3;
    uint8_t *a = encode(&fmt, 1, 2, 7, false, &n1);
    uint8_t *b = encode(&fmt, 1, 2, 7, false, &n2);
    uint8_t *c = encode(&fmt, 1, 2, 8, false, &n3);
    assert_int_equal(n1, n2);
    assert_memory_equal(a, b, n1);
    assert_true(n1 != n3 || memcmp(a, c, n1) != 0);
    free(a);
    free(b);
    free(c);
}

static void test_accepts_own_tiles(void **state)
{
    (void) state;
    image_format fmts[] = {
        {100, 70, 32, IMAGE_LAYERS_ALL}, {33, 17, 16, 0}, {5, 3, 8, IMAGE_LAYER_N},
        {64, 64, 64, IMAGE_LAYER_P}, {3, 2, 1, 0},
    };
    for (size_t f = 0; f < sizeof fmts / sizeof fmts[0]; f++) {
        const image_format *fmt = &fmts[f];
        for (int ty = 0; ty < image_format_tiles_y(fmt); ty++) {
            for (int tx = 0; tx < image_format_tiles_x(fmt); tx++) {
                size_t n;
                uint8_t *b = encode(fmt, tx, ty, f, tx % 2 == 0, &n);
                image_rect r = image_format_tile_rect(fmt, tx, ty);
                if (!image_tile_validate_exr(b, n, fmt, r, err, sizeof err))
                    fail_msg("format %zu tile (%d,%d) rejected: %s", f, tx,
                             ty, err);
                const void *chunk = NULL;
                size_t chunk_len = 0;
                assert_true(image_tile_exr_chunk(b, n, fmt, r, &chunk,
                                                 &chunk_len, err, sizeof err));
                /* the chunk is the tail of the file */
                assert_ptr_equal((const uint8_t *) chunk + chunk_len, b + n);
                /* image_tile_encode_chunk locates (not checks) the same
                 * chunk in the same bytes as the checking parser above */
                image_tile *t = tu_tile(fmt, tx, ty, f, tx % 2 == 0);
                void *own = NULL;
                size_t own_len = 0, own_chunk_len = 0;
                const void *own_chunk = NULL;
                assert_true(image_tile_encode_chunk(t, fmt, &own, &own_len, &own_chunk,
                                                    &own_chunk_len, err, sizeof err));
                assert_int_equal(own_len, n);
                assert_memory_equal(own, b, n);
                assert_int_equal(own_chunk_len, chunk_len);
                assert_int_equal((const uint8_t *) own_chunk - (const uint8_t *) own,
                                 (const uint8_t *) chunk - b);
                free(own);
                image_tile_destroy(&t);
                free(b);
            }
        }
    }
}

/* Encodes with `made`, validates with `expected`: must fail naming `what`. */
static void expect_rejected(const image_format *made, int tx, int ty,
                            const image_format *expected, image_rect r,
                            const char *what)
{
    size_t n;
    uint8_t *b = encode(made, tx, ty, 1, false, &n);
    bool ok = image_tile_validate_exr(b, n, expected, r, err, sizeof err);
    free(b);
    assert_false(ok);
    if (!strstr(err, what))
        fail_msg("message '%s' does not mention '%s'", err, what);
}

static void test_wrong_tile(void **state)
{
    (void) state;
    image_format fmt = {100, 70, 32, 0};
    /* tile (1,0) offered as tile (0,0) and as (2,1) */
    expect_rejected(&fmt, 1, 0, &fmt, image_format_tile_rect(&fmt, 0, 0),
                    "dataWindow' is (32,0)-(63,31), expected (0,0)-(31,31)");
    expect_rejected(&fmt, 1, 0, &fmt, image_format_tile_rect(&fmt, 2, 1),
                    "dataWindow");
    /* edge tile offered as a full tile of the same row */
    expect_rejected(&fmt, 3, 0, &fmt, image_format_tile_rect(&fmt, 2, 0),
                    "dataWindow");
    /* tile size 32 where 64 is expected (same rectangle) */
    image_format t32 = {32, 32, 32, 0}, t64 = {32, 32, 64, 0};
    image_rect whole = {0, 0, 32, 32};
    expect_rejected(&t32, 0, 0, &t64, whole, "'tiles' is 32x32");
    /* image size differs (display window) */
    image_format wide = {200, 70, 32, 0};
    expect_rejected(&fmt, 0, 0, &wide, image_format_tile_rect(&wide, 0, 0),
                    "displayWindow");
    /* channels: N layer sent, none expected; and the other way round */
    image_format with_n = {100, 70, 32, IMAGE_LAYER_N};
    expect_rejected(&with_n, 0, 0, &fmt, image_format_tile_rect(&fmt, 0, 0),
                    "channels' is A:half B:half G:half N.x:float");
    expect_rejected(&fmt, 0, 0, &with_n, image_format_tile_rect(&fmt, 0, 0),
                    "channels");
    /* expected rectangle that is no tile at all */
    size_t n;
    uint8_t *b = encode(&fmt, 0, 0, 1, false, &n);
    image_rect odd = {1, 0, 32, 32};
    assert_false(image_tile_validate_exr(b, n, &fmt, odd, err, sizeof err));
    assert_non_null(strstr(err, "not the corner"));
    free(b);
}

/* Every prefix of a tile file is rejected, with a message. */
static void check_prefixes(const image_format *fmt, int tx, int ty,
                           bool smooth, size_t step)
{
    size_t n;
    uint8_t *b = encode(fmt, tx, ty, 3, smooth, &n);
    image_rect r = image_format_tile_rect(fmt, tx, ty);
    for (size_t len = 0; len < n; len += (len < 600 ? 1 : step)) {
        uint8_t *copy = malloc(len ? len : 1);   /* exact size: ASan sees overreads */
        memcpy(copy, b, len);
        err[0] = '\0';
        if (image_tile_validate_exr(copy, len, fmt, r, err, sizeof err))
            fail_msg("prefix of %zu of %zu bytes accepted", len, n);
        assert_true(err[0] != '\0');
        free(copy);
    }
    assert_true(image_tile_validate_exr(b, n, fmt, r, err, sizeof err));
    free(b);
}

static void test_truncation(void **state)
{
    (void) state;
    image_format small = {20, 20, 8, IMAGE_LAYERS_ALL};
    check_prefixes(&small, 2, 2, false, 1);        /* 4x4 edge tile, all lengths */
    check_prefixes(&small, 0, 0, true, 1);         /* compressed chunk, all lengths */
    image_format big = {64, 64, 32, 0};
    check_prefixes(&big, 1, 1, false, 7);          /* dense sample */
    check_prefixes(&big, 0, 1, true, 1);
    assert_false(image_tile_validate_exr(NULL, 0, &small,
                                         image_format_tile_rect(&small, 0, 0),
                                         err, sizeof err));
    assert_non_null(strstr(err, "truncated"));
}

/* Length of the header + offset table + chunk leader of a tile file. */
static size_t chunk_start(const uint8_t *b, size_t n, const image_format *fmt,
                          image_rect r)
{
    const void *chunk;
    size_t chunk_len;
    assert_true(image_tile_exr_chunk(b, n, fmt, r, &chunk, &chunk_len, err,
                                     sizeof err));
    return (size_t) ((const uint8_t *) chunk - b);
}

static void flip_bytes(const image_format *fmt, int tx, int ty, bool smooth,
                       int trials, int *accepted)
{
    size_t n;
    uint8_t *b = encode(fmt, tx, ty, 5, smooth, &n);
    image_rect r = image_format_tile_rect(fmt, tx, ty);
    size_t data_at = chunk_start(b, n, fmt, r);
    uint8_t *copy = malloc(n);
    for (int i = 0; i < trials; i++) {
        memcpy(copy, b, n);
        size_t at = tu_below((uint32_t) n);
        uint8_t x = (uint8_t) (1 + tu_below(255));
        copy[at] ^= x;
        if (i % 3 == 0) {                      /* sometimes a second byte */
            size_t at2 = tu_below((uint32_t) n);
            copy[at2] ^= (uint8_t) (1 + tu_below(255));
            at = at < at2 ? at : at2;
        }
        if (!image_tile_validate_exr(copy, n, fmt, r, err, sizeof err))
            continue;
        (*accepted)++;
        if (at < data_at)
            fail_msg("change at byte %zu (header/framing ends at %zu) "
                     "accepted", at, data_at);
    }
    free(copy);
    free(b);
}

static void test_byte_flips(void **state)
{
    (void) state;
    tu_seed(42);
    image_format fmt = {48, 40, 16, IMAGE_LAYERS_ALL};
    int acc_raw = 0, acc_zip = 0;
    flip_bytes(&fmt, 1, 1, false, 1500, &acc_raw);   /* raw-stored chunk */
    flip_bytes(&fmt, 2, 2, true, 2000, &acc_zip);    /* zlib-compressed chunk */
    /* a changed compressed stream almost never passes zlib's checks */
    assert_true(acc_zip < 100);
    print_message("byte flips accepted (all inside chunk data): raw %d/1500, "
                  "zip %d/2000\n", acc_raw, acc_zip);
}

static void test_garbage(void **state)
{
    (void) state;
    tu_seed(99);
    image_format fmt = {48, 40, 16, 0};
    image_rect r = image_format_tile_rect(&fmt, 0, 0);
    for (int i = 0; i < 300; i++) {
        size_t n = tu_below(4000);
        uint8_t *g = malloc(n ? n : 1);
        for (size_t k = 0; k < n; k++)
            g[k] = (uint8_t) tu_next();
        if (i % 2 && n >= 8) {
            const uint8_t head[8] = {0x76, 0x2f, 0x31, 0x01, 2, 2, 0, 0};
            memcpy(g, head, 8);
        }
        assert_false(image_tile_validate_exr(g, n, &fmt, r, err, sizeof err));
        free(g);
    }
    const uint8_t scan[8] = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
    assert_false(image_tile_validate_exr(scan, 8, &fmt, r, err, sizeof err));
    assert_non_null(strstr(err, "single-part tiled"));
    const uint8_t png[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
    assert_false(image_tile_validate_exr(png, 8, &fmt, r, err, sizeof err));
    assert_non_null(strstr(err, "bad magic"));
}

static void test_encode_errors(void **state)
{
    (void) state;
    image_format fmt = {100, 70, 32, 0};
    void *bytes = (void *) 1;
    size_t len = 1;
    image_tile *off = image_tile_new(8, 0, 32, 32, 0);
    assert_false(image_tile_encode_exr(off, &fmt, &bytes, &len, err, sizeof err));
    assert_null(bytes);
    assert_int_equal(len, 0);
    assert_non_null(strstr(err, "(8,0)"));
    image_tile_destroy(&off);
    assert_null(off);
    image_tile *layered = image_tile_new(0, 0, 32, 32, IMAGE_LAYER_P);
    assert_non_null(layered->p);
    assert_null(layered->n);
    assert_false(image_tile_encode_exr(layered, &fmt, &bytes, &len, err,
                                       sizeof err));
    assert_non_null(strstr(err, "layers"));
    image_tile_destroy(&layered);
    assert_null(image_tile_new(0, 0, 0, 4, 0));
    assert_null(image_tile_new(0, 0, 4, 4, 0x80));
    image_tile_destroy(&layered);              /* NULL: no-op */
}

/* NaN and infinities become 0 in RGBA/N/P; in Z NaN and -Inf become +Inf
 * ("nothing hit") and +Inf stays; the count and first pixel are exact. */
static void test_clear_nonfinite(void **state)
{
    (void) state;
    image_tile *t = image_tile_new(16, 8, 4, 3, IMAGE_LAYER_N);
    assert_non_null(t);
    int fx = -1, fy = -1;
    assert_int_equal(image_tile_clear_nonfinite(t, &fx, &fy), 0);
    assert_int_equal(fx, -1);
    t->rgba[(1 * 4 + 2) * 4 + 0] = NAN;         /* pixel (2,1) R */
    t->rgba[(2 * 4 + 0) * 4 + 3] = INFINITY;    /* pixel (0,2) A */
    t->n[(2 * 4 + 3) * 3 + 1] = -INFINITY;      /* pixel (3,2) N.y */
    t->z[0] = INFINITY;                         /* no hit: stays */
    t->z[1] = NAN;
    t->z[2] = -INFINITY;
    t->rgba[5] = 1e30f;                         /* large but finite: stays */
    assert_int_equal(image_tile_clear_nonfinite(t, &fx, &fy), 5);
    assert_int_equal(fx, 16 + 1);               /* z[1]: pixel (1,0) comes first */
    assert_int_equal(fy, 8);
    assert_true(t->rgba[(1 * 4 + 2) * 4 + 0] == 0.0f);
    assert_true(t->rgba[(2 * 4 + 0) * 4 + 3] == 0.0f);
    assert_true(t->n[(2 * 4 + 3) * 3 + 1] == 0.0f);
    assert_true(isinf(t->z[0]) && t->z[0] > 0);
    assert_true(isinf(t->z[1]) && t->z[1] > 0);
    assert_true(isinf(t->z[2]) && t->z[2] > 0);
    assert_true(t->rgba[5] == 1e30f);
    assert_int_equal(image_tile_clear_nonfinite(t, &fx, &fy), 0);
    image_tile_destroy(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_accepts_own_tiles),
        cmocka_unit_test(test_wrong_tile),
        cmocka_unit_test(test_truncation),
        cmocka_unit_test(test_byte_flips),
        cmocka_unit_test(test_garbage),
        cmocka_unit_test(test_encode_errors),
        cmocka_unit_test(test_clear_nonfinite),
    };
    return cmocka_run_group_tests_name("image_tile", tests, NULL, NULL);
}

/*
 * tests/image/test_image_writer.c: the tiled output EXR (common/image/
 * writer.h), stitching by raw chunk copy, and reading it back (buffer.h).
 *
 *   roundtrip       random pixels -> tile EXR in memory -> validated ->
 *                   raw chunk copy into the output -> read back: R G B A
 *                   equal the binary16 rounding of the input (reference
 *                   rounding in image_testutil.c), Z N P exact; for several
 *                   formats with partial edge tiles
 *   chunk copy      the output's chunk for a tile is byte-identical to the
 *                   tile file's chunk
 *   any order       tiles in shuffled order give the same pixels and the
 *                   same chunk bytes as in order
 *   two paths       put_tile (standalone renderer) and put_exr_chunk
 *                   (master) give byte-identical files
 *   temp + rename   finish leaves OUT.exr and no temporary file; abort
 *                   leaves nothing and keeps an existing OUT.exr intact;
 *                   finish with missing tiles refuses and keeps the work
 *   rejects         garbage and wrong tiles do not disturb the writer;
 *                   duplicates are ignored; bad paths and formats are clear
 *                   errors
 */
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

#include "image/buffer.h"
#include "image/format.h"
#include "image/tile.h"
#include "image/writer.h"
#include "image_testutil.h"

static char err[512];

static uint8_t *encode_tile(const image_tile *t, const image_format *fmt,
                            size_t *len)
{
    void *bytes = NULL;
    if (!image_tile_encode_exr(t, fmt, &bytes, len, err, sizeof err))
        fail_msg("encode: %s", err);
    return bytes;
}

/* Tile order: identity or a fixed-seed shuffle. */
static int *tile_order(int n, bool shuffle)
{
    int *order = malloc((size_t) n * sizeof *order);
    for (int i = 0; i < n; i++)
        order[i] = i;
    for (int i = n - 1; shuffle && i > 0; i--) {
        int j = (int) tu_below((uint32_t) i + 1);
        int t = order[i];
        order[i] = order[j];
        order[j] = t;
    }
    return order;
}

/* Writes the whole image of fmt to path (seeded random tiles), through
 * put_exr_chunk (chunk copy) or put_tile, in order or shuffled. */
static void write_image(const char *path, const image_format *fmt,
                        uint64_t seed, bool chunk_copy, bool shuffle)
{
    image_writer *w = image_writer_new(path, fmt, err, sizeof err);
    if (!w)
        fail_msg("writer: %s", err);
    int nx = image_format_tiles_x(fmt), n = image_format_tile_count(fmt);
    int *order = tile_order(n, shuffle);
    for (int i = 0; i < n; i++) {
        int tx = order[i] % nx, ty = order[i] / nx;
        image_tile *t = tu_tile(fmt, tx, ty, seed, (tx + ty) % 3 == 0);
        bool ok;
        if (chunk_copy) {
            size_t len;
            uint8_t *b = encode_tile(t, fmt, &len);
            ok = image_writer_put_exr_chunk(w, b, len, image_tile_rect(t),
                                            err, sizeof err);
            free(b);
        } else {
            ok = image_writer_put_tile(w, t, err, sizeof err);
        }
        if (!ok)
            fail_msg("tile (%d,%d): %s", tx, ty, err);
        image_tile_destroy(&t);
    }
    free(order);
    assert_int_equal(image_writer_tiles_written(w), n);
    if (!image_writer_finish(&w, err, sizeof err))
        fail_msg("finish: %s", err);
    assert_null(w);
}

/* The read-back image must hold the tiles' values: HALF channels rounded
 * to binary16, FLOAT channels exact. */
static void check_pixels(const image_buffer *img, const image_format *fmt,
                         uint64_t seed)
{
    assert_int_equal(img->x0, 0);
    assert_int_equal(img->y0, 0);
    assert_int_equal(img->width, fmt->width);
    assert_int_equal(img->height, fmt->height);
    assert_int_equal(img->channel_count, image_format_channel_count(fmt));
    for (int ty = 0; ty < image_format_tiles_y(fmt); ty++) {
        for (int tx = 0; tx < image_format_tiles_x(fmt); tx++) {
            image_tile *t = tu_tile(fmt, tx, ty, seed, (tx + ty) % 3 == 0);
            for (int c = 0; c < img->channel_count; c++) {
                const image_channel *ch = image_format_channel(fmt, c);
                assert_string_equal(img->names[c], ch->name);
                const float *src = ch->source == IMAGE_SOURCE_RGBA ? t->rgba
                                   : ch->source == IMAGE_SOURCE_Z ? t->z
                                   : ch->source == IMAGE_SOURCE_N ? t->n : t->p;
                int k = image_source_floats(ch->source);
                for (int y = 0; y < t->h; y++) {
                    for (int x = 0; x < t->w; x++) {
                        float in = src[(size_t) (y * t->w + x) * (size_t) k
                                       + (size_t) ch->component];
                        float want = ch->type == IMAGE_PIXEL_HALF
                                     ? tu_half_round(in) : in;
                        float got = img->planes[c][(size_t) (t->y0 + y)
                                                   * (size_t) img->width
                                                   + (size_t) (t->x0 + x)];
                        if (memcmp(&got, &want, sizeof got) != 0)
                            fail_msg("%s at (%d,%d): got %.9g want %.9g "
                                     "(input %.9g)", ch->name, t->x0 + x,
                                     t->y0 + y, got, want, in);
                    }
                }
            }
            image_tile_destroy(&t);
        }
    }
}

static const image_format formats[] = {
    {100, 70, 32, IMAGE_LAYERS_ALL},   /* edge tiles 4 wide, 6 high */
    {33, 17, 16, 0},                   /* 1-pixel-wide last column */
    {5, 3, 8, IMAGE_LAYER_N},          /* one partial tile */
    {64, 64, 64, IMAGE_LAYER_P},       /* one full tile */
};

static void test_roundtrip(void **state)
{
    char *dir = *state;
    for (size_t f = 0; f < sizeof formats / sizeof formats[0]; f++) {
        const char *out = tu_path(dir, "out.exr");
        write_image(out, &formats[f], 10 + f, true, false);
        image_buffer *img = image_buffer_read_exr(out, err, sizeof err);
        if (!img)
            fail_msg("read back: %s", err);
        check_pixels(img, &formats[f], 10 + f);
        image_buffer_destroy(&img);
        assert_null(img);
        assert_int_equal(tu_dir_entries(dir), 1);
    }
}

/* The packed chunk of tile (tx, ty) of an EXR file, read raw. */
static uint8_t *raw_chunk(const char *path, int tx, int ty, size_t *len)
{
    exr_context_t ctxt = NULL;
    exr_chunk_info_t ci;
    assert_int_equal(exr_start_read(&ctxt, path, NULL), EXR_ERR_SUCCESS);
    assert_int_equal(exr_read_tile_chunk_info(ctxt, 0, tx, ty, 0, 0, &ci),
                     EXR_ERR_SUCCESS);
    uint8_t *b = malloc(ci.packed_size ? ci.packed_size : 1);
    assert_int_equal(exr_read_chunk(ctxt, 0, &ci, b), EXR_ERR_SUCCESS);
    *len = ci.packed_size;
    exr_finish(&ctxt);
    return b;
}

static void test_chunk_copy_is_verbatim(void **state)
{
    char *dir = *state;
    const image_format *fmt = &formats[0];
    const char *out = tu_path(dir, "out.exr");
    write_image(out, fmt, 3, true, true);
    for (int ty = 0; ty < image_format_tiles_y(fmt); ty++) {
        for (int tx = 0; tx < image_format_tiles_x(fmt); tx++) {
            image_tile *t = tu_tile(fmt, tx, ty, 3, (tx + ty) % 3 == 0);
            size_t len, chunk_len, file_len;
            uint8_t *b = encode_tile(t, fmt, &len);
            const void *chunk;
            assert_true(image_tile_exr_chunk(b, len, fmt, image_tile_rect(t),
                                             &chunk, &chunk_len, err,
                                             sizeof err));
            uint8_t *in_file = raw_chunk(out, tx, ty, &file_len);
            assert_int_equal(file_len, chunk_len);
            assert_memory_equal(in_file, chunk, chunk_len);
            free(in_file);
            free(b);
            image_tile_destroy(&t);
        }
    }
}

static void test_any_order(void **state)
{
    char *dir = *state;
    tu_seed(2024);
    for (size_t f = 0; f < sizeof formats / sizeof formats[0]; f++) {
        const image_format *fmt = &formats[f];
        const char *a = tu_path(dir, "inorder.exr");
        const char *b = tu_path(dir, "shuffled.exr");
        write_image(a, fmt, 5, true, false);
        write_image(b, fmt, 5, true, true);
        image_buffer *ia = image_buffer_read_exr(a, err, sizeof err);
        image_buffer *ib = image_buffer_read_exr(b, err, sizeof err);
        assert_non_null(ia);
        assert_non_null(ib);
        image_diff d;
        assert_true(image_buffer_compare(ia, ib, 0.0, &d, err, sizeof err));
        assert_int_equal(d.count, 0);
        for (int ty = 0; ty < image_format_tiles_y(fmt); ty++) {
            for (int tx = 0; tx < image_format_tiles_x(fmt); tx++) {
                size_t la, lb;
                uint8_t *ca = raw_chunk(a, tx, ty, &la);
                uint8_t *cb = raw_chunk(b, tx, ty, &lb);
                assert_int_equal(la, lb);
                assert_memory_equal(ca, cb, la);
                free(ca);
                free(cb);
            }
        }
        image_buffer_destroy(&ia);
        image_buffer_destroy(&ib);
    }
}

static void test_two_paths_identical(void **state)
{
    char *dir = *state;
    tu_seed(77);
    for (size_t f = 0; f < sizeof formats / sizeof formats[0]; f++) {
        const char *a = tu_path(dir, "copy.exr");
        const char *b = tu_path(dir, "put.exr");
        write_image(a, &formats[f], 9, true, false);
        write_image(b, &formats[f], 9, false, false);
        size_t la, lb;
        uint8_t *fa = tu_read_file(a, &la), *fb = tu_read_file(b, &lb);
        assert_non_null(fa);
        assert_non_null(fb);
        assert_int_equal(la, lb);
        assert_memory_equal(fa, fb, la);
        free(fa);
        free(fb);
    }
}

static void put_some(image_writer *w, const image_format *fmt, int count)
{
    for (int i = 0; i < count; i++) {
        image_tile *t = tu_tile(fmt, i % image_format_tiles_x(fmt),
                                i / image_format_tiles_x(fmt), 1, false);
        assert_true(image_writer_put_tile(w, t, err, sizeof err));
        image_tile_destroy(&t);
    }
}

static void test_finish_and_abort(void **state)
{
    char *dir = *state;
    const image_format *fmt = &formats[1];   /* 3 x 2 tiles */
    const char *out = tu_path(dir, "final.exr");

    /* abort: nothing left behind */
    image_writer *w = image_writer_new(out, fmt, err, sizeof err);
    assert_non_null(w);
    char temp[1024];
    snprintf(temp, sizeof temp, "%s", image_writer_temp_path(w));
    assert_non_null(strstr(temp, "final.exr.tmp-"));
    assert_true(tu_file_exists(temp));
    assert_false(tu_file_exists(out));
    put_some(w, fmt, 4);
    image_writer_destroy(&w);
    assert_null(w);
    assert_int_equal(tu_dir_entries(dir), 0);

    /* finish: exactly the final file */
    write_image(out, fmt, 1, false, false);
    assert_int_equal(tu_dir_entries(dir), 1);
    assert_false(tu_file_exists(temp));
    size_t len_before;
    uint8_t *before = tu_read_file(out, &len_before);

    /* an aborted rewrite leaves the existing file as it was */
    w = image_writer_new(out, fmt, err, sizeof err);
    assert_non_null(w);
    put_some(w, fmt, 6);
    image_writer_destroy(&w);
    size_t len_after;
    uint8_t *after = tu_read_file(out, &len_after);
    assert_int_equal(len_before, len_after);
    assert_memory_equal(before, after, len_before);
    assert_int_equal(tu_dir_entries(dir), 1);
    free(before);
    free(after);

    /* finish too early: refused, nothing lost, then completed */
    w = image_writer_new(out, fmt, err, sizeof err);
    put_some(w, fmt, 4);
    assert_false(image_writer_finish(&w, err, sizeof err));
    assert_non_null(w);
    assert_non_null(strstr(err, "2 of 6 tiles missing, first tile (1,1)"));
    assert_true(tu_file_exists(temp));
    assert_false(image_writer_has_tile(w, 1, 1));
    assert_true(image_writer_has_tile(w, 0, 1));
    put_some(w, fmt, 6);                      /* 4 duplicates, 2 new */
    assert_int_equal(image_writer_tiles_written(w), 6);
    assert_true(image_writer_finish(&w, err, sizeof err));
    assert_null(w);
    assert_int_equal(tu_dir_entries(dir), 1);
    image_buffer *img = image_buffer_read_exr(out, err, sizeof err);
    assert_non_null(img);
    image_buffer_destroy(&img);
}

static void test_rejects(void **state)
{
    char *dir = *state;
    const image_format *fmt = &formats[0];
    const char *out = tu_path(dir, "out.exr");
    image_writer *w = image_writer_new(out, fmt, err, sizeof err);
    assert_non_null(w);
    image_rect r00 = image_format_tile_rect(fmt, 0, 0);
    image_rect r10 = image_format_tile_rect(fmt, 1, 0);

    assert_false(image_writer_put_exr_chunk(w, "garbage", 7, r00, err,
                                            sizeof err));
    assert_non_null(strstr(err, "bad magic"));
    image_tile *t = tu_tile(fmt, 1, 0, 4, false);
    size_t len;
    uint8_t *b = encode_tile(t, fmt, &len);
    /* a good tile offered for the wrong position */
    assert_false(image_writer_put_exr_chunk(w, b, len, r00, err, sizeof err));
    assert_non_null(strstr(err, "dataWindow"));
    assert_int_equal(image_writer_tiles_written(w), 0);
    /* accepted at its own position, twice (the second is ignored) */
    assert_true(image_writer_put_exr_chunk(w, b, len, r10, err, sizeof err));
    assert_true(image_writer_put_exr_chunk(w, b, len, r10, err, sizeof err));
    assert_int_equal(image_writer_tiles_written(w), 1);
    assert_true(image_writer_has_tile(w, 1, 0));
    /* a tile with other layers */
    image_tile *plain = image_tile_new(0, 0, 32, 32, 0);
    assert_false(image_writer_put_tile(w, plain, err, sizeof err));
    assert_non_null(strstr(err, "layers"));
    image_tile_destroy(&plain);
    free(b);
    image_tile_destroy(&t);
    image_writer_destroy(&w);
    assert_int_equal(tu_dir_entries(dir), 0);

    /* bad output paths and formats */
    assert_null(image_writer_new("/nonexistent-aafarm-dir/out.exr", fmt, err,
                                 sizeof err));
    assert_non_null(strstr(err, "/nonexistent-aafarm-dir/out.exr.tmp-"));
    assert_non_null(strstr(err, "No such file or directory"));
    image_format bad = {0, 10, 32, 0};
    assert_null(image_writer_new(out, &bad, err, sizeof err));
    assert_non_null(strstr(err, "image size 0x10"));
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

/* Each test gets an empty scratch directory. */
#define T(fn) cmocka_unit_test_setup_teardown(fn, make_dir, remove_dir)

int main(void)
{
    const struct CMUnitTest tests[] = {
        T(test_roundtrip),
        T(test_chunk_copy_is_verbatim),
        T(test_any_order),
        T(test_two_paths_identical),
        T(test_finish_and_abort),
        T(test_rejects),
    };
    return cmocka_run_group_tests_name("image_writer", tests, NULL, NULL);
}

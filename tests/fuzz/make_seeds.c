/*
 * tests/fuzz/make_seeds.c: writes the binary seeds of the protocol and
 * tile fuzz targets (tests/fuzz/corpus/proto and corpus/tile), so that
 * they can be made again from the code instead of being opaque files:
 *   build-test/bin/fuzz_make_seeds tests/fuzz/corpus
 * Protocol seeds: every message a worker sends, valid (tests/proto
 * samples), in fuzz_proto.c's framing. Tile seeds: the expected tile of
 * fuzz_tile.c's image for each layer set, and the tile of another place.
 * The RIB and shading-language seeds are text files written by hand.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/format.h"
#include "image/tile.h"
#include "samples.h"

static int write_seed(const char *dir, const char *name, const uint8_t *prefix,
                      size_t nprefix, const void *body, size_t len)
{
    char path[4096];
    int n = snprintf(path, sizeof path, "%s/%s", dir, name);
    if (n < 0 || (size_t)n >= sizeof path) {
        fprintf(stderr, "%s/%s: path too long\n", dir, name);
        return -1;
    }
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        return -1;
    }
    fwrite(prefix, 1, nprefix, f);
    fwrite(body, 1, len, f);
    if (fclose(f) != 0) {
        perror(path);
        return -1;
    }
    return 0;
}

static int proto_seeds(const char *dir)
{
    for (size_t i = 0; i < sizeof sample_kinds / sizeof sample_kinds[0]; i++) {
        proto_kind kind = sample_kinds[i];
        if (!proto_message_from_worker(kind))
            continue;
        sample *s = calloc(1, sizeof *s);
        sample_make(s, kind);
        size_t len = 0;
        uint8_t *packed = sample_pack(&s->env, &len);
        uint8_t prefix[2] = { proto_message_has_bulk(kind) ? 1 : 0, 16 };
        char name[64];
        snprintf(name, sizeof name, "%s.bin", proto_message_name(kind));
        int rc = write_seed(dir, name, prefix, 2, packed, len);
        free(packed);
        free(s);
        if (rc != 0)
            return -1;
    }
    return 0;
}

static int tile_seeds(const char *dir)
{
    for (unsigned layers = 0; layers <= IMAGE_LAYERS_ALL; layers++) {
        image_format fmt = { .width = 48, .height = 40, .tile_size = 32, .layers = layers };
        for (int t = 0; t < 2; t++) {
            image_rect r = image_format_tile_rect(&fmt, t, t);
            image_tile *tile = image_tile_new(r.x0, r.y0, r.w, r.h, layers);
            void *bytes = NULL;
            size_t len = 0;
            char err[256];
            if (!image_tile_encode_exr(tile, &fmt, &bytes, &len, err, sizeof err)) {
                fprintf(stderr, "encode: %s\n", err);
                image_tile_destroy(&tile);
                return -1;
            }
            uint8_t prefix = (uint8_t)layers;
            char name[64];
            snprintf(name, sizeof name, "tile%d-layers%u.exr", t, layers);
            int rc = write_seed(dir, name, &prefix, 1, bytes, len);
            free(bytes);
            image_tile_destroy(&tile);
            if (rc != 0)
                return -1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s CORPUS-FOLDER (tests/fuzz/corpus)\n", argv[0]);
        return 2;
    }
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/proto", argv[1]);
    if (proto_seeds(dir) != 0)
        return 1;
    snprintf(dir, sizeof dir, "%s/tile", argv[1]);
    if (tile_seeds(dir) != 0)
        return 1;
    return 0;
}

/*
 * tests/fuzz/fuzz_tile.c: fuzz target for the master's tile validator
 * (common/image/tile.c image_tile_exr_chunk, what master/farm_messages.c
 * runs on every tile a worker returns). The input's first byte picks the
 * layers of the image (its low two bits: IMAGE_LAYER_N, IMAGE_LAYER_P); the
 * rest is the tile file. The image is 48 x 40 pixels in tiles of 32, and
 * the expected tile is the partial one at (1, 1): 16 x 8 pixels at (32, 32).
 * Checked: image_tile_validate_exr agrees with image_tile_exr_chunk; an
 * accepted tile's chunk lies inside the input; a refusal says why.
 */
#include <string.h>

#include "fuzz_target.h"
#include "image/format.h"
#include "image/tile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    image_format fmt = { .width = 48, .height = 40, .tile_size = 32,
                         .layers = data[0] & IMAGE_LAYERS_ALL };
    image_rect expect = image_format_tile_rect(&fmt, 1, 1);
    const uint8_t *bytes = data + 1;
    size_t len = size - 1;

    char err[256] = "", err2[256] = "";
    const void *chunk = NULL;
    size_t chunk_len = 0;
    bool ok = image_tile_exr_chunk(bytes, len, &fmt, expect, &chunk, &chunk_len, err,
                                   sizeof err);
    bool valid = image_tile_validate_exr(bytes, len, &fmt, expect, err2, sizeof err2);
    fuzz_check(ok == valid);
    if (ok) {
        fuzz_check(chunk != NULL && chunk_len > 0);
        const uint8_t *c = chunk;
        fuzz_check(c >= bytes && c + chunk_len <= bytes + len);
    } else {
        fuzz_check(err[0] != '\0' && err2[0] != '\0');
    }
    return 0;
}

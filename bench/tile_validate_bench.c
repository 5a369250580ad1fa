/*
 * bench/tile_validate_bench.c: what the master pays to validate one tile
 * it receives (image_tile_exr_chunk: header compared, framing checked,
 * the chunk decompressed), for tiles of 32, 128 and 512 pixels with
 * smooth (compressible) and noisy content. Prints a table; never asserts.
 *
 *   tile_validate_bench [--quick]
 *
 * Also prints, as the peer, the cost of encoding the same tile (what a
 * worker pays), so the master's share can be read as a fraction of the
 * work per tile. Timing: CLOCK_PROCESS_CPUTIME_ID, best of 3 rounds.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "image/format.h"
#include "image/tile.h"

static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static uint64_t rng = 88172645463325252ull;

static float next_uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (float)(rng >> 40) / (float)(1u << 24);
}

static void fill(image_tile *t, bool noisy)
{
    for (int y = 0; y < t->h; y++)
        for (int x = 0; x < t->w; x++) {
            size_t i = (size_t)y * (size_t)t->w + (size_t)x;
            float s = 0.5f + 0.5f * sinf((float)(t->x0 + x) * 0.05f) * cosf((float)(t->y0 + y) * 0.03f);
            for (int c = 0; c < 3; c++) t->rgba[i * 4 + (size_t)c] = noisy ? next_uniform() : s * (0.6f + 0.2f * (float)c);
            t->rgba[i * 4 + 3] = 1.0f;
            t->z[i] = noisy ? 1.0f + 10.0f * next_uniform() : 3.0f + s;
        }
}

int main(int argc, char **argv)
{
    bool quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    const int sizes[] = {32, 128, 512};
    printf("tile validation on the master (image_tile_exr_chunk), CPU ms per tile, best of 3\n");
    printf("%6s %8s %10s %12s %12s %14s\n", "tile", "content", "EXR bytes", "validate ms",
           "encode ms", "validate MB/s");
    for (int si = 0; si < 3; si++) {
        int s = sizes[si];
        image_format fmt = {s * 4, s * 4, s, 0};
        image_rect r = {s, s, s, s};
        for (int noisy = 0; noisy < 2; noisy++) {
            image_tile *t = image_tile_new(r.x0, r.y0, r.w, r.h, 0);
            fill(t, noisy);
            void *bytes = NULL;
            size_t len = 0;
            char err[512];
            int reps = (quick ? 2 : 20) * (512 / s) * (512 / s) / (s == 512 ? 1 : 4);
            if (reps < 2) reps = 2;
            double best_v = 1e30, best_e = 1e30;
            for (int round = 0; round < 3; round++) {
                double t0 = cpu_s();
                for (int i = 0; i < reps; i++) {
                    free(bytes);
                    if (!image_tile_encode_exr(t, &fmt, &bytes, &len, err, sizeof err)) {
                        fprintf(stderr, "encode: %s\n", err);
                        return 1;
                    }
                }
                double t1 = cpu_s();
                for (int i = 0; i < reps; i++) {
                    const void *chunk;
                    size_t clen;
                    if (!image_tile_exr_chunk(bytes, len, &fmt, r, &chunk, &clen, err, sizeof err)) {
                        fprintf(stderr, "validate: %s\n", err);
                        return 1;
                    }
                }
                double t2 = cpu_s();
                if ((t1 - t0) / reps < best_e) best_e = (t1 - t0) / reps;
                if ((t2 - t1) / reps < best_v) best_v = (t2 - t1) / reps;
            }
            printf("%6d %8s %10zu %12.3f %12.3f %14.0f\n", s, noisy ? "noisy" : "smooth", len,
                   best_v * 1e3, best_e * 1e3,
                   (double)s * s * image_format_pixel_bytes(&fmt) / best_v / 1e6);
            free(bytes);
            image_tile_destroy(&t);
        }
    }
    return 0;
}

/*
 * tests/image/image_testutil.h: helpers shared by the common/image tests:
 * a fixed-seed random generator, scratch directories, random tiles, a
 * reference float->half rounding and whole-file reads.
 *
 * The reference rounding is computed with double arithmetic from the
 * definition of IEEE 754 binary16 (10 fraction bits, exponents -14..15,
 * subnormal spacing 2^-24, round to nearest, ties to even, overflow to
 * infinity at 65520), independently of OpenEXR's bit manipulation.
 */
#ifndef IMAGE_TESTUTIL_H
#define IMAGE_TESTUTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image/format.h"
#include "image/tile.h"

void tu_seed(uint64_t seed);
uint64_t tu_next(void);
/* Uniform in [0, n). */
uint32_t tu_below(uint32_t n);
/* Uniform in [lo, hi). */
float tu_uniform(float lo, float hi);

/* Fills a tile with random values: RGBA in [-0.5, 4) with some exact
 * halves, Z in (0, 1000) with a few +inf, N and P in [-100, 100). */
void tu_fill_random(image_tile *tile);
/* Fills a tile with smooth values (compressible: ZIP really compresses). */
void tu_fill_smooth(image_tile *tile);

/* The binary16 value nearest to f (ties to even), as a float. */
float tu_half_round(float f);

/* A fresh scratch directory (mkdtemp) and its removal with its files. */
char *tu_make_dir(void);
void tu_remove_dir(char **dir_p);
/* dir "/" name in a static rotating buffer. */
const char *tu_path(const char *dir, const char *name);
/* Number of entries in dir other than . and .. */
int tu_dir_entries(const char *dir);
bool tu_file_exists(const char *path);
/* Whole file into memory (malloc'd); NULL if unreadable. */
uint8_t *tu_read_file(const char *path, size_t *len);
bool tu_write_file(const char *path, const void *bytes, size_t len);

/* Tile (tx, ty) of fmt with random (or smooth) content; seeds the values
 * from (seed, tx, ty) so the same call gives the same tile. */
image_tile *tu_tile(const image_format *fmt, int tx, int ty, uint64_t seed,
                    bool smooth);

#endif

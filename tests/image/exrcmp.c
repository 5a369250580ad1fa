/*
 * tests/image/exrcmp.c: compare two EXR files pixel by pixel.
 *
 *     exrcmp A.exr B.exr [tolerance]
 *
 * Reads both files completely (image_buffer_read_exr) and compares every
 * sample of every channel (image_buffer_compare: NaN equals NaN, samples
 * equal when |a - b| <= tolerance, default 0). Prints one line. Exit
 * status: 0 equal, 1 different, 2 error (unreadable file, different size
 * or channels, bad arguments). Meant for shell-level tests, e.g. checking
 * that a farm render equals the standalone render.
 */
#include <stdio.h>
#include <stdlib.h>

#include "image/buffer.h"

static int usage(void)
{
    fprintf(stderr, "usage: exrcmp A.exr B.exr [tolerance]\n");
    return 2;
}

static int compare(const image_buffer *a, const image_buffer *b,
                   double tolerance)
{
    char err[512];
    image_diff diff;
    if (!image_buffer_compare(a, b, tolerance, &diff, err, sizeof err)) {
        fprintf(stderr, "exrcmp: %s\n", err);
        return 2;
    }
    if (diff.count == 0) {
        printf("equal\n");
        return 0;
    }
    printf("%zu samples differ; largest |difference| %g in channel %s at "
           "pixel (%d,%d)\n", diff.count, diff.max_abs, diff.channel, diff.x,
           diff.y);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 4)
        return usage();
    double tolerance = 0.0;
    if (argc == 4) {
        char *end;
        tolerance = strtod(argv[3], &end);
        if (*end != '\0' || !(tolerance >= 0.0))
            return usage();
    }
    char err[512];
    image_buffer *a = image_buffer_read_exr(argv[1], err, sizeof err);
    if (!a) {
        fprintf(stderr, "exrcmp: %s\n", err);
        return 2;
    }
    image_buffer *b = image_buffer_read_exr(argv[2], err, sizeof err);
    if (!b) {
        fprintf(stderr, "exrcmp: %s\n", err);
        image_buffer_destroy(&a);
        return 2;
    }
    int rc = compare(a, b, tolerance);
    image_buffer_destroy(&a);
    image_buffer_destroy(&b);
    return rc;
}

/*
 * peers_compare.c: pixels of a peer's image that differ from a reference
 * (bench/peers/): both 16-bit linear RGBA PNGs of the same size (peers_png.h),
 * one ray per pixel, so alpha is the hit mask.
 *
 *   peers_compare TEST.png REF.png [--tol T] [--diff OUT.png]
 *
 * A pixel differs as peers_diff.h says, with tol T (default 8/255, a
 * visible step in an 8-bit image). Prints one line:
 * "differ D holes M extra E colour C pixels P", where holes are pixels the
 * reference hits and TEST misses, extra the reverse, colour the pixels hit
 * in both whose colour differs. --diff writes a picture of them: TEST's
 * grey level, holes red, extra pixels blue, colour differences yellow.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "peers_diff.h"
#include "peers_png.h"

int main(int argc, char **argv)
{
    double tol = 8.0 / 255.0;
    const char *diff = NULL;
    if (argc < 3) {
        fprintf(stderr, "usage: peers_compare TEST.png REF.png [--tol T] [--diff OUT.png]\n");
        return 2;
    }
    for (int i = 3; i < argc; i++) {
        char *end = NULL;
        if (strcmp(argv[i], "--tol") == 0 && i + 1 < argc) {
            tol = strtod(argv[++i], &end);
            if (*end || !(tol >= 0)) {
                fprintf(stderr, "peers_compare: --tol wants a number >= 0, got '%s'\n", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--diff") == 0 && i + 1 < argc) {
            diff = argv[++i];
        } else {
            fprintf(stderr, "usage: peers_compare TEST.png REF.png [--tol T] [--diff OUT.png]\n");
            return 2;
        }
    }
    char err[512];
    int w, h, rw, rh;
    float *a = NULL, *b = NULL;
    if (!peers_png_read(argv[1], &w, &h, &a, err, sizeof err) ||
        !peers_png_read(argv[2], &rw, &rh, &b, err, sizeof err)) {
        fprintf(stderr, "peers_compare: %s\n", err);
        free(a);
        return 1;
    }
    if (w != rw || h != rh) {
        fprintf(stderr, "peers_compare: %s is %dx%d but the reference %s is %dx%d: render both at one size\n",
                argv[1], w, h, argv[2], rw, rh);
        free(a);
        free(b);
        return 1;
    }
    float *pic = diff ? calloc((size_t)w * (size_t)h * 4, sizeof *pic) : NULL;
    if (diff && !pic) abort();
    peers_diff d = peers_diff_images(a, b, w, h, tol, pic);
    if (pic) {
        if (!peers_png_write(diff, w, h, pic, err, sizeof err))
            fprintf(stderr, "peers_compare: %s\n", err);
        free(pic);
    }
    printf("differ %ld holes %ld extra %ld colour %ld pixels %ld\n", d.holes + d.extra + d.colour,
           d.holes, d.extra, d.colour, (long)w * h);
    free(a);
    free(b);
    return 0;
}

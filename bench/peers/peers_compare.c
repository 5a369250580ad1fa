/*
 * peers_compare.c: pixels of a peer's image that differ from a reference
 * (bench/peers/): both 16-bit linear RGBA PNGs of the same size (peers_png.h),
 * one ray per pixel, so alpha is the hit mask.
 *
 *   peers_compare TEST.png REF.png [--tol T] [--diff OUT.png]
 *
 * A pixel differs when its hit mask differs (alpha on different sides of
 * 1/2) or, hit in both, when a colour channel differs by more than T
 * (default 8/255, a visible step in an 8-bit image). Prints one line:
 * "differ D holes M extra E colour C pixels P", where holes are pixels the
 * reference hits and TEST misses, extra the reverse, colour the pixels hit
 * in both whose colour differs. --diff writes a picture of them: TEST's
 * grey level, holes red, extra pixels blue, colour differences yellow.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    long holes = 0, extra = 0, colour = 0;
    float *pic = diff ? calloc((size_t)w * (size_t)h * 4, sizeof *pic) : NULL;
    if (diff && !pic) abort();
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        const float *p = &a[i * 4], *q = &b[i * 4];
        int hp = p[3] > 0.5f, hq = q[3] > 0.5f, kind = 0;
        if (hq && !hp) holes++, kind = 1;
        else if (hp && !hq) extra++, kind = 2;
        else if (hp && hq) {
            for (int k = 0; k < 3; k++)
                if (fabs((double)p[k] - (double)q[k]) > tol) {
                    colour++, kind = 3;
                    break;
                }
        }
        if (pic) {
            static const float mark[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {1, 1, 0}};
            float grey = (p[0] + p[1] + p[2]) / 3;
            for (int k = 0; k < 3; k++) pic[i * 4 + k] = kind ? mark[kind][k] : grey;
            pic[i * 4 + 3] = 1;
        }
    }
    if (pic) {
        if (!peers_png_write(diff, w, h, pic, err, sizeof err))
            fprintf(stderr, "peers_compare: %s\n", err);
        free(pic);
    }
    printf("differ %ld holes %ld extra %ld colour %ld pixels %ld\n", holes + extra + colour,
           holes, extra, colour, (long)w * h);
    free(a);
    free(b);
    return 0;
}

/*
 * aafarm-maketx: turns an image into a texture file with its pyramids
 * built in advance (like txmake / maketx), or writes a generated fBm
 * height map (for the terrain scene; docs/textures.md).
 *
 *   aafarm-maketx [--no-minmax] IN.{exr,png,tif} OUT.exr
 *   aafarm-maketx --fbm WIDTH HEIGHT [--octaves N] [--seed N] OUT.exr
 *
 * Exit status 0 on success, 1 when a file cannot be read or written, 2 on
 * a usage error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl/noise.h"
#include "tex/tex.h"
#include "util/cli.h"
#include "util/err.h"
#include "util/parse_num.h"
#include "util/xalloc.h"

static void usage(FILE *out)
{
    fputs("usage: aafarm-maketx [--no-minmax] IN.{exr,png,tif} OUT.exr\n"
          "       aafarm-maketx --fbm WIDTH HEIGHT [--octaves N] [--seed N] OUT.exr\n"
          "  Writes a tiled, mip-mapped OpenEXR texture: part \"mean\" (the levels the\n"
          "  filter reads) and parts \"min\" and \"max\" (the min-max pyramid that bounds\n"
          "  it), 32-bit float, 64x64 tiles (docs/textures.md).\n"
          "  --no-minmax   write the \"mean\" part only\n"
          "  --fbm W H     instead of reading an image, write a periodic fBm height\n"
          "                map of W x H texels, one channel, values about -1..1\n"
          "  --octaves N   fBm octaves (default 6)\n"
          "  --seed N      fBm seed (default 1)\n",
          out);
}

/* Periodic fBm: sum over octaves of 0.5^o (2 pnoise - 1) at 4 * 2^o cells
 * across the map, each octave periodic over the map (so it tiles). */
static tex_texture *fbm(int w, int h, int octaves, long seed)
{
    float *px = xmalloc((size_t)w * h * sizeof *px);
    double off = 17.31 * (double)seed;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            double sum = 0, amp = 1;
            for (int o = 0; o < octaves; o++) {
                int cells = 4 << o;
                double p[2] = { (i + 0.5) / w * cells + off, (j + 0.5) / h * cells + off * 0.7 };
                int per[2] = { cells, cells };
                sum += amp * (2 * sl_pnoise(2, p, per) - 1);
                amp *= 0.5;
            }
            px[(size_t)j * w + i] = (float)sum;
        }
    tex_texture *t = tex_from_pixels(px, w, h, 1, "fbm");
    free(px);
    return t;
}

int main(int argc, char **argv)
{
    bool minmax = true;
    long fbm_w = 0, fbm_h = 0, octaves = 6, seed = 1;
    const char *files[2];
    int nfiles = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--version") == 0) {
            printf("aafarm-maketx %s\n", cli_version());
            return 0;
        } else if (strcmp(a, "--no-minmax") == 0) {
            minmax = false;
        } else if (strcmp(a, "--fbm") == 0) {
            if (i + 2 >= argc || !parse_long_within(argv[i + 1], 1, 1 << 16, &fbm_w) ||
                !parse_long_within(argv[i + 2], 1, 1 << 16, &fbm_h)) {
                fprintf(stderr, "aafarm-maketx: --fbm takes a width and a height of 1 to "
                                "65536 texels\n");
                return 2;
            }
            i += 2;
        } else if (strcmp(a, "--octaves") == 0 || strcmp(a, "--seed") == 0) {
            long *dst = a[2] == 'o' ? &octaves : &seed;
            if (i + 1 >= argc || !parse_long_within(argv[i + 1], a[2] == 'o' ? 1 : 0,
                                                    a[2] == 'o' ? 16 : 1000000, dst)) {
                fprintf(stderr, "aafarm-maketx: %s takes %s\n", a,
                        a[2] == 'o' ? "1 to 16 octaves" : "a seed from 0 to 1000000");
                return 2;
            }
            i++;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "aafarm-maketx: unknown option '%s' (see --help)\n", a);
            return 2;
        } else if (nfiles < 2) {
            files[nfiles++] = a;
        } else {
            fprintf(stderr, "aafarm-maketx: too many file names (see --help)\n");
            return 2;
        }
    }
    int want = fbm_w ? 1 : 2;
    if (nfiles != want) {
        fprintf(stderr, "aafarm-maketx: %s\n", fbm_w ? "--fbm takes one output file"
                                                     : "give an input image and an output file");
        usage(stderr);
        return 2;
    }
    const char *out = files[want - 1];
    char err[ERR_LEN];
    tex_texture *t = fbm_w ? fbm((int)fbm_w, (int)fbm_h, (int)octaves, seed)
                           : tex_open(files[0], err, sizeof err);
    if (!t) {
        fprintf(stderr, "aafarm-maketx: %s\n", fbm_w ? "out of memory" : err);
        return 1;
    }
    if (!tex_write_exr(out, t, minmax, err, sizeof err)) {
        fprintf(stderr, "aafarm-maketx: %s\n", err);
        tex_destroy(&t);
        return 1;
    }
    double lo, hi;
    /* every lookup at the finest footprint: the texels' range (a footprint
     * the size of the map would read the top level, the mean, alone) */
    tex_range all = { { 0, 1 }, { 0, 1 }, { 0, 0 }, { 0, 0 } };
    tex_bound(t, 0, &all, TEX_WRAP_CLAMP, TEX_WRAP_CLAMP, 0, &lo, &hi);
    printf("%s: %d x %d, %d channel%s, %d levels, channel 0 in [%g, %g]\n", out, tex_width(t),
           tex_height(t), tex_channels(t), tex_channels(t) == 1 ? "" : "s", tex_levels(t), lo,
           hi);
    tex_destroy(&t);
    return 0;
}

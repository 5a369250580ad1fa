/*
 * tests/worker/test_worker_opacity.c: opacity from a texture channel, as
 * exporters' shaders write it (`Oi = Os * float texture(map[3], s, t)`),
 * rendered by a real aafarm-worker --standalone from maps made by a real
 * aafarm-maketx (issue 26):
 *
 *   - an RGBA map, opaque in its left half (s < 0.5), clear in its right:
 *     the image's alpha follows (left columns 1, right columns 0);
 *   - TextureCoordinates 1 0 0 0 1 1 0 1 (s mirrored) swaps the halves;
 *   - an RGB map has no alpha: channel 3 reads 1 (opaque, RI Spec 3.2's
 *     texture access parameters), not 0 (it was: fully transparent), and
 *     with "fill" 0.25 the shader's fill.
 *
 * argv[1]: the aafarm-worker binary; argv[2]: aafarm-maketx.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>

#include "image/buffer.h"
#include "tex/tex.h"

static const char *worker, *maketx;
static char dir[256];

static void write_file(const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* runs `prog args` in dir (at most 60 s), output in out; the exit status */
static int run(const char *prog, const char *args, char *out, size_t outsz)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "cd %s && timeout -k 5 60 '%s' %s 2>&1", dir, prog, args);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, outsz - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* an 8 x 8 map of nch channels (red; alpha 1 for s < 0.5, else 0) written
 * as a plain EXR, then made a texture by aafarm-maketx */
static int make_map(const char *name, int nch)
{
    float px[8 * 8 * 4];
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++) {
            float *p = &px[(j * 8 + i) * nch];
            p[0] = 0.8f;
            p[1] = p[2] = 0.2f;
            if (nch == 4)
                p[3] = i < 4 ? 1.0f : 0.0f;
        }
    tex_texture *t = tex_from_pixels(px, 8, 8, nch, name);
    char src[512], err[256], out[4096], args[600];
    snprintf(src, sizeof src, "%s/src_%s", dir, name);
    bool ok = t && tex_write_exr(src, t, false, err, sizeof err);
    tex_destroy(&t);
    if (!ok)
        return -1;
    snprintf(args, sizeof args, "src_%s %s", name, name);
    if (run(maketx, args, out, sizeof out) != 0) {
        fprintf(stderr, "%s", out);
        return -1;
    }
    return 0;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-opacity-XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    write_file("cutout.sl",
               "surface cutout(string map = \"\"; float fill = -1)\n{\n"
               "    float a;\n"
               "    if (fill >= 0)\n"
               "        a = float texture(map[3], s, t, \"fill\", fill);\n"
               "    else\n"
               "        a = float texture(map[3], s, t);\n"
               "    Oi = Os * a;\n"
               "    Ci = Oi * color texture(map, s, t);\n}\n");
    return make_map("rgba.exr", 4) || make_map("rgb.exr", 3);
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Renders a 16 x 16 image of a square twice the frame (s in 0.25..0.75 seen) with the cutout shader on
 * map (its parameters after it: `params`); the mean alpha of the four
 * left and the four right columns. */
static void render(const char *map, const char *params, const char *extra, double *left,
                   double *right)
{
    char rib[2048], out[8192];
    snprintf(rib, sizeof rib,
             "Option \"searchpath\" \"shader\" [\".\"]\n"
             "Format 16 16 1\nPixelSamples 2 2\n"
             "Projection \"orthographic\"\nScreenWindow -1 1 -1 1\n"
             "WorldBegin\n"
             "Translate 0 0 1\n"
             "%s\n"
             "Surface \"cutout\" \"string map\" [\"%s\"] %s\n"
             "Patch \"bilinear\" \"P\" [-2 2 0  2 2 0  -2 -2 0  2 -2 0]\n"
             "WorldEnd\n", extra, map, params);
    write_file("cut.rib", rib);
    if (run(worker, "--standalone cut.rib -o cut.exr", out, sizeof out) != 0)
        fail_msg("%s", out);
    char path[512], err[256];
    snprintf(path, sizeof path, "%s/cut.exr", dir);
    image_buffer *b = image_buffer_read_exr(path, err, sizeof err);
    if (!b)
        fail_msg("%s", err);
    int a = -1;
    for (int c = 0; c < b->channel_count; c++)
        if (strcmp(b->names[c], "A") == 0)
            a = c;
    assert_true(a >= 0);
    double l = 0, r = 0;
    for (int y = 0; y < b->height; y++)
        for (int x = 0; x < 4; x++) {
            l += b->planes[a][y * b->width + x];
            r += b->planes[a][y * b->width + b->width - 1 - x];
        }
    *left = l / (4.0 * b->height);
    *right = r / (4.0 * b->height);
    image_buffer_destroy(&b);
}

static void test_alpha_channel(void **state)
{
    (void)state;
    double l, r;
    render("rgba.exr", "", "", &l, &r);
    printf("rgba: alpha left %.3f right %.3f\n", l, r);
    assert_true(l > 0.99 && r < 0.01);
    render("rgba.exr", "", "TextureCoordinates 1 0  0 0  1 1  0 1", &l, &r);   /* s mirrored */
    printf("rgba, s mirrored: alpha left %.3f right %.3f\n", l, r);
    assert_true(l < 0.01 && r > 0.99);
}

static void test_missing_alpha(void **state)
{
    (void)state;
    double l, r;
    render("rgb.exr", "", "", &l, &r);
    printf("rgb: alpha left %.3f right %.3f\n", l, r);
    assert_true(l > 0.99 && r > 0.99);
    render("rgb.exr", "\"float fill\" [0.25]", "", &l, &r);
    printf("rgb, fill 0.25: alpha left %.3f right %.3f\n", l, r);
    assert_true(l > 0.249 && l < 0.251 && r > 0.249 && r < 0.251);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s AAFARM-WORKER AAFARM-MAKETX\n", argv[0]);
        return 2;
    }
    worker = argv[1];
    maketx = argv[2];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_alpha_channel),
        cmocka_unit_test(test_missing_alpha),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

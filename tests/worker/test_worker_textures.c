/*
 * test_worker_textures.c: `aafarm-worker --standalone` rendering a scene
 * displaced by an aafarm-maketx map (a real process; docs/textures.md
 * "Memory"): the map's large levels load in tiles on demand, and
 *   - a render with --texture-bytes 64K (4 tiles, so tiles are evicted
 *     and read again all the time; its --stats-json counts evictions > 0)
 *     equals the render with no budget (0 evictions) pixel for pixel, in
 *     every channel, in affine and in interval arithmetic, with 2 threads;
 *   - and both equal the render of the same map without its stored
 *     pyramids (aafarm-maketx --no-minmax: read as an image, pyramids
 *     built in memory, no tiles loaded);
 *   - a malformed --texture-bytes is a usage error (exit 2) naming it.
 * Each run is bounded by `timeout -k`.
 *
 * argv[1]: the aafarm-worker binary; argv[2]: aafarm-maketx.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>

#include "image/buffer.h"

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

/* the number after "key": in a --stats-json file; -1 if absent */
static long long json_number(const char *name, const char *key)
{
    char path[512], text[16384], pat[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = '\0';
    fclose(f);
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *at = strstr(text, pat);
    return at ? strtoll(at + strlen(pat), NULL, 10) : -1;
}

static image_buffer *read_image(const char *name)
{
    char path[512], err[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    image_buffer *b = image_buffer_read_exr(path, err, sizeof err);
    if (!b)
        fail_msg("%s", err);
    return b;
}

static void terrain(const char *name, const char *map);

static int setup(void **state)
{
    (void)state;
    char out[4096];
    /* 1024 x 1024: levels 0 and 1 load in tiles, 2 .. 10 stay in memory */
    if (run(maketx, "--fbm 1024 1024 --octaves 5 height.exr", out, sizeof out) != 0) {
        fprintf(stderr, "%s", out);
        return -1;
    }
    write_file("hmap.sl", "displacement hmap(float Km = 0.3; string map = \"\")\n{\n"
                          "    P += Km * texture(map[0], s, t) * normalize(N);\n"
                          "    N = calculatenormal(P);\n}\n");
    /* the same map without its stored pyramids: read as an image, built */
    if (run(maketx, "--no-minmax height.exr plain.exr", out, sizeof out) != 0) {
        fprintf(stderr, "%s", out);
        return -1;
    }
    terrain("terrain.rib", "height.exr");
    terrain("plain.rib", "plain.exr");
    return 0;
}

static void terrain(const char *name, const char *map)
{
    char text[2048];
    snprintf(text, sizeof text,
               "Option \"searchpath\" \"shader\" [\".\"]\n"
               "Format 40 28 1\nPixelSamples 1 1\n"
               "Projection \"perspective\" \"fov\" [40]\n"
               "Translate 0 -0.3 4.2\nRotate -30 1 0 0\n"
               "WorldBegin\n"
               "LightSource \"distantlight\" 1 \"from\" [-2 3 -1] \"to\" [0 0 0]\n"
               "Attribute \"displacementbound\" \"sphere\" [0.45]\n"
               "Displacement \"hmap\" \"string map\" [\"%s\"]\n"
               "Rotate -90 1 0 0\n"
               "Patch \"bilinear\" \"P\" [-2 -2 0  2 -2 0  -2 2 0  2 2 0]\n"
               "WorldEnd\n", map);
    write_file(name, text);
}

static void same_pixels(const char *a_name, const char *b_name)
{
    image_buffer *a = read_image(a_name), *b = read_image(b_name);
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    static const char *const channels[] = { "R", "G", "B", "A", "Z" };
    for (int c = 0; c < 5; c++) {
        float *x = image_buffer_channel(a, channels[c]), *y = image_buffer_channel(b, channels[c]);
        assert_non_null(x);
        assert_non_null(y);
        for (int k = 0; k < a->width * a->height; k++)
            if (memcmp(&x[k], &y[k], sizeof *x) != 0)
                fail_msg("%s and %s differ: channel %s, pixel %d,%d: %.9g vs %.9g", a_name,
                         b_name, channels[c], k % a->width, k / a->width, x[k], y[k]);
    }
    float *alpha = image_buffer_channel(a, "A");
    int hit = 0;
    for (int k = 0; k < a->width * a->height; k++)
        hit += alpha[k] > 0.5f;
    assert_true(hit > a->width * a->height / 4);    /* the terrain is in the picture */
    image_buffer_destroy(&a);
    image_buffer_destroy(&b);
}

static void test_tiny_budget_renders_the_same(void **state)
{
    (void)state;
    char out[8192];
    static const char *const arith[] = { "affine", "interval" };
    for (int m = 0; m < 2; m++) {
        char args[512];
        snprintf(args, sizeof args, "--standalone terrain.rib -o all.exr --threads 2 --arith %s "
                 "--texture-bytes 0 --stats-json all.json -q", arith[m]);
        assert_int_equal(run(worker, args, out, sizeof out), 0);
        snprintf(args, sizeof args, "--standalone terrain.rib -o tiny.exr --threads 2 --arith %s "
                 "--texture-bytes 64K --stats-json tiny.json -q", arith[m]);
        assert_int_equal(run(worker, args, out, sizeof out), 0);
        assert_true(json_number("all.json", "texture_tile_loads") > 0);
        assert_int_equal(json_number("all.json", "texture_tile_evictions"), 0);
        assert_int_equal(json_number("tiny.json", "texture_bytes"), 65536);
        assert_true(json_number("tiny.json", "texture_tile_evictions") > 0);
        assert_true(json_number("tiny.json", "texture_tile_loads") >
                    json_number("all.json", "texture_tile_loads"));
        same_pixels("all.exr", "tiny.exr");
        /* the plain image, its pyramids built in memory: the same picture */
        snprintf(args, sizeof args, "--standalone plain.rib -o plain_out.exr --threads 2 --arith %s "
                 "--stats-json plain.json -q", arith[m]);
        assert_int_equal(run(worker, args, out, sizeof out), 0);
        assert_int_equal(json_number("plain.json", "texture_tile_loads"), 0);
        same_pixels("all.exr", "plain_out.exr");
    }
}

static void test_bad_texture_bytes(void **state)
{
    (void)state;
    char out[4096];
    assert_int_equal(run(worker, "--standalone terrain.rib --texture-bytes lots", out, sizeof out),
                     2);
    assert_non_null(strstr(out, "--texture-bytes"));
    assert_non_null(strstr(out, "lots"));
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_worker_textures AAFARM_WORKER AAFARM_MAKETX\n");
        return 2;
    }
    worker = argv[1];
    maketx = argv[2];
    snprintf(dir, sizeof dir, "/tmp/aafarm-wtex-XXXXXX");
    if (!mkdtemp(dir)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tiny_budget_renders_the_same),
        cmocka_unit_test(test_bad_texture_bytes),
    };
    int rc = cmocka_run_group_tests(tests, setup, NULL);
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return rc;
}

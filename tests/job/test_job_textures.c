/*
 * tests/job/test_job_textures.c: the textures of a job's world
 * (common/job/job_scene.c, docs/textures.md "Where textures come from").
 * A RIB on disk names a map through a shader parameter and Option
 * "searchpath" "texture" ["maps:&"]: job_load checks it (the name
 * resolves), job_scene_new for rendering opens it once, before any ray
 * (the cache holds its pyramids and the world points at the cache); a
 * name that resolves nowhere fails job_load with the shader call's
 * file:line:col, the texture's name and the search path.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "job/frames.h"
#include "job/job.h"
#include "job/job_scene.h"
#include "tex/tex.h"

static char dir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-jobtex-XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    char path[512];
    snprintf(path, sizeof path, "%s/maps", dir);
    return mkdir(path, 0700);
}

static void write_file(const char *rel, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *SHADER =
    "displacement bumpy(float Km = 0.1; string map = \"\") {\n"
    "    if (map != \"\") P += Km * texture(map, s, t) * normalize(N);\n"
    "}\n";

static void write_rib(const char *map)
{
    char rib[1024];
    snprintf(rib, sizeof rib,
             "Option \"searchpath\" \"texture\" [\"maps:&\"]\n"
             "Format 16 16 1\nProjection \"perspective\" \"fov\" [40]\nTranslate 0 0 5\n"
             "WorldBegin\n"
             "  Attribute \"displacementbound\" \"sphere\" [0.2]\n"
             "  Displacement \"bumpy\" \"string map\" [\"%s\"]\n"
             "  Sphere 1 -1 1 360\n"
             "WorldEnd\n", map);
    write_file("main.rib", rib);
}

static void test_opened_when_bound(void **state)
{
    (void)state;
    write_file("bumpy.sl", SHADER);
    float px[8 * 4];
    for (int k = 0; k < 32; k++)
        px[k] = (float)(k % 5) / 5.0f;
    tex_texture *t = tex_from_pixels(px, 8, 4, 1, "h");
    char path[512], err[512];
    snprintf(path, sizeof path, "%s/maps/h.exr", dir);
    assert_true(tex_write_exr(path, t, true, err, sizeof err));
    tex_destroy(&t);
    write_rib("h.exr");
    snprintf(path, sizeof path, "%s/main.rib", dir);
    sl_diag *d = sl_diag_new();
    job *jb = job_load(path, NULL, NULL, d);
    if (!jb)
        sl_diag_print(d, stderr);
    assert_non_null(jb);
    job_scene *js = job_scene_new(jb, 0, true, NULL, d);
    if (!js)
        sl_diag_print(d, stderr);
    assert_non_null(js);
    assert_ptr_equal(js->world.textures, js->textures);
    assert_true(tex_cache_bytes(js->textures) >= 8 * 4 * sizeof(float));
    const tex_texture *h = tex_cache_get(js->textures, "h.exr", err, sizeof err);
    assert_non_null(h);
    assert_int_equal(tex_width(h), 8);
    assert_int_equal(tex_height(h), 4);
    job_scene_destroy(&js);
    job_destroy(&jb);
    sl_diag_destroy(&d);
}

/* An output named like a map the scene reads (or like the scene) would
 * replace it with the image: refused as a usage error, naming it; another
 * name loads. */
static void test_output_never_replaces_an_input(void **state)
{
    (void)state;
    write_file("bumpy.sl", SHADER);
    float px[4] = { 0.1f, 0.2f, 0.3f, 0.4f };
    tex_texture *t = tex_from_pixels(px, 2, 2, 1, "h");
    char map[512], rib[512], err[512];
    snprintf(map, sizeof map, "%s/maps/h.exr", dir);
    assert_true(tex_write_exr(map, t, true, err, sizeof err));
    tex_destroy(&t);
    write_rib("h.exr");
    snprintf(rib, sizeof rib, "%s/main.rib", dir);
    struct stat before;
    assert_int_equal(stat(map, &before), 0);
    const char *outputs[2] = { map, rib };
    const char *said[2] = { "the file its shaders read as 'h.exr'", "the scene file" };
    for (int i = 0; i < 2; i++) {
        sl_diag *d = sl_diag_new();
        bool usage = false;
        frame_sequence *seq = frame_sequence_load(rib, NULL, NULL, outputs[i], &usage, NULL, d);
        assert_null(seq);
        assert_true(usage);
        char *text = NULL;
        size_t len = 0;
        FILE *m = open_memstream(&text, &len);
        sl_diag_print(d, m);
        fclose(m);
        if (!strstr(text, said[i]) || !strstr(text, "give another output name"))
            fail_msg("message: %s", text);
        free(text);
        sl_diag_destroy(&d);
    }
    char other[600];
    snprintf(other, sizeof other, "%s/out.exr", dir);
    sl_diag *d = sl_diag_new();
    bool usage = false;
    frame_sequence *seq = frame_sequence_load(rib, NULL, NULL, other, &usage, NULL, d);
    assert_non_null(seq);
    frame_sequence_destroy(&seq);
    sl_diag_destroy(&d);
    struct stat after;
    assert_int_equal(stat(map, &after), 0);
    assert_int_equal(after.st_size, before.st_size);
}

static void test_missing_map_named_at_the_call(void **state)
{
    (void)state;
    write_file("bumpy.sl", SHADER);
    write_rib("nope.exr");
    char path[512];
    snprintf(path, sizeof path, "%s/main.rib", dir);
    sl_diag *d = sl_diag_new();
    job *jb = job_load(path, NULL, NULL, d);
    assert_null(jb);
    char *text = sl_diag_to_string(d);
    char want[600];
    snprintf(want, sizeof want, "%s/main.rib:7:3: error: shader 'bumpy': texture 'nope.exr': "
             "no file 'nope.exr' on the texture search path", dir);
    if (!strstr(text, want) || !strstr(text, "Option \"searchpath\" \"texture\""))
        fail_msg("diagnostics:\n%s\nwanted: %s", text, want);
    free(text);
    sl_diag_destroy(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_opened_when_bound),
        cmocka_unit_test(test_missing_map_named_at_the_call),
        cmocka_unit_test(test_output_never_replaces_an_input),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

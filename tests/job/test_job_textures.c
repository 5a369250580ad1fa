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
    tex_free(t);
    write_rib("h.exr");
    snprintf(path, sizeof path, "%s/main.rib", dir);
    sl_diag *d = sl_diag_new();
    job *jb = job_load(path, NULL, d);
    if (!jb)
        sl_diag_print(d, stderr);
    assert_non_null(jb);
    job_scene *js = job_scene_new(jb, 0, true, d);
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

static void test_missing_map_named_at_the_call(void **state)
{
    (void)state;
    write_file("bumpy.sl", SHADER);
    write_rib("nope.exr");
    char path[512];
    snprintf(path, sizeof path, "%s/main.rib", dir);
    sl_diag *d = sl_diag_new();
    job *jb = job_load(path, NULL, d);
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
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

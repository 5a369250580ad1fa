/*
 * tests/job/test_job_files.c: the data files of a job (common/job/
 * job_files.c): job_load finds every shader string constant and every
 * string parameter of the RIB's shader calls that names a regular file on
 * the texture search path (Option "searchpath" "texture", "&", relative to
 * the RIB's folder, the RIB's folder last, absolute names), hashes it, and
 * the hashes enter the job hash: a job rebuilt from names, hashes and
 * sizes (as a worker does) hashes the same, a changed file changes it.
 * job_file_resolve gives the local path, or says why not.
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

static char dir[256];

static const char tex_sl[] =
    "displacement tex(string texname = \"\"; string deflt = \"d.dat\"; string abs = \"\")\n"
    "{\n"
    "    string local = \"inline.dat\";\n"
    "    float x = 0;\n"
    "    if (texname == local) x = 1;\n"
    "    if (deflt == \"nofile.dat\" || abs == \"rgb\") x = 2;\n"
    "    P += 0.01 * x * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *path_of(const char *rel)
{
    static char buf[4][512];
    static int next;
    char *p = buf[next++ % 4];
    snprintf(p, sizeof buf[0], "%s/%s", dir, rel);
    return p;
}

static void write_file(const char *rel, const char *text)
{
    FILE *f = fopen(path_of(rel), "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

static void write_scene(void)
{
    char rib[2048];
    snprintf(rib, sizeof rib,
             "Option \"searchpath\" \"shader\" [\"shaders\"] \"texture\" [\"maps:&\"]\n"
             "Format 16 16 1\nProjection \"perspective\" \"fov\" [40]\nTranslate 0 0 5\n"
             "WorldBegin\n"
             "Displacement \"tex\" \"string texname\" \"height.dat\" \"string abs\" \"%s\"\n"
             "Patch \"bilinear\" \"P\" [-1 -1 0  1 -1 0  -1 1 0  1 1 0]\n"
             "WorldEnd\n", path_of("elsewhere/abs.dat"));
    write_file("scene.rib", rib);
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-jobfiles-XXXXXX");
    if (!mkdtemp(dir)) return -1;
    mkdir(path_of("shaders"), 0700);
    mkdir(path_of("maps"), 0700);
    mkdir(path_of("elsewhere"), 0700);
    write_file("shaders/tex.sl", tex_sl);
    write_file("maps/height.dat", "a height map");
    write_file("maps/d.dat", "the default's file");
    write_file("inline.dat", "found in the RIB's folder");
    write_file("elsewhere/abs.dat", "an absolute name");
    write_scene();
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static job *load(void)
{
    sl_diag *d = sl_diag_new();
    job *j = job_load(path_of("scene.rib"), NULL, NULL, d);
    if (!j) sl_diag_print(d, stderr);
    sl_diag_destroy(&d);
    assert_non_null(j);
    return j;
}

static void expect_file(const job *j, const char *name, const char *rel, const char *content)
{
    job_file *f = job_file_find(j, name);
    if (!f) fail_msg("'%s' is not a file of the job", name);
    char hex[HASH_HEX_SIZE];
    uint8_t d[SHA256_DIGEST_SIZE];
    sha256_digest(content, strlen(content), d);
    hash_hex(d, hex);
    assert_string_equal(f->sha256, hex);
    assert_int_equal(f->size, strlen(content));
    char path[512], why[600];
    assert_true(job_file_resolve((void *)j, name, path, sizeof path, why, sizeof why));
    /* the path names the file found (normalized folders may differ in form) */
    struct stat a, b;
    assert_int_equal(stat(path, &a), 0);
    assert_int_equal(stat(path_of(rel), &b), 0);
    assert_int_equal(a.st_ino, b.st_ino);
}

static void test_files_found_and_hashed(void **state)
{
    (void)state;
    job *j = load();
    /* d.dat (a parameter's default) and inline.dat (a constant in the code)
     * from the program; height.dat and the absolute name from the RIB;
     * "nofile.dat", "rgb" and "" name no file */
    assert_int_equal(j->nfiles, 4);
    expect_file(j, "height.dat", "maps/height.dat", "a height map");
    expect_file(j, "d.dat", "maps/d.dat", "the default's file");
    expect_file(j, "inline.dat", "inline.dat", "found in the RIB's folder");
    expect_file(j, path_of("elsewhere/abs.dat"), "elsewhere/abs.dat", "an absolute name");
    assert_int_equal(job_files_bytes(j), strlen("a height map") + strlen("the default's file") +
                                             strlen("found in the RIB's folder") +
                                             strlen("an absolute name"));
    char path[512], why[600];
    assert_false(job_file_resolve(j, "nofile.dat", path, sizeof path, why, sizeof why));
    assert_non_null(strstr(why, "searchpath"));
    assert_false(job_file_resolve(j, "height.dat", path, 4, why, sizeof why));
    assert_non_null(strstr(why, "longer than"));
    job_destroy(&j);
}

/* The job as a worker rebuilds it: names, hashes, sizes; no paths. */
static job *rebuild(const job *src, const char *change_sha_of)
{
    job *j = job_new(src->scene_file, src->scene_text, src->scene_len, &src->options);
    char why[600];
    for (size_t i = 0; i < sl_source_set_count(src->sources); i++) {
        const sl_source *s = sl_source_set_at(src->sources, i);
        assert_true(job_add_source(j, s->name, s->text, s->len, why, sizeof why));
    }
    for (int i = 0; i < src->nshaders; i++)
        assert_true(job_add_shader(j, src->shaders[i].name, src->shaders[i].file, why, sizeof why));
    for (int i = src->nfiles - 1; i >= 0; i--) {   /* another order: the same hash */
        char sha[HASH_HEX_SIZE];
        snprintf(sha, sizeof sha, "%s", src->files[i].sha256);
        if (change_sha_of && strcmp(src->files[i].name, change_sha_of) == 0)
            sha[0] = sha[0] == '0' ? '1' : '0';
        assert_true(job_add_file(j, src->files[i].name, sha, src->files[i].size, why, sizeof why));
    }
    assert_false(job_add_file(j, src->files[0].name, src->files[0].sha256, 1, why, sizeof why));
    assert_non_null(strstr(why, "twice"));
    assert_false(job_add_file(j, "x.dat", "not a hash", 1, why, sizeof why));
    assert_true(job_finish(j, why, sizeof why));
    return j;
}

static void test_hashes_enter_the_job_hash(void **state)
{
    (void)state;
    job *a = load();
    job *same = rebuild(a, NULL);
    assert_string_equal(same->hash, a->hash);
    char path[512], why[600];
    assert_false(job_file_resolve(same, "height.dat", path, sizeof path, why, sizeof why));
    assert_non_null(strstr(why, "not present"));
    job *other = rebuild(a, "inline.dat");
    assert_string_not_equal(other->hash, a->hash);

    /* the same name with other bytes on disk: a new job */
    write_file("maps/height.dat", "a height map, edited");
    job *b = load();
    assert_string_not_equal(b->hash, a->hash);
    expect_file(b, "height.dat", "maps/height.dat", "a height map, edited");
    /* back: the same job again */
    write_file("maps/height.dat", "a height map");
    job *c = load();
    assert_string_equal(c->hash, a->hash);
    job_destroy(&a);
    job_destroy(&same);
    job_destroy(&other);
    job_destroy(&b);
    job_destroy(&c);
}

static void test_search_path_order(void **state)
{
    (void)state;
    /* a height.dat in the RIB's folder too: "maps" comes first */
    write_file("height.dat", "the RIB folder's copy");
    job *j = load();
    expect_file(j, "height.dat", "maps/height.dat", "a height map");
    job_destroy(&j);
    unlink(path_of("height.dat"));
    /* a folder is not a file */
    mkdir(path_of("maps/folder.dat"), 0700);
    write_file("scene.rib",
               "Option \"searchpath\" \"shader\" [\"shaders\"] \"texture\" [\"maps\"]\n"
               "Format 16 16 1\nProjection \"perspective\" \"fov\" [40]\nWorldBegin\n"
               "Displacement \"tex\" \"string texname\" \"folder.dat\"\n"
               "Patch \"bilinear\" \"P\" [-1 -1 0  1 -1 0  -1 1 0  1 1 0]\nWorldEnd\n");
    j = load();
    assert_null(job_file_find(j, "folder.dat"));
    assert_non_null(job_file_find(j, "d.dat"));
    job_destroy(&j);
    write_scene();
}

/* "did you mean plastic?" (issue 26): a shader found nowhere names the
 * closest of the shaders on the search path and the standard ones. */
static void expect_shader_error(const char *call, const char *want)
{
    char rib[1024];
    snprintf(rib, sizeof rib,
             "Option \"searchpath\" \"shader\" [\"shaders\"]\n"
             "Format 16 16 1\nProjection \"perspective\" \"fov\" [40]\nTranslate 0 0 5\n"
             "WorldBegin\n%s\nSphere 1 -1 1 360\nWorldEnd\n", call);
    write_file("typo.rib", rib);
    sl_diag *d = sl_diag_new();
    job *j = job_load(path_of("typo.rib"), NULL, NULL, d);
    assert_null(j);
    assert_true(sl_diag_count(d) >= 1);
    const sl_diagnostic *x = sl_diag_get(d, 0);
    char got[2048], expect[2048];
    snprintf(got, sizeof got, "%d:%d: %s", x->line, x->col, x->message);
    snprintf(expect, sizeof expect, want, dir, dir);
    assert_string_equal(got, expect);
    sl_diag_destroy(&d);
}

static void test_shader_did_you_mean(void **state)
{
    (void)state;
    expect_shader_error("Surface \"plastc\"",
                        "6:1: shader 'plastc' not found (did you mean plastic?): looked for "
                        "'plastc.sl' in %s/shaders, %s");
    expect_shader_error("Displacement \"Tx\"",
                        "6:1: shader 'Tx' not found (did you mean tex?): looked for "
                        "'Tx.sl' in %s/shaders, %s");
    expect_shader_error("Surface \"velvet\"",
                        "6:1: shader 'velvet' not found: looked for 'velvet.sl' in "
                        "%s/shaders, %s; add its folder with Option \"searchpath\" "
                        "\"shader\" [\"dir:&\"]");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_files_found_and_hashed),
        cmocka_unit_test(test_hashes_enter_the_job_hash),
        cmocka_unit_test(test_search_path_order),
        cmocka_unit_test(test_shader_did_you_mean),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

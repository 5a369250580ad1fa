/*
 * tests/scene/test_scene_archive.c: ReadArchive (common/scene/rib_archive.c).
 * Archives written to a fresh temporary folder: read relative to the
 * including file (nested archives relative to their own folder), through
 * Option "searchpath" "archive", gzip-compressed; in the graphics state of
 * the ReadArchive; errors with file:line:col naming the archive chain (not
 * found, cycles, too deep); the size limit (uncompressed, per archive,
 * far over a shader source's); and a parse from a set without a loader (what
 * a worker does) never touches the disk.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "scene_testing.h"

static char dir[256];

static void write_text(const char *rel, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, strlen(text), f), strlen(text));
    assert_int_equal(fclose(f), 0);
}

static void write_gzip(const char *rel, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    gzFile f = gzopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(gzwrite(f, text, (unsigned)strlen(text)), (int)strlen(text));
    assert_int_equal(gzclose(f), Z_OK);
}

static char *path_of(const char *rel)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    return path;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-archive-XXXXXX");
    assert_non_null(mkdtemp(dir));
    char sub[512];
    snprintf(sub, sizeof sub, "%s/parts", dir);
    assert_int_equal(mkdir(sub, 0700), 0);
    snprintf(sub, sizeof sub, "%s/lib", dir);
    assert_int_equal(mkdir(sub, 0700), 0);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static scene *load_main(const char *text, sl_diag **d)
{
    write_text("main.rib", text);
    *d = sl_diag_new();
    return scene_load(path_of("main.rib"), *d);
}

/* parts/a.rib reads b.rib from its own folder (parts/), which reads a
 * gzip-compressed archive; the objects take the transform and color
 * current at each ReadArchive. */
static void test_nested_relative_and_gzip(void **state)
{
    (void)state;
    write_text("parts/a.rib", "Translate 1 0 0\nSphere 1 -1 1 360\nReadArchive \"b.rib\"\n");
    write_text("parts/b.rib", "Color 0 1 0\nReadArchive \"c.rib.gz\"\n");
    write_gzip("parts/c.rib.gz", "# compressed\nTranslate 0 2 0\nDisk 0 1 360\n");
    sl_diag *d;
    scene *s = load_main(CAMERA "WorldBegin\nAttributeBegin\nReadArchive \"parts/a.rib\"\n"
                         "AttributeEnd\nCylinder 1 0 1 360\nWorldEnd\n", &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 3);
    assert_int_equal(s->objects[0].surface->kind, GEOM_SPHERE);
    assert_int_equal(s->objects[1].surface->kind, GEOM_DISK);
    assert_int_equal(s->objects[2].surface->kind, GEOM_CYLINDER);
    vec3 o1 = mat4_xform_point(&s->objects[1].object_to_world, v3(0, 0, 0));
    assert_true(vec_dist(o1, v3(1, 2, 0)) < 1e-12);
    assert_true(s->objects[1].Cs[0] == 0 && s->objects[1].Cs[1] == 1);
    /* the AttributeEnd in main.rib undid what the archives set */
    vec3 o2 = mat4_xform_point(&s->objects[2].object_to_world, v3(0, 0, 0));
    assert_true(vec_dist(o2, v3(0, 0, 0)) < 1e-12);
    assert_true(s->objects[2].Cs[1] == 1 && s->objects[2].Cs[0] == 1);
    /* positions of objects point into the archive they came from */
    assert_non_null(strstr(s->objects[1].pos.file, "parts/c.rib.gz"));
    assert_int_equal(s->objects[1].pos.line, 3);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_search_path(void **state)
{
    (void)state;
    write_text("lib/lamp.rib", "Sphere 0.5 -0.5 0.5 360\n");
    sl_diag *d;
    scene *s = load_main("Option \"searchpath\" \"archive\" [\"nowhere:lib:&\"]\n" CAMERA
                         "WorldBegin\nReadArchive \"lamp.rib\"\nWorldEnd\n", &d);
    if (!s)
        sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 1);
    assert_true(s->objects[0].surface->radius == 0.5);
    scene_destroy(&s);
    sl_diag_destroy(&d);
}

static void test_not_found(void **state)
{
    (void)state;
    sl_diag *d;
    scene *s = load_main(CAMERA "WorldBegin\nSphere 1 -1 1 360\n  ReadArchive \"nope.rib\"\n"
                         "WorldEnd\n", &d);
    assert_null(s);
    const char *line = diag_line(nth_diag(d, SL_DIAG_ERROR, 0));
    char want[4096];
    snprintf(want, sizeof want, "%s/main.rib:5:15: ReadArchive: archive \"nope.rib\" not found: "
             "looked in %s; add its folder with Option \"searchpath\" \"archive\" [\"dir:&\"]",
             dir, dir);
    assert_string_equal(line, want);
    sl_diag_destroy(&d);
}

/* An error inside an archive names where it is and the chain that read
 * it, innermost first. */
static void test_error_names_chain(void **state)
{
    (void)state;
    write_text("parts/outer.rib", "\nReadArchive \"inner.rib\"\n");
    write_text("parts/inner.rib", "Sphere 1 -1\n");
    sl_diag *d;
    scene *s = load_main(CAMERA "WorldBegin\nReadArchive \"parts/outer.rib\"\nWorldEnd\n", &d);
    assert_null(s);
    const char *line = diag_line(nth_diag(d, SL_DIAG_ERROR, 0));
    char want[4096];
    snprintf(want, sizeof want, "%s/parts/inner.rib:1:1: Sphere: expected 4 numbers (radius "
             "zmin zmax thetamax), got 2 (in archive %s/parts/inner.rib read at "
             "%s/parts/outer.rib:2:1, archive %s/parts/outer.rib read at %s/main.rib:4:1)",
             dir, dir, dir, dir, dir);
    assert_string_equal(line, want);
    sl_diag_destroy(&d);
}

static void test_cycle_and_depth(void **state)
{
    (void)state;
    write_text("parts/x.rib", "ReadArchive \"y.rib\"\n");
    write_text("parts/y.rib", "Sphere 1 -1 1 360\nReadArchive \"x.rib\"\n");
    sl_diag *d;
    scene *s = load_main(CAMERA "WorldBegin\nReadArchive \"parts/x.rib\"\nWorldEnd\n", &d);
    assert_null(s);
    const char *line = diag_line(nth_diag(d, SL_DIAG_ERROR, 0));
    assert_non_null(strstr(line, "parts/y.rib:2:13: ReadArchive: archive \"x.rib\""));
    assert_non_null(strstr(line, "reads itself"));
    sl_diag_destroy(&d);

    /* the main file reading itself */
    s = load_main(CAMERA "WorldBegin\nSphere 1 -1 1 360\nReadArchive \"main.rib\"\nWorldEnd\n",
                  &d);
    assert_null(s);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)), "reads itself"));
    sl_diag_destroy(&d);

    /* a chain of distinct files deeper than the limit */
    for (int i = 0; i <= SCENE_ARCHIVE_MAX_DEPTH + 1; i++) {
        char name[64], text[128];
        snprintf(name, sizeof name, "parts/d%d.rib", i);
        snprintf(text, sizeof text, "ReadArchive \"d%d.rib\"\n", i + 1);
        write_text(name, text);
    }
    s = load_main(CAMERA "WorldBegin\nSphere 1 -1 1 360\nReadArchive \"parts/d0.rib\"\n"
                  "WorldEnd\n", &d);
    assert_null(s);
    assert_int_equal(sl_diag_error_count(d), 1);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)), "nested more than 16 deep"));
    sl_diag_destroy(&d);
}

/* A damaged gzip file is an error with the ReadArchive's position. */
static void test_damaged_gzip(void **state)
{
    (void)state;
    write_gzip("parts/ok.rib.gz", "Sphere 1 -1 1 360\nSphere 2 -2 2 360\n");
    char *full = read_whole_file(path_of("parts/ok.rib.gz"), &(size_t){0});
    assert_non_null(full);
    /* keep the header and half the deflate stream */
    FILE *f = fopen(path_of("parts/bad.rib.gz"), "wb");
    assert_non_null(f);
    fwrite(full, 1, 20, f);
    fclose(f);
    free(full);
    sl_diag *d;
    scene *s = load_main(CAMERA "WorldBegin\nSphere 1 -1 1 360\nReadArchive \"parts/bad.rib.gz\"\n"
                         "WorldEnd\n", &d);
    assert_null(s);
    bool named = false;
    for (int i = 0; nth_diag(d, SL_DIAG_ERROR, i); i++)
        named |= strstr(diag_line(nth_diag(d, SL_DIAG_ERROR, i)),
                        "main.rib:5:13: ReadArchive: archive \"parts/bad.rib.gz\" cannot be "
                        "read") != NULL;
    if (!named)
        sl_diag_print(d, stderr);
    assert_true(named);
    sl_diag_destroy(&d);
}

/* An archive is bounded by its set's size (SCENE_ARCHIVE_MAX_BYTES, 1 GiB,
 * in the sets the parser, job_load and a worker use: far over the 4 MiB
 * of a shader source), counted uncompressed: a 5 MiB archive gzipped to a
 * few KiB reads whole under the default, and over a 1 MiB bound it is an
 * error naming the archive and the limit, and ReadArchive's position. */
static void test_archive_size_limit(void **state)
{
    (void)state;
    enum { BIG = 5 << 20 };
    char *text = malloc(BIG + 1);
    assert_non_null(text);
    const char *line = "Translate 0 0 0.000\n";   /* 20 bytes */
    for (size_t i = 0; i + 20 <= BIG; i += 20) memcpy(text + i, line, 20);
    memcpy(text + BIG - 20, "Sphere 1 -1 1 360  \n", 20);
    text[BIG] = '\0';
    write_gzip("parts/big.rib.gz", text);
    free(text);
    assert_true(SCENE_ARCHIVE_MAX_BYTES == (size_t)1 << 30);
    sl_diag *d;
    scene *s = load_main(CAMERA "WorldBegin\nReadArchive \"parts/big.rib.gz\"\nWorldEnd\n", &d);
    if (!s) sl_diag_print(d, stderr);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 1);
    scene_destroy(&s);
    sl_diag_destroy(&d);

    sl_source_set *set = scene_archive_set_new();
    sl_source_set_set_max_size(set, 1 << 20);
    d = sl_diag_new();
    const char *main_text = CAMERA "WorldBegin\nReadArchive \"parts/big.rib.gz\"\nWorldEnd\n";
    s = scene_parse_archives(path_of("main.rib"), main_text, strlen(main_text), set, d);
    assert_null(s);
    char want[1024];
    snprintf(want, sizeof want, "archive '%s' is larger than 1 MiB uncompressed (the limit "
             "is 1048576 bytes per archive): split it into several archives",
             path_of("parts/big.rib.gz"));
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)), want));
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_ERROR, 1)),
                           "main.rib:4:13: ReadArchive: archive \"parts/big.rib.gz\" cannot be "
                           "read"));
    sl_diag_destroy(&d);
    sl_source_set_destroy(&set);
}

/* A worker: archives only from the set it was given, none from disk. */
static void test_from_set_only(void **state)
{
    (void)state;
    const char *text = CAMERA "WorldBegin\nReadArchive \"parts/m.rib\"\nWorldEnd\n";
    sl_source_set *set = sl_source_set_new();
    assert_int_equal(sl_source_set_add(set, "proj/parts/m.rib", "Sphere 3 -3 3 360\n", 18), 0);
    sl_diag *d = sl_diag_new();
    scene *s = scene_parse_archives("proj/main.rib", text, strlen(text), set, d);
    assert_non_null(s);
    assert_int_equal(s->nobjects, 1);
    assert_true(s->objects[0].surface->radius == 3);
    scene_destroy(&s);
    sl_diag_destroy(&d);

    /* the same name exists on disk under dir, but the set does not hold it */
    write_text("parts/m.rib", "Sphere 1 -1 1 360\n");
    char main_path[512];
    snprintf(main_path, sizeof main_path, "%s/main.rib", dir);
    d = sl_diag_new();
    s = scene_parse_archives(main_path, text, strlen(text), set, d);
    assert_null(s);
    assert_non_null(strstr(diag_line(nth_diag(d, SL_DIAG_ERROR, 0)), "not found"));
    sl_diag_destroy(&d);
    sl_source_set_destroy(&set);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nested_relative_and_gzip),
        cmocka_unit_test(test_search_path),
        cmocka_unit_test(test_not_found),
        cmocka_unit_test(test_error_names_chain),
        cmocka_unit_test(test_cycle_and_depth),
        cmocka_unit_test(test_damaged_gzip),
        cmocka_unit_test(test_archive_size_limit),
        cmocka_unit_test(test_from_set_only),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

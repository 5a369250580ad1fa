/*
 * tests/job/test_job_archive.c: archives travel inside the job
 * (common/job/job.c, common/scene/rib_archive.c). The master's job_load
 * reads the archives (a gzip one decompressed) into the job's sources;
 * a worker's job rebuilt from those sources alone, after the files are gone
 * from disk, parses to the same objects with the same hash; changing an
 * archive's content changes the hash.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "job/job.h"
#include "job/job_scene.h"

static char dir[256];

static void write_file(const char *rel, const char *text, bool gzip)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    if (gzip) {
        gzFile f = gzopen(path, "wb");
        assert_non_null(f);
        assert_int_equal(gzwrite(f, text, (unsigned)strlen(text)), (int)strlen(text));
        assert_int_equal(gzclose(f), Z_OK);
        return;
    }
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

static const char *MAIN_RIB =
    "Format 32 32 1\nProjection \"perspective\" \"fov\" [40]\nTranslate 0 0 5\n"
    "WorldBegin\nReadArchive \"a.rib\"\nWorldEnd\n";

static job *load(sl_diag *d)
{
    char path[512];
    snprintf(path, sizeof path, "%s/main.rib", dir);
    job *j = job_load(path, NULL, NULL, d);
    if (!j)
        sl_diag_print(d, stderr);
    return j;
}

static void test_archives_travel(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-jobarch-XXXXXX");
    assert_non_null(mkdtemp(dir));
    write_file("main.rib", MAIN_RIB, false);
    write_file("a.rib", "Sphere 1 -1 1 360\nReadArchive \"b.rib.gz\"\n", false);
    const char *b_text = "Translate 2 0 0\nDisk 0 1 360\n";
    write_file("b.rib.gz", b_text, true);

    sl_diag *d = sl_diag_new();
    job *master = load(d);
    assert_non_null(master);
    char bpath[512];
    snprintf(bpath, sizeof bpath, "%s/b.rib.gz", dir);
    const sl_source *b = sl_source_set_find(master->sources, bpath);
    assert_non_null(b);
    assert_int_equal(b->len, strlen(b_text));          /* shipped uncompressed */
    assert_memory_equal(b->text, b_text, b->len);

    /* the worker: the job rebuilt from what travels, the files gone */
    job *worker = job_new(master->scene_file, master->scene_text, master->scene_len,
                          &master->options);
    char why[256];
    for (size_t i = 0; i < sl_source_set_count(master->sources); i++) {
        const sl_source *s = sl_source_set_at(master->sources, i);
        assert_true(job_add_source(worker, s->name, s->text, s->len, why, sizeof why));
    }
    assert_true(job_finish(worker, why, sizeof why));
    assert_string_equal(worker->hash, master->hash);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -f '%s/a.rib' '%s/b.rib.gz'", dir, dir);
    assert_int_equal(system(cmd), 0);
    job_scene *js = job_scene_new(worker, 0, false, NULL, d);
    if (!js)
        sl_diag_print(d, stderr);
    assert_non_null(js);
    assert_int_equal(js->scene->nobjects, 2);
    assert_int_equal(js->world.nobjects, 2);
    job_scene_destroy(&js);
    job_destroy(&worker);

    /* another archive content: another job */
    write_file("a.rib", "Sphere 1 -1 1 360\nReadArchive \"b.rib.gz\"\n", false);
    write_file("b.rib.gz", "Translate 3 0 0\nDisk 0 1 360\n", true);
    job *changed = load(d);
    assert_non_null(changed);
    assert_string_not_equal(changed->hash, master->hash);
    job_destroy(&changed);
    job_destroy(&master);
    sl_diag_destroy(&d);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_archives_travel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * tests/job/test_job_archive.c: archives travel as files of the job
 * (common/job/job_archive.c, common/scene/rib_archive.c). The master's
 * job_load makes each archive the scene reads a job file
 * "archive:<name>" (hashed as on disk: a gzip one compressed), and none
 * lands in the job's sources (the Job message); a worker's job rebuilt
 * from the names, hashes and sizes, its files in a "store" folder named by
 * hash, parses to the same objects with the same hash after the master's
 * files are gone; a file not present is an error; an archive changed
 * after the load is refused; changing an archive's content changes the hash.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "job/job.h"
#include "job/job_scene.h"

static char dir[256];

static const char *path_of(const char *rel)
{
    static char path[2][512];
    static int k;
    k ^= 1;
    snprintf(path[k], sizeof path[k], "%s/%s", dir, rel);
    return path[k];
}

static void write_file(const char *rel, const char *text, bool gzip)
{
    if (gzip) {
        gzFile f = gzopen(path_of(rel), "wb");
        assert_non_null(f);
        assert_int_equal(gzwrite(f, text, (unsigned)strlen(text)), (int)strlen(text));
        assert_int_equal(gzclose(f), Z_OK);
        return;
    }
    FILE *f = fopen(path_of(rel), "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

/* SHA-256 of a file's bytes, and its size */
static void hash_of(const char *path, char hex[HASH_HEX_SIZE], uint64_t *size)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    sha256 h;
    sha256_init(&h);
    unsigned char buf[4096];
    size_t got;
    *size = 0;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        sha256_update(&h, buf, got);
        *size += got;
    }
    fclose(f);
    uint8_t d[SHA256_DIGEST_SIZE];
    sha256_final(&h, d);
    hash_hex(d, hex);
}

static const char *MAIN_RIB =
    "Format 32 32 1\nProjection \"perspective\" \"fov\" [40]\nTranslate 0 0 5\n"
    "WorldBegin\nReadArchive \"a.rib\"\nWorldEnd\n";

static job *load(sl_diag *d)
{
    job *j = job_load(path_of("main.rib"), NULL, NULL, d);
    if (!j)
        sl_diag_print(d, stderr);
    return j;
}

/* The worker's job: rebuilt from what the Job message says (the text, the
 * sources, the file names, hashes and sizes), its files at store/<hash>. */
static job *rebuild(const job *master, bool with_paths)
{
    job *w = job_new(master->scene_file, master->scene_text, master->scene_len,
                     &master->options);
    char why[256];
    for (size_t i = 0; i < sl_source_set_count(master->sources); i++) {
        const sl_source *s = sl_source_set_at(master->sources, i);
        assert_true(job_add_source(w, s->name, s->text, s->len, why, sizeof why));
    }
    for (int i = 0; i < master->nshaders; i++)
        assert_true(job_add_shader(w, master->shaders[i].name, master->shaders[i].file, why,
                                   sizeof why));
    for (int i = 0; i < master->nfiles; i++) {
        const job_file *f = &master->files[i];
        assert_true(job_add_file(w, f->name, f->sha256, f->size, why, sizeof why));
        char rel[128];
        snprintf(rel, sizeof rel, "store/%s", f->sha256);
        if (with_paths) job_file_set_path(w, i, path_of(rel));
    }
    w->files_known = true;
    assert_true(job_finish(w, why, sizeof why));
    return w;
}

static void test_archives_travel_as_files(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-jobarch-XXXXXX");
    assert_non_null(mkdtemp(dir));
    assert_int_equal(mkdir(path_of("store"), 0700), 0);
    write_file("main.rib", MAIN_RIB, false);
    write_file("a.rib", "Sphere 1 -1 1 360\nReadArchive \"b.rib.gz\"\n", false);
    write_file("b.rib.gz", "Translate 2 0 0\nDisk 0 1 360\n", true);

    sl_diag *d = sl_diag_new();
    job *master = load(d);
    assert_non_null(master);
    /* nothing of the archives in the sources: the Job message stays small */
    for (size_t i = 0; i < sl_source_set_count(master->sources); i++)
        assert_null(strstr(sl_source_set_at(master->sources, i)->name, ".rib"));
    /* two files, by name, hash and size of the bytes on disk */
    assert_int_equal(master->nfiles, 2);
    const char *rels[] = {"a.rib", "b.rib.gz"};
    for (int i = 0; i < 2; i++) {
        char name[600], hex[HASH_HEX_SIZE];
        uint64_t size;
        snprintf(name, sizeof name, "archive:%s", path_of(rels[i]));
        const job_file *f = job_file_find(master, name);
        assert_non_null(f);
        hash_of(path_of(rels[i]), hex, &size);
        assert_string_equal(f->sha256, hex);
        assert_int_equal(f->size, size);            /* b: compressed, as it travels */
        assert_string_equal(f->path, path_of(rels[i]));
        /* the host's store: the bytes under their hash */
        char cmd[1200], store[128];
        snprintf(store, sizeof store, "store/%s", hex);
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", path_of(rels[i]), path_of(store));
        assert_int_equal(system(cmd), 0);
    }

    /* a worker whose store lacks them: an error naming the archive */
    job *absent = rebuild(master, false);
    assert_string_equal(absent->hash, master->hash);
    assert_null(job_scene_new(absent, 0, false, NULL, d));
    char want[600];
    snprintf(want, sizeof want, "archive '%s' (", path_of("a.rib"));
    char *said = sl_diag_to_string(d);
    assert_non_null(strstr(said, want));
    assert_non_null(strstr(said, "is not present on this host"));
    free(said);
    job_destroy(&absent);
    sl_diag_destroy(&d);
    d = sl_diag_new();

    /* the worker: the same hash, the master's files gone, parsed from the store */
    job *worker = rebuild(master, true);
    assert_string_equal(worker->hash, master->hash);
    assert_int_equal(unlink(path_of("a.rib")), 0);
    assert_int_equal(unlink(path_of("b.rib.gz")), 0);
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

    /* changed on disk after the load: the render refuses it (standalone
     * and the master's own parse read the disk the hash was made of) */
    write_file("b.rib.gz", "Translate 4 0 0\nDisk 0 1 360\n", true);
    struct stat st;
    assert_int_equal(stat(path_of("b.rib.gz"), &st), 0);
    struct timespec later[2] = {st.st_atim, {st.st_mtim.tv_sec + 5, st.st_mtim.tv_nsec}};
    assert_int_equal(utimensat(AT_FDCWD, path_of("b.rib.gz"), later, 0), 0);
    sl_diag_destroy(&d);
    d = sl_diag_new();
    assert_null(job_scene_new(changed, 0, false, NULL, d));
    said = sl_diag_to_string(d);
    snprintf(want, sizeof want, "archive '%s' changed on disk after the job was loaded",
             path_of("b.rib.gz"));
    assert_non_null(strstr(said, want));
    free(said);

    job_destroy(&changed);
    job_destroy(&master);
    sl_diag_destroy(&d);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_archives_travel_as_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

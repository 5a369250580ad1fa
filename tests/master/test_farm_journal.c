/*
 * test_farm_journal.c: the master's journal of taken tiles (journal.h) and
 * the finder of dead masters' leftovers (stale.h), on real files:
 *   - records come back in order, byte for byte, once per tile;
 *   - a torn tail (the file cut inside a record, or garbage appended) and
 *     a corrupt record (one flipped byte) end the journal there: the tiles
 *     before are replayed, the file is cut back, appending works again;
 *   - another job's journal, or another image grid, is refused with a
 *     message naming both; a missing journal is reported as missing;
 *   - a journal in use by one master is locked against a second one;
 *   - CRC-32 matches the standard check value;
 *   - temporary outputs and ipc folders of dead processes are removed,
 *     those of live processes and folders that are not ours are not.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "journal.h"
#include "stale.h"

static char dir[64];
static char path[128];

static const journal_id job_a = {
    "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa", 64, 48, 8, 0, 48};

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-jtest-XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/out.exr.journal", dir);
    return 0;
}

static void rm_rf(const char *d)
{
    DIR *dd = opendir(d);
    if (!dd) return;
    struct dirent *e;
    while ((e = readdir(dd))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        char p[512];
        snprintf(p, sizeof p, "%s/%s", d, e->d_name);
        struct stat st;
        if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode)) rm_rf(p);
        else unlink(p);
    }
    closedir(dd);
    rmdir(d);
}

static int teardown(void **state)
{
    (void)state;
    rm_rf(dir);
    return 0;
}

/* Chunk of tile t: t+1 .. bytes of a pattern depending on t. */
static size_t chunk_of(int t, uint8_t *buf)
{
    size_t n = 100 + (size_t)t * 37;
    for (size_t i = 0; i < n; i++) buf[i] = (uint8_t)(i * 7 + (size_t)t * 13);
    return n;
}

typedef struct seen {
    int order[64];
    int n;
    bool bytes_ok;
} seen;

static bool on_tile(void *arg, int tile, const void *chunk, size_t len, char *err, size_t errsz)
{
    (void)err;
    (void)errsz;
    seen *s = arg;
    uint8_t want[4096];
    size_t n = chunk_of(tile, want);
    if (n != len || memcmp(want, chunk, n) != 0) s->bytes_ok = false;
    s->order[s->n++] = tile;
    return true;
}

/* A journal with tiles 3, 0, 7, 3 (again), 12. */
static void write_journal(void)
{
    bool replaced = true;
    char err[512];
    journal *j = journal_create(path, &job_a, &replaced, err, sizeof err);
    assert_non_null(j);
    assert_false(replaced);
    int tiles[] = {3, 0, 7, 3, 12};
    uint8_t buf[4096];
    for (int i = 0; i < 5; i++) {
        size_t n = chunk_of(tiles[i], buf);
        assert_true(journal_append(j, tiles[i], buf, n, i * 10, err, sizeof err));
    }
    journal_close(&j);
    assert_null(j);
}

static journal *resume(seen *s, journal_replay *info, const journal_id *id, char *err,
                       size_t errsz)
{
    memset(s, 0, sizeof *s);
    s->bytes_ok = true;
    bool missing = true;
    journal *j = journal_resume(path, id, on_tile, s, info, &missing, err, errsz);
    assert_false(missing);
    return j;
}

static long file_size(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

static void test_journal_replays_in_order(void **state)
{
    (void)state;
    write_journal();
    seen s;
    journal_replay info;
    char err[512];
    journal *j = resume(&s, &info, &job_a, err, sizeof err);
    assert_non_null(j);
    assert_int_equal(s.n, 4);   /* tile 3 once */
    assert_int_equal(s.order[0], 3);
    assert_int_equal(s.order[1], 0);
    assert_int_equal(s.order[2], 7);
    assert_int_equal(s.order[3], 12);
    assert_true(s.bytes_ok);
    assert_int_equal(info.tiles, 4);
    assert_int_equal(info.dropped_bytes, 0);
    journal_remove(&j);
    assert_int_equal(access(path, F_OK), -1);
}

static void test_journal_torn_tail_dropped(void **state)
{
    (void)state;
    write_journal();
    long whole = file_size(path);
    /* cut inside the last record (tile 12: 16 + 544 bytes) */
    assert_int_equal(truncate(path, whole - 100), 0);
    seen s;
    journal_replay info;
    char err[512];
    journal *j = resume(&s, &info, &job_a, err, sizeof err);
    assert_non_null(j);
    assert_int_equal(s.n, 3);
    assert_true(s.bytes_ok);
    assert_int_equal(info.dropped_bytes, 16 + 100 + 12 * 37 - 100);
    assert_non_null(strstr(info.dropped_why, "torn record (tile 12)"));
    assert_int_equal(file_size(path), whole - (16 + 100 + 12 * 37));
    /* appending goes on after the last whole record */
    uint8_t buf[4096];
    size_t n = chunk_of(12, buf);
    assert_true(journal_append(j, 12, buf, n, 0, err, sizeof err));
    journal_close(&j);
    assert_int_equal(file_size(path), whole);
    j = resume(&s, &info, &job_a, err, sizeof err);
    assert_non_null(j);
    assert_int_equal(s.n, 4);
    assert_int_equal(info.dropped_bytes, 0);
    journal_close(&j);
}

static void test_journal_garbage_and_flipped_byte(void **state)
{
    (void)state;
    write_journal();
    long whole = file_size(path);
    FILE *f = fopen(path, "ab");
    assert_non_null(f);
    fputs("TILE\x01garbage after the end", f);
    fclose(f);
    seen s;
    journal_replay info;
    char err[512];
    journal *j = resume(&s, &info, &job_a, err, sizeof err);
    assert_non_null(j);
    assert_int_equal(s.n, 4);
    assert_true(info.dropped_bytes > 0);
    journal_close(&j);
    assert_int_equal(file_size(path), whole);
    /* one flipped byte inside tile 7's chunk (the third record) */
    long at = 96 + (16 + 100 + 3 * 37) + (16 + 100) + 16 + 50;
    int fd = open(path, O_RDWR);
    assert_true(fd >= 0);
    uint8_t b;
    assert_int_equal(pread(fd, &b, 1, at), 1);
    b ^= 0x10;
    assert_int_equal(pwrite(fd, &b, 1, at), 1);
    close(fd);
    j = resume(&s, &info, &job_a, err, sizeof err);
    assert_non_null(j);
    assert_int_equal(s.n, 2);   /* 3 and 0 */
    assert_non_null(strstr(info.dropped_why, "bad checksum (tile 7)"));
    journal_close(&j);
}

static void test_journal_other_job_refused(void **state)
{
    (void)state;
    write_journal();
    long whole = file_size(path);
    journal_id other = job_a;
    other.job_hash[0] = 'b';
    seen s;
    journal_replay info;
    char err[512];
    assert_null(resume(&s, &info, &other, err, sizeof err));
    assert_non_null(strstr(err, "belongs to job aaaaaaaaaaaa, this render is job baaaaaaaaaaa"));
    journal_id grid = job_a;
    grid.tile_size = 16;
    grid.tiles = 12;
    assert_null(resume(&s, &info, &grid, err, sizeof err));
    assert_non_null(strstr(err, "64x48 image in tiles of 8, this render is 64x48 in tiles of 16"));
    assert_int_equal(file_size(path), whole);   /* untouched */
    assert_int_equal(s.n, 0);
}

static void test_journal_missing_and_locked(void **state)
{
    (void)state;
    seen s = {.bytes_ok = true};
    journal_replay info;
    char err[512];
    bool missing = false;
    assert_null(journal_resume(path, &job_a, on_tile, &s, &info, &missing, err, sizeof err));
    assert_true(missing);
    bool replaced;
    journal *j = journal_create(path, &job_a, &replaced, err, sizeof err);
    assert_non_null(j);
    assert_null(journal_create(path, &job_a, &replaced, err, sizeof err));
    assert_non_null(strstr(err, "another master is rendering into the same output"));
    missing = true;
    assert_null(journal_resume(path, &job_a, on_tile, &s, &info, &missing, err, sizeof err));
    assert_false(missing);
    journal_close(&j);
    /* a journal cut inside its header holds no tile: as good as missing */
    assert_int_equal(truncate(path, 40), 0);
    missing = false;
    assert_null(journal_resume(path, &job_a, on_tile, &s, &info, &missing, err, sizeof err));
    assert_true(missing);
    /* a fresh render replaces a journal with records and says so */
    write_journal();
    j = journal_create(path, &job_a, &replaced, err, sizeof err);
    assert_non_null(j);
    assert_true(replaced);
    journal_close(&j);
    assert_int_equal(file_size(path), 96);
}

static void test_journal_crc32_check_value(void **state)
{
    (void)state;
    assert_int_equal(journal_crc32(0, "123456789", 9), 0xCBF43926u);
    assert_int_equal(journal_crc32(journal_crc32(0, "1234", 4), "56789", 5), 0xCBF43926u);
}

/* ---- leftovers ---- */

static pid_t dead_pid(void)
{
    pid_t p = fork();
    if (p == 0) _exit(0);
    waitpid(p, NULL, 0);
    return p;
}

static void touch(const char *p)
{
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fclose(f);
}

typedef struct reports {
    int removed, kept;
} reports;

static void count_report(void *arg, const char *p, long pid, int removed)
{
    (void)p;
    (void)pid;
    reports *r = arg;
    if (removed) r->removed++;
    else r->kept++;
}

static void test_stale_outputs(void **state)
{
    (void)state;
    char p[256], out[256];
    snprintf(out, sizeof out, "%s/out.exr", dir);
    snprintf(p, sizeof p, "%s/out.exr.tmp-%ld", dir, (long)dead_pid());
    touch(p);
    char live[256];
    snprintf(live, sizeof live, "%s/out.exr.tmp-%ld", dir, (long)getppid());
    touch(live);
    char other[256];
    snprintf(other, sizeof other, "%s/out.exr.tmp-12x", dir);
    touch(other);
    reports r = {0, 0};
    assert_int_equal(stale_clean_outputs(out, count_report, &r), 1);
    assert_int_equal(r.removed, 1);
    assert_int_equal(r.kept, 1);
    assert_int_equal(access(p, F_OK), -1);
    assert_int_equal(access(live, F_OK), 0);
    assert_int_equal(access(other, F_OK), 0);
}

static void make_ipc_dir(const char *name, long pid, bool foreign)
{
    char d[256], p[300];
    snprintf(d, sizeof d, "%s/%s", dir, name);
    assert_int_equal(mkdir(d, 0700), 0);
    snprintf(p, sizeof p, "%s/master.sock", d);
    touch(p);
    snprintf(p, sizeof p, "%s/%s", d, STALE_PID_FILE);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fprintf(f, "%ld\n", pid);
    fclose(f);
    if (foreign) {
        snprintf(p, sizeof p, "%s/notes.txt", d);
        touch(p);
    }
}

static void test_stale_ipc_dirs(void **state)
{
    (void)state;
    make_ipc_dir("aafarm-dead01", (long)dead_pid(), false);
    make_ipc_dir("aafarm-live01", (long)getppid(), false);
    make_ipc_dir("aafarm-mixed1", (long)dead_pid(), true);
    reports r = {0, 0};
    assert_int_equal(stale_clean_ipc_dirs(dir, count_report, &r), 1);
    assert_int_equal(r.removed, 1);
    assert_int_equal(r.kept, 0);   /* running masters' folders are not news */
    char p[256];
    snprintf(p, sizeof p, "%s/aafarm-dead01", dir);
    assert_int_equal(access(p, F_OK), -1);
    snprintf(p, sizeof p, "%s/aafarm-live01", dir);
    assert_int_equal(access(p, F_OK), 0);
    snprintf(p, sizeof p, "%s/aafarm-mixed1/notes.txt", dir);
    assert_int_equal(access(p, F_OK), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_journal_replays_in_order, setup, teardown),
        cmocka_unit_test_setup_teardown(test_journal_torn_tail_dropped, setup, teardown),
        cmocka_unit_test_setup_teardown(test_journal_garbage_and_flipped_byte, setup, teardown),
        cmocka_unit_test_setup_teardown(test_journal_other_job_refused, setup, teardown),
        cmocka_unit_test_setup_teardown(test_journal_missing_and_locked, setup, teardown),
        cmocka_unit_test_setup_teardown(test_journal_crc32_check_value, setup, teardown),
        cmocka_unit_test_setup_teardown(test_stale_outputs, setup, teardown),
        cmocka_unit_test_setup_teardown(test_stale_ipc_dirs, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_file_store.c: the worker's content-addressed store of job files
 * (worker/file_store.h) on a real folder: a transfer written chunk by
 * chunk lands under its hash only when its bytes hash to it; chunks not
 * asked, duplicated or misaligned are refused; a transfer abandoned half
 * way resumes from the chunks written; a second fetcher of the same file
 * is told to wait (the lock); a corrupt object is found by its hash and
 * removed; eviction under a byte budget removes the least recently used
 * files first and never a file in use; a folder others may write is refused.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "file_store.h"
#include "util/hash.h"

static char dir[64];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-test-store-XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* n pseudo-random bytes (seeded) and their hash. */
static uint8_t *make_bytes(size_t n, uint32_t seed, char hex[HASH_HEX_SIZE])
{
    uint8_t *b = malloc(n + 1);
    assert_non_null(b);
    uint32_t x = seed | 1;
    for (size_t i = 0; i < n; i++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        b[i] = (uint8_t)x;
    }
    uint8_t d[SHA256_DIGEST_SIZE];
    sha256_digest(b, n, d);
    hash_hex(d, hex);
    return b;
}

/* Fetches the whole file through a transfer, in chunk-sized pieces. */
static void fetch(file_store *st, const uint8_t *b, size_t n, const char *hex, uint32_t chunk)
{
    file_transfer *t = NULL;
    char err[600];
    assert_int_equal(file_store_begin(st, hex, n, chunk, &t, err, sizeof err), FILE_BEGIN_STARTED);
    uint64_t off;
    uint32_t len;
    while (file_transfer_next(t, &off, &len))
        assert_int_equal(file_transfer_put(t, off, b + off, len, err, sizeof err), (long)len);
    assert_true(file_transfer_complete(t));
    assert_int_equal(file_transfer_finish(&t, err, sizeof err), 0);
    assert_null(t);
}

static uint64_t sum_file(const char *path, char hex[HASH_HEX_SIZE])
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    sha256 h;
    sha256_init(&h);
    uint8_t buf[4096];
    size_t got;
    uint64_t n = 0;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        sha256_update(&h, buf, got);
        n += got;
    }
    fclose(f);
    uint8_t d[SHA256_DIGEST_SIZE];
    sha256_final(&h, d);
    hash_hex(d, hex);
    return n;
}

static void test_transfer_lands_under_its_hash(void **state)
{
    (void)state;
    char err[600], hex[HASH_HEX_SIZE], got[HASH_HEX_SIZE], path[PATH_MAX + 100];
    file_store *st = file_store_open(dir, 0, err, sizeof err);
    assert_non_null(st);
    size_t n = 100000;
    uint8_t *b = make_bytes(n, 7, hex);
    assert_int_equal(file_store_acquire(st, hex, n, path, sizeof path), -1);

    file_transfer *t = NULL;
    assert_int_equal(file_store_begin(st, hex, n, 16384, &t, err, sizeof err), FILE_BEGIN_STARTED);
    /* misaligned, wrong length, past the end: refused */
    assert_int_equal(file_transfer_put(t, 100, b + 100, 16384, err, sizeof err), 0);
    assert_int_equal(file_transfer_put(t, 0, b, 100, err, sizeof err), 0);
    assert_int_equal(file_transfer_put(t, 200000, b, 16384, err, sizeof err), 0);
    /* the last chunk is short: 100000 = 6 x 16384 + 1696 */
    assert_int_equal(file_transfer_put(t, 98304, b + 98304, 1696, err, sizeof err), 1696);
    assert_int_equal(file_transfer_put(t, 98304, b + 98304, 1696, err, sizeof err), 0);
    assert_int_equal(file_transfer_missing(t), n - 1696);
    uint64_t off;
    uint32_t len;
    int chunks = 0;
    while (file_transfer_next(t, &off, &len)) {
        assert_int_equal(file_transfer_put(t, off, b + off, len, err, sizeof err), (long)len);
        chunks++;
    }
    assert_int_equal(chunks, 6);
    assert_true(file_transfer_complete(t));
    assert_int_equal(file_transfer_finish(&t, err, sizeof err), 0);

    int fd = file_store_acquire(st, hex, n, path, sizeof path);
    assert_true(fd >= 0);
    assert_int_equal(sum_file(path, got), n);
    assert_string_equal(got, hex);
    file_store_release(fd);
    /* the size is part of what is asked for */
    assert_int_equal(file_store_acquire(st, hex, n + 1, path, sizeof path), -1);
    free(b);
    file_store_close(&st);
}

static void test_wrong_bytes_are_discarded(void **state)
{
    (void)state;
    char err[600], hex[HASH_HEX_SIZE], other[HASH_HEX_SIZE], path[PATH_MAX + 100];
    file_store *st = file_store_open(dir, 0, err, sizeof err);
    size_t n = 50000;
    uint8_t *b = make_bytes(n, 11, hex);
    uint8_t *c = make_bytes(n, 13, other);
    file_transfer *t = NULL;
    assert_int_equal(file_store_begin(st, hex, n, 8192, &t, err, sizeof err), FILE_BEGIN_STARTED);
    uint64_t off;
    uint32_t len;
    while (file_transfer_next(t, &off, &len))
        file_transfer_put(t, off, c + off, len, err, sizeof err);   /* another file's bytes */
    assert_int_equal(file_transfer_finish(&t, err, sizeof err), -1);
    assert_non_null(strstr(err, "hash to"));
    assert_int_equal(file_store_acquire(st, hex, n, path, sizeof path), -1);
    /* and the next attempt starts from nothing */
    assert_int_equal(file_store_begin(st, hex, n, 8192, &t, err, sizeof err), FILE_BEGIN_STARTED);
    assert_int_equal(file_transfer_missing(t), n);
    file_transfer_abandon(&t);
    free(b);
    free(c);
    file_store_close(&st);
}

static void test_abandoned_transfer_resumes_and_locks(void **state)
{
    (void)state;
    char err[600], hex[HASH_HEX_SIZE], path[PATH_MAX + 100];
    file_store *st = file_store_open(dir, 0, err, sizeof err);
    size_t n = 40000;
    uint8_t *b = make_bytes(n, 21, hex);
    file_transfer *t = NULL, *t2 = NULL;
    assert_int_equal(file_store_begin(st, hex, n, 4096, &t, err, sizeof err), FILE_BEGIN_STARTED);
    /* a second fetcher (its own lock description) must wait */
    assert_int_equal(file_store_begin(st, hex, n, 4096, &t2, err, sizeof err), FILE_BEGIN_BUSY);
    assert_null(t2);
    uint64_t off;
    uint32_t len;
    for (int i = 0; i < 4 && file_transfer_next(t, &off, &len); i++)
        assert_int_equal(file_transfer_put(t, off, b + off, len, err, sizeof err), (long)len);
    assert_true(file_transfer_next(t, &off, &len));   /* asked, never answered */
    file_transfer_abandon(&t);                        /* as if the process died */

    /* resumed by a process with another chunk size: the map's size wins */
    assert_int_equal(file_store_begin(st, hex, n, 8192, &t, err, sizeof err), FILE_BEGIN_STARTED);
    assert_int_equal(file_transfer_missing(t), n - 4 * 4096);
    int asked = 0;
    while (file_transfer_next(t, &off, &len)) {
        assert_true(off >= 4 * 4096);   /* only the chunks it lacks */
        assert_true(len <= 4096);
        assert_int_equal(file_transfer_put(t, off, b + off, len, err, sizeof err), (long)len);
        asked++;
    }
    assert_int_equal(asked, 6);   /* ceil(40000 / 4096) = 10 chunks, 4 written before */
    assert_int_equal(file_transfer_finish(&t, err, sizeof err), 0);
    /* another chunk size cannot use the map: but the file is whole now */
    assert_int_equal(file_store_begin(st, hex, n, 8192, &t, err, sizeof err), FILE_BEGIN_PRESENT);
    int fd = file_store_acquire(st, hex, n, path, sizeof path);
    assert_true(fd >= 0);
    file_store_release(fd);
    free(b);
    file_store_close(&st);
}

static void test_corrupt_object_is_found_by_hash(void **state)
{
    (void)state;
    char err[600], hex[HASH_HEX_SIZE], path[PATH_MAX + 100];
    file_store *st = file_store_open(dir, 0, err, sizeof err);
    size_t n = 30000;
    uint8_t *b = make_bytes(n, 31, hex);
    fetch(st, b, n, hex, 8192);
    file_store_close(&st);
    /* a bit flips on disk; same size */
    char obj[PATH_MAX];
    snprintf(obj, sizeof obj, "%s/objects/%s", dir, hex);
    int fd = open(obj, O_WRONLY);
    assert_true(fd >= 0);
    uint8_t x = (uint8_t)(b[1234] ^ 0x10);
    assert_int_equal(pwrite(fd, &x, 1, 1234), 1);
    close(fd);
    /* a new process (store) checks the hash on first use, removes it */
    st = file_store_open(dir, 0, err, sizeof err);
    assert_int_equal(file_store_acquire(st, hex, n, path, sizeof path), -1);
    assert_int_equal(access(obj, F_OK), -1);
    fetch(st, b, n, hex, 8192);   /* and it can be fetched again */
    fd = file_store_acquire(st, hex, n, path, sizeof path);
    assert_true(fd >= 0);
    file_store_release(fd);
    free(b);
    file_store_close(&st);
}

/* A later process trusts an object as its stamp recorded it, without
 * hashing it again; a stamp that does not match (changed object, broken
 * stamp) costs a hash, never trust. */
static void test_stamp_spares_the_hash(void **state)
{
    (void)state;
    char err[600], hex[HASH_HEX_SIZE], path[PATH_MAX + 100];
    unsigned long hashed, stamped;
    file_store *st = file_store_open(dir, 0, err, sizeof err);
    size_t n = 20000;
    uint8_t *b = make_bytes(n, 47, hex);
    fetch(st, b, n, hex, 4096);
    file_store_close(&st);

    st = file_store_open(dir, 0, err, sizeof err);   /* "another process" */
    int fd = file_store_acquire(st, hex, n, path, sizeof path);
    assert_true(fd >= 0);
    file_store_release(fd);
    file_store_checks(st, &hashed, &stamped);
    assert_int_equal(hashed, 0);
    assert_int_equal(stamped, 1);
    file_store_close(&st);

    /* a broken stamp: hashed, found good, stamped anew */
    char stamp[PATH_MAX];
    snprintf(stamp, sizeof stamp, "%s/verified/%s", dir, hex);
    FILE *f = fopen(stamp, "w");
    assert_non_null(f);
    fputs("not a stamp\n", f);
    fclose(f);
    st = file_store_open(dir, 0, err, sizeof err);
    fd = file_store_acquire(st, hex, n, path, sizeof path);
    assert_true(fd >= 0);
    file_store_release(fd);
    file_store_checks(st, &hashed, &stamped);
    assert_int_equal(hashed, 1);
    assert_int_equal(stamped, 0);
    file_store_close(&st);

    /* a write right after the last use (same size): the mtime moves, the
     * stamp no longer matches, the hash finds it, the object goes */
    char obj[PATH_MAX];
    snprintf(obj, sizeof obj, "%s/objects/%s", dir, hex);
    int w = open(obj, O_WRONLY);
    assert_true(w >= 0);
    uint8_t x = (uint8_t)(b[77] ^ 0x01);
    assert_int_equal(pwrite(w, &x, 1, 77), 1);
    close(w);
    st = file_store_open(dir, 0, err, sizeof err);
    assert_int_equal(file_store_acquire(st, hex, n, path, sizeof path), -1);
    file_store_checks(st, &hashed, &stamped);
    assert_int_equal(hashed, 1);
    assert_int_equal(access(obj, F_OK), -1);
    assert_int_equal(access(stamp, F_OK), -1);       /* the stamp went with it */
    file_store_close(&st);
    free(b);
}

static void set_age(const char *folder, const char *hex, time_t seconds_ago)
{
    char obj[PATH_MAX];
    snprintf(obj, sizeof obj, "%s/objects/%s", folder, hex);
    struct timespec ts[2];
    clock_gettime(CLOCK_REALTIME, &ts[0]);
    ts[0].tv_sec -= seconds_ago;
    ts[1] = ts[0];
    if (utimensat(AT_FDCWD, obj, ts, 0) != 0) fail_msg("utimensat %s: %s", obj, strerror(errno));
}

static void test_eviction_is_lru_and_spares_files_in_use(void **state)
{
    (void)state;
    char err[600], path[PATH_MAX + 100];
    char hex[4][HASH_HEX_SIZE];
    uint8_t *b[4];
    size_t n = 100000;
    char sub[128];
    snprintf(sub, sizeof sub, "%s/lru", dir);
    file_store *st = file_store_open(sub, 250000, err, sizeof err);
    assert_non_null(st);
    for (int i = 0; i < 3; i++) {
        b[i] = make_bytes(n, 101u + 2u * (uint32_t)i, hex[i]);
        fetch(st, b[i], n, hex[i], 65536);
    }
    /* ages: 0 oldest, then 1, then 2 */
    set_age(sub, hex[0], 300);
    set_age(sub, hex[1], 200);
    set_age(sub, hex[2], 100);
    /* 300000 bytes > 250000: the oldest goes */
    assert_int_equal(file_store_evict(st), 1);
    assert_int_equal(file_store_acquire(st, hex[0], n, path, sizeof path), -1);
    assert_int_equal(file_store_bytes(st), 200000);

    /* file 1 is in use (a job holds it); using it makes it the newest, so
     * age it again: it is the oldest, and still it stays */
    int in_use = file_store_acquire(st, hex[1], n, path, sizeof path);
    assert_true(in_use >= 0);
    set_age(sub, hex[1], 500);
    b[3] = make_bytes(n, 107, hex[3]);
    fetch(st, b[3], n, hex[3], 65536);
    assert_int_equal(file_store_evict(st), 1);
    char obj[PATH_MAX];
    snprintf(obj, sizeof obj, "%s/objects/%s", sub, hex[1]);
    assert_int_equal(access(obj, F_OK), 0);    /* in use: kept */
    snprintf(obj, sizeof obj, "%s/objects/%s", sub, hex[2]);
    assert_int_equal(access(obj, F_OK), -1);   /* the oldest not in use: gone */
    file_store_release(in_use);
    /* released, it may go */
    set_age(sub, hex[1], 500);
    fetch(st, b[0], n, hex[0], 65536);
    assert_int_equal(file_store_evict(st), 1);
    snprintf(obj, sizeof obj, "%s/objects/%s", sub, hex[1]);
    assert_int_equal(access(obj, F_OK), -1);
    assert_true(file_store_bytes(st) <= 250000);
    for (int i = 0; i < 4; i++) free(b[i]);
    file_store_close(&st);
}

static void test_unusable_folder_is_said(void **state)
{
    (void)state;
    char err[600], sub[PATH_MAX];
    snprintf(sub, sizeof sub, "%s/plainfile", dir);
    FILE *f = fopen(sub, "w");
    assert_non_null(f);
    fclose(f);
    snprintf(sub, sizeof sub, "%s/plainfile/cache", dir);
    assert_null(file_store_open(sub, 0, err, sizeof err));
    assert_non_null(strstr(err, "--file-cache"));
    assert_non_null(strstr(err, "plainfile"));
    /* a folder others may write is not trusted */
    snprintf(sub, sizeof sub, "%s/open", dir);
    assert_int_equal(mkdir(sub, 0700), 0);
    assert_int_equal(chmod(sub, 0777), 0);
    assert_null(file_store_open(sub, 0, err, sizeof err));
    assert_non_null(strstr(err, "not this user's own"));
    assert_int_equal(chmod(sub, 0700), 0);
    file_store *st = file_store_open(sub, 0, err, sizeof err);
    assert_non_null(st);
    file_store_close(&st);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_transfer_lands_under_its_hash),
        cmocka_unit_test(test_wrong_bytes_are_discarded),
        cmocka_unit_test(test_abandoned_transfer_resumes_and_locks),
        cmocka_unit_test(test_corrupt_object_is_found_by_hash),
        cmocka_unit_test(test_stamp_spares_the_hash),
        cmocka_unit_test(test_eviction_is_lru_and_spares_files_in_use),
        cmocka_unit_test(test_unusable_folder_is_said),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

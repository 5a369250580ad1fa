/*
 * test_file_server.c: the master's file server (master/file_server.c) on a
 * real file: a chunk is read as it is on disk, a range outside the file and
 * an unknown hash are a peer's mistakes, and a chunk buffer that cannot be
 * allocated (the size a worker chose, up to 16 MiB) is refused with
 * FILE_READ_NO_MEMORY and a message, not an abort: the process is held
 * under an address-space limit (RLIMIT_AS) in a child.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "file_server.h"
#include "util/err.h"
#include "util/hash.h"

#if defined(__SANITIZE_ADDRESS__)
#define UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define UNDER_ASAN 1
#endif
#endif

static char dir[64], path[128];
static job jb;
static job_file file;

enum { FILE_BYTES = 100000, BIG_CHUNK = 16u << 20 };

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/aafarm-file-server-XXXXXX");
    if (!mkdtemp(dir)) return -1;
    snprintf(path, sizeof path, "%s/map.bin", dir);
    int fd = open(path, O_RDWR | O_CREAT | O_TRUNC, 0600);
    if (fd < 0) return -1;
    for (int i = 0; i < FILE_BYTES; i++) {
        uint8_t b = (uint8_t)(i * 7 + 3);
        if (write(fd, &b, 1) != 1) return -1;
    }
    uint64_t len = 0;
    bool ok = hash_fd(fd, file.sha256, &len);
    close(fd);
    if (!ok || len != FILE_BYTES) return -1;
    file.name = "map.bin";
    file.path = path;
    file.size = FILE_BYTES;   /* not stamped: the server hashes it once */
    jb.files = &file;
    jb.nfiles = 1;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    unlink(path);
    rmdir(dir);
    return 0;
}

static void test_reads_chunks(void **state)
{
    (void)state;
    file_server *fs = file_server_new(&jb);
    const uint8_t *data = NULL;
    const job_file *f = NULL;
    char err[2 * ERR_LEN] = "";
    assert_int_equal(file_server_read(fs, file.sha256, 1000, 4096, &data, &f, err, sizeof err),
                     FILE_READ_OK);
    assert_ptr_equal(f, &file);
    for (int i = 0; i < 4096; i++) assert_int_equal(data[i], (uint8_t)((1000 + i) * 7 + 3));
    assert_int_equal(file_server_read(fs, file.sha256, FILE_BYTES - 10, 11, &data, &f, err,
                                      sizeof err), FILE_READ_RANGE);
    char other[HASH_HEX_SIZE];
    memset(other, '0', 64);
    other[64] = '\0';
    assert_int_equal(file_server_read(fs, other, 0, 10, &data, &f, err, sizeof err),
                     FILE_READ_UNKNOWN);
    file_server_destroy(&fs);
    assert_null(fs);
}

#ifndef UNDER_ASAN
/* In a child: the address space held to what it uses now plus 4 MiB, a
 * 16 MiB chunk asked for. Exit 0 when it was refused with the message. */
static int read_big_chunk_without_memory(void)
{
    file_server *fs = file_server_new(&jb);
    const uint8_t *data = NULL;
    const job_file *f = NULL;
    char err[2 * ERR_LEN] = "";
    /* a small chunk first: the file is open and hashed, its buffer small */
    if (file_server_read(fs, file.sha256, 0, 100, &data, &f, err, sizeof err) != FILE_READ_OK)
        return 2;
    long pages = 0;
    FILE *statm = fopen("/proc/self/statm", "r");
    if (!statm || fscanf(statm, "%ld", &pages) != 1) return 3;
    fclose(statm);
    rlim_t now = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE);
    struct rlimit lim = {now + (4u << 20), now + (4u << 20)};
    if (setrlimit(RLIMIT_AS, &lim) != 0) return 4;
    /* a made-up file of the job as big as a chunk: the range check passes */
    file.size = BIG_CHUNK;
    file_read r = file_server_read(fs, file.sha256, 0, BIG_CHUNK, &data, &f, err, sizeof err);
    if (r != FILE_READ_NO_MEMORY) return 5;
    if (strcmp(err, "file 'map.bin': no memory for a chunk of 16777216 bytes (the master is "
                    "out of memory)") != 0) {
        fprintf(stderr, "got: %s\n", err);
        return 6;
    }
    /* the smaller buffer it had is still there */
    if (file_server_read(fs, file.sha256, 0, 100, &data, &f, err, sizeof err) != FILE_READ_OK)
        return 7;
    file_server_destroy(&fs);
    return 0;
}
#endif

static void test_no_memory_is_refused(void **state)
{
    (void)state;
#ifdef UNDER_ASAN
    skip();   /* the sanitizer's shadow memory does not live under RLIMIT_AS */
#else
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) _exit(read_big_chunk_without_memory());
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
#endif
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reads_chunks),
        cmocka_unit_test(test_no_memory_is_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

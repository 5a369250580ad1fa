/*
 * tests/worker/test_fdio.c: common/util/fdio (full reads and writes on a
 * descriptor), which the worker's file store and the master's journal and
 * file server share: a write at an offset reads back whole; a read past
 * the end says so with errno 0 and how much it got; a bad descriptor
 * fails with its errno.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "util/fdio.h"

static void test_roundtrip_and_short(void **state)
{
    (void)state;
    char path[] = "/tmp/aafarm-fdio-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    unlink(path);
    assert_true(fd_write_all(fd, "head", 4));
    unsigned char big[100000];
    for (size_t i = 0; i < sizeof big; i++) big[i] = (unsigned char)(i * 7);
    assert_true(fd_pwrite_all(fd, big, sizeof big, 10));
    unsigned char back[sizeof big];
    size_t got = 0;
    assert_true(fd_pread_all(fd, back, sizeof back, 10, &got));
    assert_int_equal(got, sizeof big);
    assert_memory_equal(back, big, sizeof big);
    char head[4];
    assert_true(fd_pread_all(fd, head, 4, 0, NULL));
    assert_memory_equal(head, "head", 4);
    errno = 12345;
    assert_false(fd_pread_all(fd, back, 50, sizeof big, &got));   /* 10 bytes left */
    assert_int_equal(errno, 0);
    assert_int_equal(got, 10);
    close(fd);
}

static void test_bad_descriptor(void **state)
{
    (void)state;
    char b[8] = {0};
    size_t got = 99;
    assert_false(fd_pread_all(-1, b, sizeof b, 0, &got));
    assert_int_equal(errno, EBADF);
    assert_int_equal(got, 0);
    assert_false(fd_pwrite_all(-1, b, sizeof b, 0));
    assert_int_equal(errno, EBADF);
    assert_false(fd_write_all(-1, b, sizeof b));
    assert_int_equal(errno, EBADF);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roundtrip_and_short),
        cmocka_unit_test(test_bad_descriptor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

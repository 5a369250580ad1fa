/*
 * tests/image/test_image_exrcmp.c: the exrcmp tool (tests/image/exrcmp.c),
 * run as a child process; its path is the test's first argument.
 *
 *   equal files (written in different tile orders) -> exit 0
 *   one tile with other pixels                     -> exit 1
 *   a difference within the given tolerance        -> exit 0
 *   missing file, different image sizes, bad usage -> exit 2
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "image/writer.h"
#include "image_testutil.h"

extern char **environ;

static const char *exrcmp_path;
static char err[512];

/* Runs exrcmp with up to 3 arguments; returns its exit status. */
static int run(const char *a, const char *b, const char *tol)
{
    char *argv[5] = {(char *) exrcmp_path, (char *) a, (char *) b,
                     (char *) tol, NULL};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", 1, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", 1, 0);
    pid_t pid;
    int rc = posix_spawn(&pid, exrcmp_path, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    assert_int_equal(rc, 0);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    return WEXITSTATUS(status);
}

/* Writes fmt's image; tile (1,0) gets `bump` added to its R values. */
static void write_image(const char *path, const image_format *fmt,
                        bool reverse, float bump)
{
    image_writer *w = image_writer_new(path, fmt, err, sizeof err);
    assert_non_null(w);
    int n = image_format_tile_count(fmt), nx = image_format_tiles_x(fmt);
    for (int k = 0; k < n; k++) {
        int i = reverse ? n - 1 - k : k;
        image_tile *t = tu_tile(fmt, i % nx, i / nx, 5, false);
        if (i == 1)
            for (int p = 0; p < t->w * t->h; p++)
                t->rgba[4 * p] = 1.0f + bump;
        assert_true(image_writer_put_tile(w, t, err, sizeof err));
        image_tile_destroy(&t);
    }
    assert_true(image_writer_finish(&w, err, sizeof err));
}

static void test_exrcmp(void **state)
{
    const char *dir = *state;
    image_format fmt = {40, 20, 16, IMAGE_LAYER_P};
    image_format other = {41, 20, 16, IMAGE_LAYER_P};
    const char *a = tu_path(dir, "a.exr"), *b = tu_path(dir, "b.exr");
    write_image(a, &fmt, false, 0.0f);
    write_image(b, &fmt, true, 0.0f);
    assert_int_equal(run(a, b, NULL), 0);
    write_image(b, &fmt, true, 0.5f);          /* 1.5 exactly in half */
    assert_int_equal(run(a, b, NULL), 1);
    assert_int_equal(run(a, b, "0.5"), 0);
    assert_int_equal(run(a, b, "0.4"), 1);
    const char *c = tu_path(dir, "c.exr");
    write_image(c, &other, false, 0.0f);
    assert_int_equal(run(a, c, NULL), 2);
    assert_int_equal(run(a, tu_path(dir, "none.exr"), NULL), 2);
    assert_int_equal(run(a, NULL, NULL), 2);
    assert_int_equal(run(a, b, "-1"), 2);
}

static int make_dir(void **state)
{
    *state = tu_make_dir();
    return *state ? 0 : -1;
}

static int remove_dir(void **state)
{
    char *dir = *state;
    tu_remove_dir(&dir);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s path/to/exrcmp\n", argv[0]);
        return 2;
    }
    exrcmp_path = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_exrcmp, make_dir, remove_dir),
    };
    return cmocka_run_group_tests_name("image_exrcmp", tests, NULL, NULL);
}

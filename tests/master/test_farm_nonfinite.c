/*
 * test_farm_nonfinite.c: a surface shader writing NaN, +Inf and -Inf
 * (Ci = color(0/0, 1/0, -1/0) on half of a square), with real processes:
 *   - the standalone renderer exits 0, warns once with the count and the
 *     first pixel, reports the count in --stats-json, and its EXR holds no
 *     non-finite R, G, B or A sample (they were written as 0);
 *   - the farm (embedded master, two local workers) counts the same
 *     number (the count is a pure function of the scene), warns, reports
 *     it in --stats-json, and its image equals the standalone one;
 *   - a scene without such a shader counts 0 and does not warn.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include "farm_testutil.h"
#include "image/buffer.h"

static char *dir;

static int group_setup(void **state)
{
    (void)state;
    return ft_group_begin(&dir, FT_SCENE_NAN, 0);
}

static int standalone(const char *scene, const char *out, const char *json, const char *log)
{
    const char *argv[] = {ft_worker, "--standalone", scene, "-o", out, "--tile", "8",
                          "--threads", "2", "--stats-json", json, NULL};
    return ft_wait(ft_spawn(log, argv), 120);
}

static long nonfinite_in(const char *exr)
{
    char err[512];
    image_buffer *b = image_buffer_read_exr(exr, err, sizeof err);
    assert_non_null(b);
    long n = 0;
    const char *names[] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; c++) {
        const float *v = image_buffer_channel(b, names[c]);
        assert_non_null(v);
        for (long i = 0; i < (long)b->width * b->height; i++)
            if (!isfinite(v[i])) n++;
    }
    image_buffer_destroy(&b);
    return n;
}

static void test_nonfinite_counted_written_as_zero(void **state)
{
    (void)state;
    const char *sa_log = ft_path(dir, "sa.log");
    assert_int_equal(standalone(ft_path(dir, "scene.rib"), ft_path(dir, "sa.exr"),
                                ft_path(dir, "sa.json"), sa_log), 0);
    long n = ft_json_number(ft_path(dir, "sa.json"), "nonfinite_samples");
    assert_true(n > 0);
    char needle[128];
    snprintf(needle, sizeof needle, "warning: %ld NaN/Inf samples (the first at pixel (", n);
    assert_int_equal(ft_count(sa_log, needle), 1);
    assert_int_equal(nonfinite_in(ft_path(dir, "sa.exr")), 0);

    const char *log = ft_path(dir, "farm.log"), *json = ft_path(dir, "farm.json");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "farm.exr"),
                          "--tile", "8", "--local-workers", "2", "--stats-json", json, NULL};
    setenv("TMPDIR", dir, 1);
    pid_t master = ft_spawn(log, argv);
    unsetenv("TMPDIR");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_json_number(json, "nonfinite_samples"), n);
    snprintf(needle, sizeof needle, "warning: %ld NaN/Inf samples in ", n);
    assert_int_equal(ft_count(log, needle), 1);
    assert_int_equal(ft_exr_diff(ft_path(dir, "sa.exr"), ft_path(dir, "farm.exr")), 0);
}

static void test_finite_scene_counts_zero(void **state)
{
    (void)state;
    char *wave = ft_tempdir();
    ft_write_scene(wave, FT_SCENE_WAVE);
    const char *log = ft_path(wave, "sa.log");
    assert_int_equal(standalone(ft_path(wave, "scene.rib"), ft_path(wave, "sa.exr"),
                                ft_path(wave, "sa.json"), log), 0);
    assert_int_equal(ft_json_number(ft_path(wave, "sa.json"), "nonfinite_samples"), 0);
    assert_int_equal(ft_count(log, "NaN/Inf"), 0);
    ft_rmtree(wave);
    free(wave);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nonfinite_counted_written_as_zero),
        cmocka_unit_test(test_finite_scene_counts_zero),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}

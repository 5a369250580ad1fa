/*
 * tests/tex/test_tex_maketx.c: the aafarm-maketx command (docs/textures.md).
 * Runs the built tool (its path from CMake) in a child process, output to
 * files, killed by SIGKILL after 30 s and reaped by its PID:
 *   --help: status 0 and the usage; no files, an unknown option, a bad
 *   --fbm size: status 2 and a message; a missing input: status 1 naming
 *   it; an unwritable output: status 1 and no file left behind (not even
 *   the temporary one); a PNG made here: the written texture has its
 *   texels; --fbm W H: a W x H one-channel map, not constant, within
 *   [-2, 2].
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <png.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "tex/tex.h"

#ifndef AAFARM_MAKETX
#define AAFARM_MAKETX "aafarm-maketx"
#endif

static char dir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/test_tex_maketx.XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Runs aafarm-maketx with args (NULL-terminated); its stdout + stderr into
 * out. Returns the exit status (-1 if killed). */
static int run(char *out, size_t size, ...)
{
    char *argv[16] = { (char *)AAFARM_MAKETX };
    int argc = 1;
    va_list ap;
    va_start(ap, size);
    for (char *a; argc < 15 && (a = va_arg(ap, char *)) != NULL;)
        argv[argc++] = a;
    va_end(ap);
    argv[argc] = NULL;
    char log[300];
    snprintf(log, sizeof log, "%s/log.txt", dir);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        FILE *f = freopen(log, "w", stdout);
        if (!f || dup2(fileno(stdout), 2) < 0)
            _exit(127);
        execv(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    for (int waited = 0; waitpid(pid, &status, WNOHANG) == 0; waited++) {
        if (waited > 3000) {               /* 30 s: the watchdog */
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            return -1;
        }
        usleep(10000);
    }
    FILE *f = fopen(log, "r");
    size_t n = f ? fread(out, 1, size - 1, f) : 0;
    out[n] = 0;
    if (f)
        fclose(f);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static void test_usage_errors(void **state)
{
    (void)state;
    char out[4096];
    assert_int_equal(run(out, sizeof out, "--help", NULL), 0);
    assert_non_null(strstr(out, "usage: aafarm-maketx"));
    assert_int_equal(run(out, sizeof out, NULL), 2);
    assert_non_null(strstr(out, "give an input image and an output file"));
    assert_int_equal(run(out, sizeof out, "--sharpen", "a.png", "b.exr", NULL), 2);
    assert_non_null(strstr(out, "unknown option '--sharpen'"));
    assert_int_equal(run(out, sizeof out, "--fbm", "0", "10", "x.exr", NULL), 2);
    assert_non_null(strstr(out, "--fbm takes a width and a height"));
    char missing[300], dst[300];
    snprintf(missing, sizeof missing, "%s/missing.png", dir);
    snprintf(dst, sizeof dst, "%s/out.exr", dir);
    assert_int_equal(run(out, sizeof out, missing, dst, NULL), 1);
    assert_non_null(strstr(out, missing));
    assert_int_equal(access(dst, F_OK), -1);
}

static void test_unwritable_output_leaves_nothing(void **state)
{
    (void)state;
    char out[4096], sub[280], dst[320];
    snprintf(sub, sizeof sub, "%s/ro", dir);
    assert_int_equal(mkdir(sub, 0500), 0);
    snprintf(dst, sizeof dst, "%s/map.exr", sub);
    int st = run(out, sizeof out, "--fbm", "16", "16", dst, NULL);
    if (geteuid() != 0) {                /* root writes anywhere: nothing to see */
        assert_int_equal(st, 1);
        assert_non_null(strstr(out, "cannot write the texture"));
    }
    chmod(sub, 0700);
    DIR *d = opendir(sub);
    int files = 0;
    for (struct dirent *e; d && (e = readdir(d)) != NULL;)
        files += e->d_name[0] != '.' && strstr(e->d_name, ".tmp") != NULL;
    if (d)
        closedir(d);
    assert_int_equal(files, 0);
    snprintf(dst, sizeof dst, "%s/nodir/map.exr", dir);
    assert_int_equal(run(out, sizeof out, "--fbm", "16", "16", dst, NULL), 1);
    assert_non_null(strstr(out, "nodir/map.exr: cannot write the texture"));
}

static void test_png_and_fbm(void **state)
{
    (void)state;
    char src[300], dst[300], out[4096], err[512];
    snprintf(src, sizeof src, "%s/in.png", dir);
    snprintf(dst, sizeof dst, "%s/in.exr", dir);
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = 37;
    img.height = 21;
    img.format = PNG_FORMAT_RGB;
    unsigned char px[37 * 21 * 3];
    for (size_t k = 0; k < sizeof px; k++)
        px[k] = (unsigned char)(k * 7919 % 251);
    assert_true(png_image_write_to_file(&img, src, 0, px, 0, NULL));
    assert_int_equal(run(out, sizeof out, src, dst, NULL), 0);
    assert_non_null(strstr(out, "37 x 21, 3 channels"));
    tex_texture *a = tex_open(src, err, sizeof err), *b = tex_open(dst, err, sizeof err);
    assert_non_null(a);
    assert_non_null(b);
    assert_int_equal(tex_channels(b), 3);
    for (int j = 0; j < 21; j++)
        for (int i = 0; i < 37; i++)
            for (int c = 0; c < 3; c++)
                assert_true(tex_texel(a, 0, c, i, j) == tex_texel(b, 0, c, i, j));
    tex_destroy(&a);
    tex_destroy(&b);

    snprintf(dst, sizeof dst, "%s/fbm.exr", dir);
    assert_int_equal(run(out, sizeof out, "--fbm", "48", "20", "--octaves", "4", dst, NULL), 0);
    tex_texture *f = tex_open(dst, err, sizeof err);
    assert_non_null(f);
    assert_int_equal(tex_width(f), 48);
    assert_int_equal(tex_height(f), 20);
    assert_int_equal(tex_channels(f), 1);
    double lo = 1e9, hi = -1e9;
    for (int j = 0; j < 20; j++)
        for (int i = 0; i < 48; i++) {
            lo = fmin(lo, tex_texel(f, 0, 0, i, j));
            hi = fmax(hi, tex_texel(f, 0, 0, i, j));
        }
    assert_true(lo >= -2 && hi <= 2 && hi - lo > 0.1);
    /* the range it prints is the texels' (within the bilinear filter's
     * rounding), not the top level's mean */
    double plo, phi;
    const char *said = strstr(out, "channel 0 in [");
    assert_non_null(said);
    assert_int_equal(sscanf(said, "channel 0 in [%lf, %lf]", &plo, &phi), 2);
    assert_true(fabs(plo - lo) <= 1e-6 * (1 + fabs(lo)) && fabs(phi - hi) <= 1e-6 * (1 + fabs(hi)));
    tex_destroy(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_usage_errors),
        cmocka_unit_test(test_unwritable_output_leaves_nothing),
        cmocka_unit_test(test_png_and_fbm),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

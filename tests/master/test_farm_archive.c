/*
 * test_farm_archive.c: the scenes users bring, through the farm: a scene
 * whose geometry lives in a gzip-compressed archive (bicubic b-spline
 * patches and a holed general polygon) placed twice as instances of one
 * object, rendered by a master and a worker over tcp://127.0.0.1, equals
 * the standalone render pixel for pixel, although the archive files are
 * deleted from disk after the master has read the job and before the
 * worker starts: the archive travels inside the job.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "farm_testutil.h"

static char *dir;

static const char *archive_text =
    "Basis \"b-spline\" 1 \"b-spline\" 1\n"
    "PatchMesh \"bicubic\" 4 \"nonperiodic\" 4 \"nonperiodic\" \"P\" [\n"
    " -1 -1 0  -0.3 -1 0.5  0.3 -1 -0.5  1 -1 0   -1 -0.3 0.4  -0.3 -0.3 1  0.3 -0.3 0  1 -0.3 0.3\n"
    " -1 0.3 -0.2  -0.3 0.3 0.2  0.3 0.3 0.8  1 0.3 0   -1 1 0  -0.3 1 0.3  0.3 1 0  1 1 0.2]\n"
    "PointsGeneralPolygons [2] [4 3] [0 1 2 3 4 5 6] \"P\" [1 -1 0.5  2 -1 0.5  2 0 0.5"
    "  1 0 0.5  1.3 -0.7 0.5  1.6 -0.7 0.5  1.3 -0.3 0.5]\n";

static const char *scene_text =
    "Format 48 32 1\nPixelSamples 1 1\nProjection \"perspective\" \"fov\" [40]\n"
    "Translate 0 0 4\nWorldBegin\n"
    "LightSource \"distantlight\" 1 \"from\" [0 1 -1] \"to\" [0 0 0]\n"
    "ObjectBegin 1\nReadArchive \"parts/obj.rib.gz\"\nObjectEnd\n"
    "Translate -0.8 0 0\nObjectInstance 1\nTranslate 0.3 0.4 1\nObjectInstance 1\n"
    "WorldEnd\n";

static int setup(void **state)
{
    (void)state;
    dir = ft_tempdir();
    if (mkdir(ft_path(dir, "parts"), 0700) != 0)
        return -1;
    gzFile gz = gzopen(ft_path(dir, "parts/obj.rib.gz"), "wb");
    if (!gz || gzwrite(gz, archive_text, (unsigned)strlen(archive_text)) <= 0 ||
        gzclose(gz) != Z_OK)
        return -1;
    FILE *f = fopen(ft_path(dir, "scene.rib"), "w");
    if (!f)
        return -1;
    fputs(scene_text, f);
    fclose(f);
    if (ft_standalone(dir, 8) != 0) {
        fprintf(stderr, "the standalone reference render failed:\n%s\n",
                ft_read(ft_path(dir, "standalone.log")));
        return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    ft_stop_all();
    ft_rmtree(dir);
    free(dir);
    return 0;
}

static void test_archive_travels_in_the_job(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "master.log");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "farm.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "8", NULL};
    pid_t master = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 30));
    /* the master has read the job: the worker must not need the files */
    assert_int_equal(unlink(ft_path(dir, "parts/obj.rib.gz")), 0);
    assert_int_equal(rmdir(ft_path(dir, "parts")), 0);
    const char *wargv[] = {ft_worker, "--connect", ep, "--name", "w", "--threads", "2", NULL};
    pid_t worker = ft_spawn(ft_path(dir, "worker.log"), wargv);
    int status = ft_wait(master, 120);
    if (status != 0)
        fprintf(stderr, "master:\n%s\nworker:\n%s\n", ft_read(log),
                ft_read(ft_path(dir, "worker.log")));
    assert_int_equal(status, 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "farm.exr")), 0);
    kill(worker, SIGTERM);
    assert_int_equal(ft_wait(worker, 20), 130);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv))
        return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_archive_travels_in_the_job),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

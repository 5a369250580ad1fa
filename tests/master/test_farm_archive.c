/*
 * test_farm_archive.c: big geometry on the farm (issue 23). A scene whose
 * geometry lives in gzip-compressed archives: a height field of 152,100
 * quads (PointsPolygons, ~7.6 MB of RIB uncompressed: over the 4 MiB a
 * Job message may carry per source) and a small archive of b-spline
 * patches and a holed general polygon placed twice as instances of one
 * object. A master and two workers sharing one file store over
 * tcp://127.0.0.1 render it equal to the standalone render pixel for
 * pixel, and:
 *   - the archives are files of the job (content-addressed, hashed as
 *     compressed on disk): the Job message stays small (a few KiB);
 *   - the host receives each archive once (file_bytes_sent = the gzip
 *     files' sizes, all by one of the two workers);
 *   - each worker parses them from the store (its -v resolver line gives
 *     a path in the store whose bytes hash to the master's file): the
 *     master runs in the scene's folder, the workers elsewhere, so the
 *     archives' names ("parts/mesh.rib.gz") lead nowhere on their side.
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
#include <math.h>
#include <zlib.h>

#include "farm_testutil.h"
#include "util/hash.h"

enum { GRID = 390 };   /* GRID x GRID quads */

static char *dir;
static long mesh_text_bytes;

static const char *small_text =
    "Basis \"b-spline\" 1 \"b-spline\" 1\n"
    "PatchMesh \"bicubic\" 4 \"nonperiodic\" 4 \"nonperiodic\" \"P\" [\n"
    " -1 -1 0  -0.3 -1 0.5  0.3 -1 -0.5  1 -1 0   -1 -0.3 0.4  -0.3 -0.3 1  0.3 -0.3 0  1 -0.3 0.3\n"
    " -1 0.3 -0.2  -0.3 0.3 0.2  0.3 0.3 0.8  1 0.3 0   -1 1 0  -0.3 1 0.3  0.3 1 0  1 1 0.2]\n"
    "PointsGeneralPolygons [2] [4 3] [0 1 2 3 4 5 6] \"P\" [1 -1 0.5  2 -1 0.5  2 0 0.5"
    "  1 0 0.5  1.3 -0.7 0.5  1.6 -0.7 0.5  1.3 -0.3 0.5]\n";

static const char *scene_text =
    "Format 32 32 1\nPixelSamples 1 1\nProjection \"perspective\" \"fov\" [40]\n"
    "Translate 0 0 4\nRotate -40 1 0 0\nWorldBegin\n"
    "LightSource \"distantlight\" 1 \"from\" [0 1 -1] \"to\" [0 0 0]\n"
    "ObjectBegin 1\nReadArchive \"parts/obj.rib.gz\"\nObjectEnd\n"
    "AttributeBegin\nScale 1.5 1.5 1\nReadArchive \"parts/mesh.rib.gz\"\nAttributeEnd\n"
    "Translate -0.8 0 -0.5\nScale 0.4 0.4 0.4\nObjectInstance 1\nTranslate 0.3 0.4 1\n"
    "ObjectInstance 1\nWorldEnd\n";

static void gzip_text(const char *path, const char *text, size_t len)
{
    gzFile gz = gzopen(path, "wb");
    assert_non_null(gz);
    assert_int_equal(gzwrite(gz, text, (unsigned)len), (int)len);
    assert_int_equal(gzclose(gz), Z_OK);
}

/* The height field: (GRID+1)^2 points, GRID^2 quads. */
static char *mesh_text(size_t *len)
{
    size_t cap = (size_t)64 << 20, n = 0;
    char *t = malloc(cap);
    assert_non_null(t);
    n += (size_t)snprintf(t + n, cap - n, "PointsPolygons [");
    for (int i = 0; i < GRID * GRID; i++) n += (size_t)snprintf(t + n, cap - n, "4 ");
    n += (size_t)snprintf(t + n, cap - n, "]\n[");
    for (int y = 0; y < GRID; y++)
        for (int x = 0; x < GRID; x++) {
            int a = y * (GRID + 1) + x;
            n += (size_t)snprintf(t + n, cap - n, "%d %d %d %d\n", a, a + 1, a + GRID + 2,
                                  a + GRID + 1);
        }
    n += (size_t)snprintf(t + n, cap - n, "]\n\"P\" [");
    for (int y = 0; y <= GRID; y++)
        for (int x = 0; x <= GRID; x++) {
            double u = -1 + 2.0 * x / GRID, v = -1 + 2.0 * y / GRID;
            n += (size_t)snprintf(t + n, cap - n, "%.4f %.4f %.4f\n", u, v,
                                  0.08 * sin(7 * u) * cos(5 * v));
        }
    n += (size_t)snprintf(t + n, cap - n, "]\n");
    assert_true(n < cap - 1);
    *len = n;
    return t;
}

static int setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_NONE, 0) != 0) return -1;
    if (mkdir(ft_path(dir, "parts"), 0700) != 0)
        return -1;
    gzip_text(ft_path(dir, "parts/obj.rib.gz"), small_text, strlen(small_text));
    size_t len;
    char *mesh = mesh_text(&len);
    mesh_text_bytes = (long)len;
    gzip_text(ft_path(dir, "parts/mesh.rib.gz"), mesh, len);
    free(mesh);
    FILE *f = fopen(ft_path(dir, "scene.rib"), "w");
    if (!f)
        return -1;
    fputs(scene_text, f);
    fclose(f);
    return ft_standalone(dir, 8) == 0 ? 0 : -1;
}

static long file_size(const char *path)
{
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    return (long)st.st_size;
}

static void sha_of(const char *path, char hex[HASH_HEX_SIZE])
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    sha256 h;
    sha256_init(&h);
    unsigned char buf[65536];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) sha256_update(&h, buf, got);
    fclose(f);
    uint8_t d[SHA256_DIGEST_SIZE];
    sha256_final(&h, d);
    hash_hex(d, hex);
}

/* A number of one worker's entry in the statistics file, -1 when absent. */
static long worker_number(const char *stats, const char *worker, const char *key)
{
    char *text = ft_read(stats);
    char name[160], k[80];
    snprintf(name, sizeof name, "{\"name\": \"%s\"", worker);
    snprintf(k, sizeof k, "\"%s\": ", key);
    char *at = strstr(text, name);
    char *v = at ? strstr(at, k) : NULL;
    char *end = at ? strchr(at, '}') : NULL;
    long n = v && v < end ? strtol(v + strlen(k), NULL, 10) : -1;
    free(text);
    return n;
}

/* The path a worker's resolver gave for the job file `name` (its -v log). */
static char *resolved_path(const char *log, const char *name)
{
    char *text = ft_read(log);
    char needle[1100];
    snprintf(needle, sizeof needle, "file '%s' resolves to ", name);
    char *at = strstr(text, needle);
    if (!at) fail_msg("no resolver line for '%s' in the worker's log:\n%s", name, text);
    at += strlen(needle);
    char *path = strndup(at, strcspn(at, "\n"));
    free(text);
    return path;
}

static void test_big_archive_reaches_each_host_once(void **state)
{
    (void)state;
    assert_true(mesh_text_bytes > 4L << 20);   /* more than a Job source may hold */
    char *log = strdup(ft_path(dir, "master.log")), *stats = strdup(ft_path(dir, "stats.json"));
    char *cache = strdup(ft_path(dir, "cache"));
    /* the master runs in the scene's folder and names it relatively, so
     * its archives are "parts/...": a worker (in this test's folder) that
     * read the master's disk instead of its store would find none */
    char cmd[4096], *master_bin = realpath(ft_master, NULL);
    assert_non_null(master_bin);
    snprintf(cmd, sizeof cmd, "cd '%s' && exec '%s' scene.rib -o farm.exr --bind "
             "tcp://127.0.0.1:* --tile 8 --stats-json stats.json", dir, master_bin);
    free(master_bin);
    const char *argv[] = {"/bin/sh", "-c", cmd, NULL};
    pid_t master = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 60));
    /* slow tiles, so that both workers take part */
    pid_t w[2];
    const char *names[2] = {"a", "b"};
    for (int i = 0; i < 2; i++) {
        char wlog[64];
        snprintf(wlog, sizeof wlog, "worker-%s.log", names[i]);
        const char *wargv[] = {ft_worker, "--connect", ep, "--name", names[i], "--threads", "1",
                               "--file-cache", cache, "--tile-delay", "150", "-v", NULL};
        w[i] = ft_spawn(ft_path(dir, wlog), wargv);
    }
    int status = ft_wait(master, 240);
    if (status != 0)
        fprintf(stderr, "master:\n%s\nworker a:\n%s\n", ft_read(log),
                ft_read(ft_path(dir, "worker-a.log")));
    assert_int_equal(status, 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "farm.exr")), 0);

    long gz_mesh = file_size(ft_path(dir, "parts/mesh.rib.gz"));
    long gz_obj = file_size(ft_path(dir, "parts/obj.rib.gz"));
    /* the archives are the job's files, by their compressed bytes */
    assert_int_equal(ft_json_number(stats, "files"), 2);
    assert_int_equal(ft_json_number(stats, "files_bytes"), gz_mesh + gz_obj);
    /* the Job message carries the RIB, not the model */
    long job_bytes = worker_number(stats, "a", "job_bytes") + worker_number(stats, "b", "job_bytes");
    assert_int_equal(job_bytes, ft_json_number(stats, "job_bytes_sent"));
    assert_true(job_bytes > 0 && job_bytes <= 2 * 8192);
    /* once per host: the two workers share the store, each file crossed
     * once (one worker may fetch one archive while the other fetches the
     * other: the store holds each file's fetch for whoever comes second) */
    assert_int_equal(ft_json_number(stats, "file_bytes_sent"), gz_mesh + gz_obj);
    long fa = worker_number(stats, "a", "file_bytes"), fb = worker_number(stats, "b", "file_bytes");
    printf("file bytes: a %ld, b %ld (archives %ld + %ld)\n", fa, fb, gz_mesh, gz_obj);
    assert_int_equal(fa + fb, gz_mesh + gz_obj);
    assert_true(fa == 0 || fa == gz_mesh || fa == gz_obj || fa == gz_mesh + gz_obj);
    /* each parsed the archives from the store */
    char want[HASH_HEX_SIZE], got[HASH_HEX_SIZE], name[1024];
    sha_of(ft_path(dir, "parts/mesh.rib.gz"), want);
    snprintf(name, sizeof name, "archive:parts/mesh.rib.gz");
    assert_int_equal(access("parts/mesh.rib.gz", F_OK), -1);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(worker_number(stats, names[i], "file_hits") +
                             worker_number(stats, names[i], "file_misses"), 2);
        char wlog[64];
        snprintf(wlog, sizeof wlog, "worker-%s.log", names[i]);
        char *path = resolved_path(ft_path(dir, wlog), name);
        assert_int_equal(strncmp(path, cache, strlen(cache)), 0);
        sha_of(path, got);
        assert_string_equal(got, want);
        free(path);
    }
    for (int i = 0; i < 2; i++) {
        kill(w[i], SIGTERM);
        assert_int_equal(ft_wait(w[i], 20), 130);
    }
    fprintf(stderr, "mesh archive: %ld bytes of RIB, %ld gzipped; Job message %ld bytes per "
            "worker; master peak RSS %ld KiB\n", mesh_text_bytes, gz_mesh, job_bytes / 2,
            ft_json_number(stats, "master_peak_rss_kb"));
    free(log);
    free(stats);
    free(cache);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv))
        return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_big_archive_reaches_each_host_once),
    };
    return cmocka_run_group_tests(tests, setup, ft_group_teardown);
}

/*
 * test_farm_files.c: job files (textures) on the farm, with real
 * aafarm-master and aafarm-worker processes over tcp://127.0.0.1
 * (docs/textures.md, "The wire and the cache").
 *
 * The scene's displacement shader has a `string texname` parameter the
 * RIB sets to a data file on the texture search path: the file is part of
 * the job (by hash), shipped once per host and kept in the worker's store.
 *   - a job with a file renders equal to the standalone render; the worker
 *     fetched exactly the file's bytes, and its resolver (job_file_resolve,
 *     logged with -v) gives a path whose bytes hash to the master's file;
 *     a second job with the same file moves 0 file bytes (a store hit);
 *     the same job to a worker that still holds it moves neither;
 *   - two worker processes sharing one store fetch the file once;
 *   - a worker killed mid-transfer (small chunks, slowed down) loses
 *     nothing: the next worker resumes from the chunks written;
 *   - a worker whose fetch lasts longer than a lease keeps the tiles it
 *     was granted (no lease expires, no tile is requeued or granted twice);
 *   - a file changed on disk between jobs gets a new job hash and is
 *     fetched again (and the old version leaves a store with a one-file
 *     budget); one changed after the master loaded the job fails the
 *     render with a message naming it;
 *   - a peer asking for more than 64 MiB beyond what it says it received
 *     is not served beyond that;
 *   - a shader that reads the file with texture() (a height map: an EXR
 *     this test renders first) renders on the farm equal to standalone,
 *     the worker reading the map from its store (issue 16).
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

#include <time.h>
#include <zmq.h>

#include "farm_testutil.h"
#include "util/hash.h"
#include "version.h"
#include "wire_pb.h"

static char *dir;

static const char hmap_sl[] =
    "/* a displacement that names a height map it does not read yet */\n"
    "displacement hmap(float Km = 0.1; string texname = \"\")\n"
    "{\n"
    "    float ds = s - 0.5, dt = t - 0.5;\n"
    "    P += Km * sin(2 * PI * 3 * sqrt(ds * ds + dt * dt)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char scene_fmt[] =
    "Option \"searchpath\" \"shader\" [\"shaders:&\"] \"texture\" [\"maps:&\"]\n"
    "Format 32 24 1\nPixelSamples 1 1\nProjection \"perspective\" \"fov\" [25]\n"
    "Translate 0 0.08 3.5\nRotate -35 1 0 0\nWorldBegin\n"
    "  LightSource \"distantlight\" 1 \"intensity\" [1.0] \"from\" [-1 2 -2] \"to\" [0 0 0]\n"
    "  AttributeBegin\n"
    "    Displacement \"hmap\" \"float Km\" [%g] \"string texname\" \"height.dat\"\n"
    "    Patch \"bilinear\" \"P\" [-1 -1 0  1 -1 0  -1 1 0  1 1 0]\n"
    "  AttributeEnd\nWorldEnd\n";

static int setup(void **state)
{
    (void)state;
    return ft_group_begin(&dir, FT_SCENE_NONE, 0);
}

/* ---- helpers ---- */

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

/* A folder d with shaders/hmap.sl, scene.rib (Km) and maps/. */
static char *make_case(const char *name, double km)
{
    char *d = strdup(ft_path(dir, name));
    mkdir(d, 0700);
    mkdir(ft_path(d, "shaders"), 0700);
    mkdir(ft_path(d, "maps"), 0700);
    write_text(ft_path(d, "shaders/hmap.sl"), hmap_sl);
    char rib[2048];
    snprintf(rib, sizeof rib, scene_fmt, km);
    write_text(ft_path(d, "scene.rib"), rib);
    return d;
}

/* n pseudo-random bytes (seed) written in place (same inode) at path. */
static void write_data(const char *path, size_t n, uint32_t seed)
{
    FILE *f = fopen(path, "r+b");
    if (!f) f = fopen(path, "wb");
    assert_non_null(f);
    uint32_t x = seed * 2u + 1u;
    for (size_t i = 0; i < n; i++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        fputc((int)(x & 0xff), f);
    }
    assert_int_equal(fclose(f), 0);
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

static pid_t start_master_on(const char *d, const char *tag, const char *bind, char *ep,
                             size_t epsz)
{
    char log[64], out[64], stats[64];
    snprintf(log, sizeof log, "master-%s.log", tag);
    snprintf(out, sizeof out, "farm-%s.exr", tag);
    snprintf(stats, sizeof stats, "stats-%s.json", tag);
    char *l = strdup(ft_path(d, log)), *o = strdup(ft_path(d, out)), *s = strdup(ft_path(d, stats));
    const char *argv[] = {ft_master, ft_path(d, "scene.rib"), "-o", o, "--bind",
                          bind, "--tile", "8", "--stats-json", s, NULL};
    pid_t pid = ft_spawn(l, argv);
    assert_true(ft_master_endpoint(l, ep, epsz, 30));
    free(l);
    free(o);
    free(s);
    return pid;
}

static pid_t start_master(const char *d, const char *tag, char *ep, size_t epsz)
{
    return start_master_on(d, tag, "tcp://127.0.0.1:*", ep, epsz);
}

/* start_master with leases of at most lease_s seconds (--lease) */
static pid_t start_master_lease(const char *d, const char *tag, const char *lease_s, char *ep,
                                size_t epsz)
{
    char log[64], out[64], stats[64];
    snprintf(log, sizeof log, "master-%s.log", tag);
    snprintf(out, sizeof out, "farm-%s.exr", tag);
    snprintf(stats, sizeof stats, "stats-%s.json", tag);
    char *l = strdup(ft_path(d, log)), *o = strdup(ft_path(d, out)), *s = strdup(ft_path(d, stats));
    const char *argv[] = {ft_master, ft_path(d, "scene.rib"), "-o", o, "--bind",
                          "tcp://127.0.0.1:*", "--tile", "8", "--stats-json", s, "--lease",
                          lease_s, NULL};
    pid_t pid = ft_spawn(l, argv);
    assert_true(ft_master_endpoint(l, ep, epsz, 30));
    free(l);
    free(o);
    free(s);
    return pid;
}

/* aafarm-worker --connect ep --name name --file-cache cache [extra...] */
static pid_t start_worker(const char *d, const char *name, const char *ep, const char *cache,
                          const char *const *extra)
{
    const char *argv[24] = {ft_worker, "--connect", ep, "--name", name, "--threads", "1",
                            "--file-cache", cache, "-v"};
    int n = 10;
    for (int i = 0; extra && extra[i] && n < 23; i++) argv[n++] = extra[i];
    argv[n] = NULL;
    char log[64];
    snprintf(log, sizeof log, "worker-%s.log", name);
    return ft_spawn(ft_path(d, log), argv);
}

static void expect_master_ok(const char *d, const char *tag, pid_t master)
{
    int status = ft_wait(master, 120);
    if (status != 0) {
        char log[64];
        snprintf(log, sizeof log, "master-%s.log", tag);
        fprintf(stderr, "master:\n%s\n", ft_read(ft_path(d, log)));
    }
    assert_int_equal(status, 0);
}

static void stop_worker(pid_t pid)
{
    kill(pid, SIGTERM);
    assert_int_equal(ft_wait(pid, 20), 130);
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

static void job_hash_of(const char *stats, char hex[HASH_HEX_SIZE])
{
    char *text = ft_read(stats);
    char *at = strstr(text, "\"job_hash\": \"");
    assert_non_null(at);
    snprintf(hex, HASH_HEX_SIZE, "%.64s", at + 13);
    free(text);
}

/* The path the worker's resolver gave for the file (its -v log). */
static void resolved_path(const char *log, const char *name, char *path, size_t size)
{
    char *text = ft_read(log);
    char needle[200];
    snprintf(needle, sizeof needle, "file '%s' resolves to ", name);
    char *at = strstr(text, needle);
    if (!at) fail_msg("no resolver line for '%s' in the worker's log:\n%s", name, text);
    at += strlen(needle);
    size_t n = strcspn(at, "\n");
    snprintf(path, size, "%.*s", (int)n, at);
    free(text);
}

/* Chunks marked written in a transfer's .have map. */
static int chunks_written(const char *have)
{
    FILE *f = fopen(have, "rb");
    if (!f) return 0;
    int n = 0, c, i = 0;
    while ((c = fgetc(f)) != EOF)
        if (i++ >= 16 && c == 1) n++;
    fclose(f);
    return n;
}

/* ---- tests ---- */

static void test_files_travel_once_per_host(void **state)
{
    (void)state;
    enum { SIZE = 3000000 };
    char *d = make_case("once", 0.1);
    write_data(ft_path(d, "maps/height.dat"), SIZE, 1);
    char want[HASH_HEX_SIZE], got[HASH_HEX_SIZE], ep[256], path[4096];
    sha_of(ft_path(d, "maps/height.dat"), want);
    assert_int_equal(ft_standalone(d, 8), 0);
    char *cache = strdup(ft_path(d, "cache"));

    pid_t m = start_master(d, "1", ep, sizeof ep);
    const char *chunked[] = {"--file-chunk", "256K", NULL};
    pid_t w = start_worker(d, "w1", ep, cache, chunked);
    expect_master_ok(d, "1", m);
    assert_int_equal(ft_exr_diff(ft_path(d, "ref.exr"), ft_path(d, "farm-1.exr")), 0);
    const char *stats = ft_path(d, "stats-1.json");
    assert_int_equal(ft_json_number(stats, "files"), 1);
    assert_int_equal(ft_json_number(stats, "files_bytes"), SIZE);
    assert_int_equal(ft_json_number(stats, "file_bytes_sent"), SIZE);
    assert_int_equal(ft_json_number(stats, "file_chunks_sent"), 12);   /* ceil(3e6 / 256 KiB) */
    assert_int_equal(worker_number(stats, "w1", "file_misses"), 1);
    assert_int_equal(worker_number(stats, "w1", "file_hits"), 0);
    /* the resolver's path holds the master's bytes */
    resolved_path(ft_path(d, "worker-w1.log"), "height.dat", path, sizeof path);
    assert_non_null(strstr(path, cache));
    sha_of(path, got);
    assert_string_equal(got, want);
    stop_worker(w);
    char first[HASH_HEX_SIZE];
    job_hash_of(stats, first);

    /* another job (another Km), the same file, a new worker on the host */
    char rib[2048];
    snprintf(rib, sizeof rib, scene_fmt, 0.05);
    write_text(ft_path(d, "scene.rib"), rib);
    char fixed[64];   /* one port for masters 2 and 3: w2 serves both */
    snprintf(fixed, sizeof fixed, "tcp://127.0.0.1:%d", ft_free_port());
    m = start_master_on(d, "2", fixed, ep, sizeof ep);
    w = start_worker(d, "w2", ep, cache, NULL);
    expect_master_ok(d, "2", m);
    stats = ft_path(d, "stats-2.json");
    char second[HASH_HEX_SIZE];
    job_hash_of(stats, second);
    assert_string_not_equal(first, second);
    assert_int_equal(ft_json_number(stats, "file_bytes_sent"), 0);
    assert_int_equal(worker_number(stats, "w2", "file_bytes"), 0);
    assert_int_equal(worker_number(stats, "w2", "file_hits"), 1);
    assert_int_equal(worker_number(stats, "w2", "file_misses"), 0);
    resolved_path(ft_path(d, "worker-w2.log"), "height.dat", path, sizeof path);
    sha_of(path, got);
    assert_string_equal(got, want);

    /* the same job again: w2 still holds it (its Hello says so), so neither
     * the Job nor the file is sent, and it still reports its files */
    m = start_master_on(d, "3", fixed, ep, sizeof ep);
    expect_master_ok(d, "3", m);
    stats = ft_path(d, "stats-3.json");
    assert_true(ft_count(ft_path(d, "master-3.log"), "holds the job") >= 1);
    assert_int_equal(ft_json_number(stats, "jobs_sent"), 0);
    assert_int_equal(ft_json_number(stats, "file_bytes_sent"), 0);
    assert_int_equal(worker_number(stats, "w2", "file_hits"), 1);
    stop_worker(w);
    free(cache);
    free(d);
}

/* A copy of file from to file to. */
static void copy_file(const char *from, const char *to)
{
    size_t n = 0;
    FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
    assert_non_null(in);
    assert_non_null(out);
    char buf[65536];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, in)) > 0) n += fwrite(buf, 1, got, out);
    fclose(in);
    assert_int_equal(fclose(out), 0);
    assert_true(n > 0);
}

static void test_texture_map_on_the_farm(void **state)
{
    (void)state;
    /* the map: the first case's standalone render (an RGBA EXR), shipped
     * under the name the scene gives, read through its first channel */
    char *src = make_case("texsrc", 0.1);
    assert_int_equal(ft_standalone(src, 8), 0);
    char *d = make_case("texmap", 0.2);
    write_text(ft_path(d, "shaders/hmap.sl"),
               "/* a height map read with texture(): height times Km along N */\n"
               "displacement hmap(float Km = 0.1; string texname = \"\")\n"
               "{\n"
               "    float h = float texture(texname, s, t, \"blur\", 0.01);\n"
               "    P += Km * h * normalize(N);\n"
               "    N = calculatenormal(P);\n"
               "}\n");
    copy_file(ft_path(src, "ref.exr"), ft_path(d, "maps/height.dat"));
    struct stat st;
    assert_int_equal(stat(ft_path(d, "maps/height.dat"), &st), 0);
    assert_int_equal(ft_standalone(d, 8), 0);
    char *cache = strdup(ft_path(d, "cache"));
    char ep[256];
    pid_t m = start_master(d, "1", ep, sizeof ep);
    pid_t w = start_worker(d, "w1", ep, cache, NULL);
    expect_master_ok(d, "1", m);
    assert_int_equal(ft_exr_diff(ft_path(d, "ref.exr"), ft_path(d, "farm-1.exr")), 0);
    const char *stats = ft_path(d, "stats-1.json");
    assert_int_equal(ft_json_number(stats, "files"), 1);
    assert_int_equal(ft_json_number(stats, "file_bytes_sent"), (long)st.st_size);
    stop_worker(w);
    /* texture() really reads the map: the same scene and shader over
     * another map (this render's own image) renders differently */
    char *d2 = make_case("texmap2", 0.2);
    char *sl = ft_read(ft_path(d, "shaders/hmap.sl"));
    write_text(ft_path(d2, "shaders/hmap.sl"), sl);
    free(sl);
    copy_file(ft_path(d, "ref.exr"), ft_path(d2, "maps/height.dat"));
    assert_int_equal(ft_standalone(d2, 8), 0);
    assert_true(ft_exr_diff(ft_path(d, "ref.exr"), ft_path(d2, "ref.exr")) > 0);
    free(d2);
    free(cache);
    free(d);
    free(src);
}

static void test_two_workers_share_one_store(void **state)
{
    (void)state;
    enum { SIZE = 2000000 };
    char *d = make_case("shared", 0.1);
    write_data(ft_path(d, "maps/height.dat"), SIZE, 2);
    assert_int_equal(ft_standalone(d, 8), 0);
    char ep[256];
    char *cache = strdup(ft_path(d, "cache"));
    pid_t m = start_master(d, "1", ep, sizeof ep);
    /* slow transfers (31 chunks, 20 ms apart), so both wait for the file,
     * and slow tiles, so both have tiles left when it is there */
    const char *slow[] = {"--file-chunk", "64K", "--file-delay", "20", "--tile-delay", "300",
                          NULL};
    pid_t a = start_worker(d, "a", ep, cache, slow);
    pid_t b = start_worker(d, "b", ep, cache, slow);
    expect_master_ok(d, "1", m);
    assert_int_equal(ft_exr_diff(ft_path(d, "ref.exr"), ft_path(d, "farm-1.exr")), 0);
    const char *stats = ft_path(d, "stats-1.json");
    /* the host fetched the file once */
    assert_int_equal(ft_json_number(stats, "file_bytes_sent"), SIZE);
    long fa = worker_number(stats, "a", "file_bytes"), fb = worker_number(stats, "b", "file_bytes");
    assert_true((fa == SIZE && fb == 0) || (fa == 0 && fb == SIZE));
    /* and both had it for their tiles */
    for (const char *const *n = (const char *const[]){"a", "b", NULL}; *n; n++)
        assert_int_equal(worker_number(stats, *n, "file_hits") +
                             worker_number(stats, *n, "file_misses"),
                         1);
    stop_worker(a);
    stop_worker(b);
    free(cache);
    free(d);
}

static void test_killed_worker_loses_nothing(void **state)
{
    (void)state;
    enum { SIZE = 4000000, CHUNK = 65536 };   /* 62 chunks */
    char *d = make_case("killed", 0.1);
    write_data(ft_path(d, "maps/height.dat"), SIZE, 3);
    char want[HASH_HEX_SIZE], got[HASH_HEX_SIZE], ep[256], path[4096];
    sha_of(ft_path(d, "maps/height.dat"), want);
    assert_int_equal(ft_standalone(d, 8), 0);
    char *cache = strdup(ft_path(d, "cache"));
    char have[4200];
    snprintf(have, sizeof have, "%s/partial/%s.have", cache, want);

    pid_t m = start_master(d, "1", ep, sizeof ep);
    const char *slow[] = {"--file-chunk", "64K", "--file-inflight", "64K", "--file-delay", "40",
                          NULL};
    pid_t a = start_worker(d, "a", ep, cache, slow);
    int written = 0;
    for (int i = 0; i < 1500 && (written = chunks_written(have)) < 8; i++) ft_sleep_ms(10);
    assert_true(written >= 8);
    assert_true(written < SIZE / CHUNK);   /* mid-transfer */
    kill(a, SIGKILL);
    assert_int_equal(ft_wait(a, 20), 128 + SIGKILL);
    int before = chunks_written(have);

    pid_t b = start_worker(d, "b", ep, cache, NULL);
    expect_master_ok(d, "1", m);
    assert_int_equal(ft_exr_diff(ft_path(d, "ref.exr"), ft_path(d, "farm-1.exr")), 0);
    const char *stats = ft_path(d, "stats-1.json");
    long fb = worker_number(stats, "b", "file_bytes");
    /* b asked only for what a had not written */
    assert_int_equal(fb, SIZE - (long)before * CHUNK);
    /* nothing moved twice beyond the one chunk in flight when a died */
    assert_true(ft_json_number(stats, "file_bytes_sent") <= SIZE + CHUNK);
    resolved_path(ft_path(d, "worker-b.log"), "height.dat", path, sizeof path);
    sha_of(path, got);
    assert_string_equal(got, want);
    assert_int_equal(access(have, F_OK), -1);   /* the transfer's map is gone */
    stop_worker(b);
    free(cache);
    free(d);
}

/* A worker fetching a file for longer than a lease lasts keeps its leases:
 * the tiles it was granted are not requeued while the chunks flow (each
 * chunk sent renews them, and FilesReady starts their clock again), and
 * the render needs no second grant of any tile. */
static void test_slow_fetch_keeps_its_leases(void **state)
{
    (void)state;
    enum { SIZE = 2000000 };                  /* 31 chunks of 64K, 150 ms apart: 4.5 s */
    char *d = make_case("slowfetch", 0.1);
    write_data(ft_path(d, "maps/height.dat"), SIZE, 4);
    assert_int_equal(ft_standalone(d, 8), 0);
    char ep[256];
    char *cache = strdup(ft_path(d, "cache"));
    pid_t m = start_master_lease(d, "1", "2", ep, sizeof ep);    /* leases of 2 s at most */
    const char *slow[] = {"--file-chunk", "64K", "--file-inflight", "64K", "--file-delay", "150",
                          NULL};
    pid_t a = start_worker(d, "a", ep, cache, slow);
    expect_master_ok(d, "1", m);
    assert_int_equal(ft_exr_diff(ft_path(d, "ref.exr"), ft_path(d, "farm-1.exr")), 0);
    const char *stats = ft_path(d, "stats-1.json");
    assert_int_equal(worker_number(stats, "a", "file_bytes"), SIZE);
    assert_true(worker_number(stats, "a", "file_seconds") >= 3);  /* it outlasted a lease */
    assert_int_equal(ft_json_number(stats, "expired_leases"), 0);
    assert_int_equal(ft_json_number(stats, "requeued"), 0);
    assert_int_equal(ft_json_number(stats, "grants"), 12);   /* 32x24 in 8x8 tiles, once each */
    stop_worker(a);
    free(cache);
    free(d);
}

static void test_changed_file(void **state)
{
    (void)state;
    enum { SIZE = 300000 };
    char *d = make_case("changed", 0.1);
    const char *data = ft_path(d, "maps/height.dat");
    write_data(data, SIZE, 4);
    char first[HASH_HEX_SIZE], second[HASH_HEX_SIZE], want[HASH_HEX_SIZE], got[HASH_HEX_SIZE];
    char ep[256], path[4096];
    char *cache = strdup(ft_path(d, "cache"));
    pid_t m = start_master(d, "1", ep, sizeof ep);
    pid_t w = start_worker(d, "w1", ep, cache, NULL);
    expect_master_ok(d, "1", m);
    job_hash_of(ft_path(d, "stats-1.json"), first);
    stop_worker(w);

    /* the same name, other bytes (in place): a new job, the file fetched again */
    write_data(ft_path(d, "maps/height.dat"), SIZE, 5);
    sha_of(ft_path(d, "maps/height.dat"), want);
    m = start_master(d, "2", ep, sizeof ep);
    /* a store budget of one file: the old version (no longer in use) goes */
    const char *budget[] = {"--file-cache-bytes", "300000", NULL};
    w = start_worker(d, "w2", ep, cache, budget);
    expect_master_ok(d, "2", m);
    char objects[4200];
    snprintf(objects, sizeof objects, "%s/objects", cache);
    assert_int_equal(ft_count_files(objects, ""), 3);   /* ".", ".." and the new version */
    snprintf(objects, sizeof objects, "%s/objects/%s", cache, want);
    assert_int_equal(access(objects, F_OK), 0);
    job_hash_of(ft_path(d, "stats-2.json"), second);
    assert_string_not_equal(first, second);
    assert_int_equal(ft_json_number(ft_path(d, "stats-2.json"), "file_bytes_sent"), SIZE);
    resolved_path(ft_path(d, "worker-w2.log"), "height.dat", path, sizeof path);
    sha_of(path, got);
    assert_string_equal(got, want);
    stop_worker(w);

    /* changed after the master loaded the job: the render fails, saying so */
    m = start_master(d, "3", ep, sizeof ep);
    write_data(ft_path(d, "maps/height.dat"), SIZE, 6);
    char *fresh = strdup(ft_path(d, "cache2"));
    w = start_worker(d, "w3", ep, fresh, NULL);
    int status = ft_wait(m, 60);
    assert_int_equal(status, 1);
    assert_true(ft_count(ft_path(d, "master-3.log"), "changed on the master's disk") >= 1);
    assert_true(ft_count(ft_path(d, "master-3.log"), "height.dat") >= 1);
    assert_int_equal(access(ft_path(d, "farm-3.exr"), F_OK), -1);   /* no output */
    stop_worker(w);
    free(fresh);
    free(cache);
    free(d);
}

/* ---- a greedy peer speaking the protocol by hand ---- */

static void peer_send(void *s, Aafarm__Envelope *env)
{
    assert_int_equal(wire_send_envelope(s, NULL, NULL, 0, env, NULL, 0, NULL, 0), 0);
}

static double mono_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* A Heartbeat at most every 0.4 s, so the master keeps the peer. */
static void peer_alive(void *s)
{
    static double last;
    if (mono_s() - last < 0.4) return;
    Aafarm__Heartbeat hb = AAFARM__HEARTBEAT__INIT;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_HEARTBEAT;
    env.heartbeat = &hb;
    peer_send(s, &env);
    last = mono_s();
}

static wire_msg *peer_wait(void *s, proto_kind kind, double timeout_s)
{
    struct timespec t0, t;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        zmq_pollitem_t it = {s, 0, ZMQ_POLLIN, 0};
        zmq_poll(&it, 1, 50);
        peer_alive(s);
        wire_msg *m;
        while ((m = wire_recv(s, NULL, NULL, ZMQ_DONTWAIT, NULL, 0))) {
            if (wire_msg_kind(m) == kind) return m;
            wire_msg_destroy(&m);
        }
        clock_gettime(CLOCK_MONOTONIC, &t);
        if ((double)(t.tv_sec - t0.tv_sec) + (double)(t.tv_nsec - t0.tv_nsec) * 1e-9 > timeout_s)
            return NULL;
    }
}

static void peer_need(void *s, const char *job_hash, const char *sha, uint64_t received)
{
    Aafarm__NeedFile n = AAFARM__NEED_FILE__INIT;
    n.job_hash = (char *)job_hash;
    n.sha256 = (char *)sha;
    n.offset = 0;
    n.length = 16u << 20;
    n.received = received;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_NEED_FILE;
    env.need_file = &n;
    peer_send(s, &env);
}

/* FileChunks arriving until none came for timeout_s. */
static int peer_chunks(void *s, double timeout_s)
{
    int n = 0;
    wire_msg *m;
    while ((m = peer_wait(s, PROTO_FILE_CHUNK, timeout_s))) {
        n++;
        wire_msg_destroy(&m);
    }
    return n;
}

static void test_greedy_peer_is_capped(void **state)
{
    (void)state;
    char *d = make_case("greedy", 0.1);
    write_data(ft_path(d, "maps/height.dat"), 16u << 20, 7);
    char ep[256], job_hash[HASH_HEX_SIZE], sha[HASH_HEX_SIZE];
    pid_t m = start_master(d, "1", ep, sizeof ep);
    void *ctx = zmq_ctx_new();
    void *s = zmq_socket(ctx, ZMQ_DEALER);
    int linger = 0;
    zmq_setsockopt(s, ZMQ_LINGER, &linger, sizeof linger);
    assert_int_equal(zmq_connect(s, ep), 0);
    Aafarm__Hello h = AAFARM__HELLO__INIT;
    h.protocol_version = AAFARM_PROTOCOL_VERSION;
    h.worker_name = "greedy";
    h.host = "elsewhere";
    h.threads = 1;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_HELLO;
    env.hello = &h;
    peer_send(s, &env);
    wire_msg *w = peer_wait(s, PROTO_WELCOME, 30);
    assert_non_null(w);
    wire_msg_destroy(&w);
    Aafarm__Ask a = AAFARM__ASK__INIT;
    a.credits = 1;
    Aafarm__Envelope ask = AAFARM__ENVELOPE__INIT;
    ask.body_case = AAFARM__ENVELOPE__BODY_ASK;
    ask.ask = &a;
    peer_send(s, &ask);
    wire_msg *job = peer_wait(s, PROTO_JOB, 30);
    assert_non_null(job);
    const Aafarm__Job *jm = wire_msg_envelope(job)->job;
    assert_int_equal(jm->n_files, 1);
    assert_int_equal(jm->files[0]->size, 16u << 20);
    snprintf(job_hash, sizeof job_hash, "%s", jm->job_hash);
    snprintf(sha, sizeof sha, "%s", jm->files[0]->sha256);
    wire_msg_destroy(&job);

    /* five 16 MiB chunks, saying nothing was received: four are sent */
    for (int i = 0; i < 5; i++) peer_need(s, job_hash, sha, 0);
    for (int i = 0; i < 300 && ft_count(ft_path(d, "master-1.log"), "asks for more") == 0; i++) {
        ft_sleep_ms(50);
        peer_alive(s);
    }
    assert_int_equal(ft_count(ft_path(d, "master-1.log"), "asks for more file bytes"), 1);
    assert_int_equal(peer_chunks(s, 1.0), 4);
    /* having received them, it may have one more */
    peer_need(s, job_hash, sha, 64u << 20);
    assert_int_equal(peer_chunks(s, 1.0), 1);
    zmq_close(s);
    zmq_ctx_term(ctx);
    kill(m, SIGINT);
    assert_int_equal(ft_wait(m, 20), 130);
    free(d);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv))
        return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_files_travel_once_per_host),
        cmocka_unit_test(test_two_workers_share_one_store),
        cmocka_unit_test(test_killed_worker_loses_nothing),
        cmocka_unit_test(test_slow_fetch_keeps_its_leases),
        cmocka_unit_test(test_changed_file),
        cmocka_unit_test(test_greedy_peer_is_capped),
        cmocka_unit_test(test_texture_map_on_the_farm),
    };
    return cmocka_run_group_tests(tests, setup, ft_group_teardown);
}

/*
 * test_farm_service.c: a serving master (aafarm-master --serve; docs/farm.md
 * "A job queue") as a service, with real processes over loopback:
 *   - token: a master whose --http needs a token refuses aafarm-submit
 *     without it or with a wrong one (401, and the submitter says what to
 *     do), takes it with --token-file;
 *   - malformed submissions over HTTP (not a submission, JSON, cut short,
 *     a Job whose hash is not its content's, no frame, a Content-Length
 *     over the limit, unknown job paths): each a clear 4xx, and the master
 *     keeps serving (nothing queued);
 *   - cancelling a running job: its worker is told (JobDone cancelled) and
 *     drops its tiles, no tile of it is taken after, its state is
 *     cancelled (--wait: 130), no output or journal stays; the next queued
 *     job then runs and equals the standalone render;
 *   - every local worker killed mid-job: the job goes back to the queue
 *     (never failed), the workers are started again, it resumes from its
 *     journal and equals the standalone render (--wait: 0);
 *   - pools: a job of pool blue goes only to the blue worker, one of pool
 *     red only to red's; a red worker that fails every tile is benched for
 *     the job once red finished its tiles (shown in /api/workers, the
 *     log); a job without a pool goes to any worker; every output equals
 *     the standalone render.
 *
 * argv: aafarm-master aafarm-worker aafarm-submit
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include "bundle.h"
#include "farm_testutil.h"
#include "http_testutil.h"
#include "job/frames.h"

static char *dir;
static const char *submit_bin;
static const char token[] = "test-token-0123456789abcdef";

static int group_setup(void **state)
{
    (void)state;
    if (ft_group_begin(&dir, FT_SCENE_WAVE, 16) != 0) return -1;
    FILE *t = fopen(ft_path(dir, "token"), "w");
    fprintf(t, "%s\n", token);
    fclose(t);
    t = fopen(ft_path(dir, "wrong-token"), "w");
    fprintf(t, "not-the-token-0123456789abcdef\n");
    fclose(t);
    return 0;
}

/* A serving master on 127.0.0.1:port with the extra arguments (NULL-ended). */
static pid_t start_master(const char *log, const char *db, int port, ...)
{
    static char http[32], dbpath[1024];
    snprintf(http, sizeof http, "127.0.0.1:%d", port);
    snprintf(dbpath, sizeof dbpath, "%s", ft_path(dir, db));
    const char *argv[32] = {ft_master, "--serve", "--db", dbpath, "--http", http};
    int n = 6;
    va_list ap;
    va_start(ap, port);
    for (const char *a; (a = va_arg(ap, const char *)) && n < 30;) argv[n++] = a;
    va_end(ap);
    argv[n] = NULL;
    return ft_spawn(log, argv);
}

/* aafarm-submit --master url and the arguments (NULL-ended). */
static pid_t submit(const char *log, const char *url, ...)
{
    const char *argv[32] = {submit_bin, "--master", url};
    int n = 3;
    va_list ap;
    va_start(ap, url);
    for (const char *a; (a = va_arg(ap, const char *)) && n < 30;) argv[n++] = a;
    va_end(ap);
    argv[n] = NULL;
    return ft_spawn(log, argv);
}

/* Waits until the file exists and grew twice (a whole tile record in a journal). */
static bool journal_grew(const char *path, double timeout_s)
{
    long size0 = -1;
    int grew = 0;
    for (double t0 = ft_now(); ft_now() - t0 < timeout_s; ft_sleep_ms(20)) {
        struct stat st;
        if (stat(path, &st) != 0) continue;
        if (size0 < 0) size0 = (long)st.st_size;
        else if ((long)st.st_size > size0 && ++grew == 2) return true;
        if ((long)st.st_size > size0) size0 = (long)st.st_size;
    }
    return false;
}

/* Where needle is in the file (-1: not there). */
static long position(const char *path, const char *needle)
{
    char *text = ft_read(path);
    const char *p = strstr(text, needle);
    long at = p ? (long)(p - text) : -1;
    free(text);
    return at;
}

/* A valid submission of dir/scene.rib (bundle.h), malloc'd; its job's hash. */
static uint8_t *make_bundle(size_t *len, char hash[HASH_HEX_SIZE])
{
    job_options jo;
    job_options_default(&jo);
    jo.tile_size = 16;
    sl_diag *diag = sl_diag_new();
    bool usage = false;
    frame_sequence *seq = frame_sequence_load(ft_path(dir, "scene.rib"), &jo, NULL,
                                              ft_path(dir, "bundle.exr"), &usage, NULL, diag);
    sl_diag_destroy(&diag);
    assert_non_null(seq);
    char err[512];
    uint8_t *b = job_bundle_encode(seq, "scene.rib", 0, NULL, len, err, sizeof err);
    memcpy(hash, seq->jobs[0]->hash, HASH_HEX_SIZE);
    frame_sequence_destroy(&seq);
    assert_non_null(b);
    return b;
}

/* POSTs body to base + path with the token; the status, the body's error in *error. */
static long post(const char *base, const char *path, const void *body, size_t len,
                 char *error, size_t errsz)
{
    char url[256], auth[128];
    snprintf(url, sizeof url, "%s%s", base, path);
    snprintf(auth, sizeof auth, "Authorization: Bearer %s", token);
    ht_response r = ht_post_body("POST", url, auth, body ? body : "", len);
    snprintf(error, errsz, "%s", r.body ? r.body : "");
    long status = r.status;
    ht_response_clear(&r);
    return status;
}

/* The first line of the answer to a POST whose Content-Length is huge,
 * sent with the headers alone over a raw socket. */
static void huge_post(int port, char *line, size_t n)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    assert_true(fd >= 0);
    struct timeval tv = {15, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(connect(fd, (struct sockaddr *)&a, sizeof a), 0);
    char req[512];
    int len = snprintf(req, sizeof req, "POST /api/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                       "Authorization: Bearer %s\r\nContent-Length: 1099511627776\r\n\r\n",
                       token);
    assert_int_equal(write(fd, req, (size_t)len), len);
    ssize_t got = read(fd, line, n - 1);
    close(fd);
    line[got > 0 ? got : 0] = '\0';
    char *nl = strchr(line, '\r');
    if (nl) *nl = '\0';
}

static void test_token_malformed_and_cancel_running(void **state)
{
    (void)state;
    int port = ft_free_port();
    char url[64], log[1024], tokfile[1024], wrongfile[1024];
    snprintf(url, sizeof url, "http://127.0.0.1:%d", port);
    snprintf(log, sizeof log, "%s", ft_path(dir, "master-a.log"));
    snprintf(tokfile, sizeof tokfile, "%s", ft_path(dir, "token"));
    snprintf(wrongfile, sizeof wrongfile, "%s", ft_path(dir, "wrong-token"));
    pid_t master = start_master(log, "a.db", port, "--http-token-file", tokfile,
                                "--local-workers", "1", "--worker-binary",
                                ft_slow_worker(dir, 150), "-v", NULL);
    assert_true(ft_wait_for(log, "serving the job queue", 1, 30));

    /* the token: required, and checked */
    char scene[1024], out[1024];
    snprintf(scene, sizeof scene, "%s", ft_path(dir, "scene.rib"));
    snprintf(out, sizeof out, "%s", ft_path(dir, "a.exr"));
    assert_int_equal(ft_wait(submit(ft_path(dir, "s-none.log"), url, scene, "-o", out, "--tile",
                                    "16", NULL), 30), 1);
    assert_int_equal(ft_count(ft_path(dir, "s-none.log"), "needs a token (answer 401): give the "
                              "line of its --http-token-file with --token-file FILE"), 1);
    assert_int_equal(ft_wait(submit(ft_path(dir, "s-wrong.log"), url, scene, "-o", out,
                                    "--tile", "16", "--token-file", wrongfile, NULL), 30), 1);
    assert_int_equal(ft_count(ft_path(dir, "s-wrong.log"), "refused the token (answer 401)"), 1);
    assert_int_equal(ft_wait(submit(ft_path(dir, "l-none.log"), url, "--list", NULL), 30), 1);
    assert_int_equal(ft_count(ft_path(dir, "l-none.log"), "needs a token (answer 401)"), 1);

    /* malformed submissions: a clear 4xx each, nothing queued */
    char error[4096];
    assert_int_equal(post(url, "/api/jobs", "hello", 5, error, sizeof error), 400);
    assert_non_null(strstr(error, "not a job submission"));
    const char *json = "{\"scene\": \"wave.rib\", \"output\": \"x.exr\"}";
    assert_int_equal(post(url, "/api/jobs", json, strlen(json), error, sizeof error), 400);
    assert_non_null(strstr(error, "not a job submission"));
    const char *noframe = "AAFARM-JOB 1\npriority 0\nscene x\n\n";
    assert_int_equal(post(url, "/api/jobs", noframe, strlen(noframe), error, sizeof error), 400);
    assert_non_null(strstr(error, "names no frame"));
    size_t blen = 0;
    char hash[HASH_HEX_SIZE];
    uint8_t *bundle = make_bundle(&blen, hash);
    assert_int_equal(post(url, "/api/jobs", bundle, blen * 2 / 3, error, sizeof error), 400);
    assert_non_null(strstr(error, "refused the submission"));
    /* the Job's hash: one hex digit changed, so the content no longer hashes to it */
    uint8_t *bad = malloc(blen);
    memcpy(bad, bundle, blen);
    int changed = 0;
    for (size_t i = 0; i + HASH_HEX_SIZE - 1 <= blen; i++)
        if (memcmp(bad + i, hash, HASH_HEX_SIZE - 1) == 0) {
            bad[i + 10] = bad[i + 10] == '0' ? '1' : '0';
            changed++;
        }
    assert_int_equal(changed, 1);
    long st = post(url, "/api/jobs", bad, blen, error, sizeof error);
    if (st != 400) fprintf(stderr, "tampered: %ld %s (hash %s)\n", st, error, hash);
    assert_int_equal(st, 400);
    assert_non_null(strstr(error, "hash"));
    free(bad);
    char line[256];
    huge_post(port, line, sizeof line);
    assert_int_equal(strncmp(line, "HTTP/1.1 413 ", 13), 0);
    assert_int_equal(post(url, "/api/jobs/x/cancel", NULL, 0, error, sizeof error), 404);
    assert_int_equal(post(url, "/api/jobs/99/cancel", NULL, 0, error, sizeof error), 404);
    char auth[128], jurl[128];
    snprintf(auth, sizeof auth, "Authorization: Bearer %s", token);
    snprintf(jurl, sizeof jurl, "%s/api/jobs/99", url);
    ht_response r = ht_request("GET", jurl, auth);
    assert_int_equal(r.status, 404);
    ht_response_clear(&r);
    snprintf(jurl, sizeof jurl, "%s/api/jobs", url);
    r = ht_request("GET", jurl, auth);   /* still serving, nothing queued */
    assert_int_equal(r.status, 200);
    assert_non_null(strstr(r.body, "{\"jobs\": []}"));
    ht_response_clear(&r);
    assert_true(ft_running(master));
    free(bundle);

    /* cancel a running job: job 1 runs, job 2 waits behind it */
    char outb[1024];
    snprintf(outb, sizeof outb, "%s", ft_path(dir, "b.exr"));
    pid_t first = submit(ft_path(dir, "s-1.log"), url, scene, "-o", out, "--tile", "16",
                         "--token-file", tokfile, "--wait", NULL);
    assert_true(ft_wait_for(log, "job 1: ", 1, 30));
    pid_t second = submit(ft_path(dir, "s-2.log"), url, scene, "-o", outb, "--tile", "16",
                          "--token-file", tokfile, "--wait", NULL);
    assert_true(ft_wait_for(ft_path(dir, "s-2.log"), "job 2 queued", 1, 30));
    assert_true(journal_grew(ft_path(dir, "a.exr.journal"), 30));
    pid_t cancel = submit(ft_path(dir, "c-1.log"), url, "--cancel", "1", "--token-file", tokfile,
                          NULL);
    assert_int_equal(ft_wait(cancel, 30), 0);
    assert_int_equal(ft_count(ft_path(dir, "c-1.log"), "job 1 is running: its master stops it"),
                     1);
    assert_int_equal(ft_wait(first, 30), 130);
    assert_int_equal(ft_count(ft_path(dir, "s-1.log"), "job 1 cancelled: cancelled while "
                              "running"), 1);
    assert_int_equal(ft_wait(second, 60), 0);
    assert_true(ft_wait_for(log, "job 2 done", 1, 10));
    /* the worker was told and dropped the job's tiles; none taken after */
    assert_true(ft_count(log, " cancelled: cancelled") >= 1);   /* the worker's JobDone line */
    long at_cancel = position(log, "job 1 cancelled"), at_next = position(log, "job 2: ");
    assert_true(at_cancel > 0 && at_next > at_cancel);
    char *text = ft_read(log);
    int taken_after = 0;
    for (const char *p = text + at_cancel; (p = strstr(p, "took tile")) && p < text + at_next; p++)
        taken_after++;
    free(text);
    assert_int_equal(taken_after, 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), outb), 0);
    assert_int_equal(access(out, F_OK), -1);
    assert_int_equal(ft_count_files(dir, "a.exr"), 0);   /* no journal, no temporary file */

    kill(master, SIGTERM);
    assert_int_equal(ft_wait(master, 10), 130);
}

/* The pid of the live local worker in /api/workers (0: none). */
static long local_worker_pid(const char *url)
{
    json_object *doc = ht_get_json(url, "/api/workers");
    if (!doc) return 0;
    json_object *ws = ht_member(doc, "workers");
    long pid = 0;
    for (size_t i = 0; i < json_object_array_length(ws); i++) {
        json_object *w = json_object_array_get_idx(ws, i);
        if (json_object_get_boolean(ht_member(w, "alive"))) pid = ht_int(w, "pid");
    }
    json_object_put(doc);
    return pid;
}

static void test_workers_lost_job_requeued(void **state)
{
    (void)state;
    int port = ft_free_port();
    char url[64], log[1024], scene[1024], out[1024];
    snprintf(url, sizeof url, "http://127.0.0.1:%d", port);
    snprintf(log, sizeof log, "%s", ft_path(dir, "master-b.log"));
    snprintf(scene, sizeof scene, "%s", ft_path(dir, "scene.rib"));
    snprintf(out, sizeof out, "%s", ft_path(dir, "c.exr"));
    pid_t master = start_master(log, "b.db", port, "--local-workers", "1", "--worker-binary",
                                ft_slow_worker(dir, 150), NULL);
    assert_true(ft_wait_for(log, "serving the job queue", 1, 30));
    pid_t waiter = submit(ft_path(dir, "s-c.log"), url, scene, "-o", out, "--tile", "16",
                          "--wait", NULL);
    assert_true(journal_grew(ft_path(dir, "c.exr.journal"), 30));
    long pid = local_worker_pid(url);
    assert_true(pid > 0);
    kill((pid_t)pid, SIGKILL);
    assert_true(ft_wait_for(log, "job 1 requeued: every local worker exited", 1, 30));
    assert_true(ft_wait_for(log, "started the 1 local workers again (restart 1)", 1, 30));
    assert_int_equal(ft_wait(waiter, 60), 0);
    assert_true(ft_wait_for(log, "job 1 done", 1, 10));
    assert_int_equal(ft_count(log, "resuming: "), 1);
    assert_int_equal(ft_count(log, "failed"), 0);
    assert_true(position(log, "job 1 requeued") < position(log, "resuming: "));
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), out), 0);
    assert_int_equal(ft_count_files(dir, "c.exr."), 0);
    kill(master, SIGTERM);
    assert_int_equal(ft_wait(master, 10), 130);
}

/* The workers' document: name -> tiles, and whether `benched_name` is benched. */
static long worker_tiles(json_object *doc, const char *name)
{
    json_object *ws = ht_member(doc, "workers");
    for (size_t i = 0; i < json_object_array_length(ws); i++) {
        json_object *w = json_object_array_get_idx(ws, i);
        if (strcmp(json_object_get_string(ht_member(w, "name")), name) == 0)
            return ht_int(w, "tiles");
    }
    return -1;
}

static bool worker_benched(json_object *doc, const char *name)
{
    json_object *ws = ht_member(doc, "workers");
    for (size_t i = 0; i < json_object_array_length(ws); i++) {
        json_object *w = json_object_array_get_idx(ws, i);
        if (strcmp(json_object_get_string(ht_member(w, "name")), name) == 0)
            return json_object_get_boolean(ht_member(w, "benched")) &&
                   strcmp(json_object_get_string(ht_member(w, "state")), "benched") == 0;
    }
    return false;
}

static pid_t start_worker(const char *endpoint, const char *name, const char *pool, bool fail)
{
    char log[1024], delay[16];
    snprintf(log, sizeof log, "%s", ft_path(dir, name));
    strcat(log, ".log");
    snprintf(delay, sizeof delay, "%d", fail ? 0 : 250);
    const char *argv[] = {ft_worker, "--connect", endpoint, "--name", name, "--threads", "1",
                          "--tile-delay", delay, "--pool", pool, fail ? "--fail-tiles" : NULL,
                          NULL};
    return ft_spawn(log, argv);
}

static void test_pools_and_benching(void **state)
{
    (void)state;
    int port = ft_free_port();
    char url[64], log[1024], scene[1024], endpoint[256];
    snprintf(url, sizeof url, "http://127.0.0.1:%d", port);
    snprintf(log, sizeof log, "%s", ft_path(dir, "master-p.log"));
    snprintf(scene, sizeof scene, "%s", ft_path(dir, "scene.rib"));
    pid_t master = start_master(log, "p.db", port, "--bind", "tcp://127.0.0.1:*",
                                "--local-workers", "0", NULL);
    assert_true(ft_master_endpoint(log, endpoint, sizeof endpoint, 30));
    start_worker(endpoint, "blue-1", "blue", false);
    start_worker(endpoint, "red-1", "red", false);
    start_worker(endpoint, "red-bad", "red", true);
    assert_true(ft_wait_for(log, " joined (", 3, 30));

    /* pool blue: only the blue worker */
    char out[1024];
    snprintf(out, sizeof out, "%s", ft_path(dir, "blue.exr"));
    assert_int_equal(ft_wait(submit(ft_path(dir, "s-blue.log"), url, scene, "-o", out, "--tile",
                                    "16", "--pool", "blue", "--wait", NULL), 60), 0);
    json_object *doc = ht_get_json(url, "/api/workers");
    assert_non_null(doc);
    assert_int_equal(worker_tiles(doc, "blue-1"), 12);
    assert_int_equal(worker_tiles(doc, "red-1"), 0);
    json_object_put(doc);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), out), 0);
    assert_int_equal(ft_count(ft_path(dir, "red-bad.log"), "failing on purpose"), 0);

    /* pool red: red-bad fails every tile, red-1 finishes them: red-bad is benched */
    snprintf(out, sizeof out, "%s", ft_path(dir, "red.exr"));
    pid_t red = submit(ft_path(dir, "s-red.log"), url, scene, "-o", out, "--tile", "16",
                       "--pool", "red", "--wait", NULL);
    bool seen = false;
    for (double t0 = ft_now(); !seen && ft_now() - t0 < 30 && ft_running(red); ft_sleep_ms(50)) {
        doc = ht_get_json(url, "/api/workers");
        if (doc) seen = worker_benched(doc, "red-bad");
        json_object_put(doc);
    }
    assert_true(seen);
    assert_int_equal(ft_wait(red, 60), 0);
    assert_int_equal(ft_count(log, "worker red-bad benched for this job: 2 tiles it failed were "
                              "finished by other workers"), 1);
    doc = ht_get_json(url, "/api/workers");
    assert_int_equal(worker_tiles(doc, "blue-1"), 12);   /* none of the red job */
    assert_int_equal(worker_tiles(doc, "red-1"), 12);
    assert_int_equal(worker_tiles(doc, "red-bad"), 0);
    assert_false(worker_benched(doc, "red-bad"));          /* for that job only */
    json_object_put(doc);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), out), 0);

    /* no pool: any worker */
    snprintf(out, sizeof out, "%s", ft_path(dir, "any.exr"));
    assert_int_equal(ft_wait(submit(ft_path(dir, "s-any.log"), url, scene, "-o", out, "--tile",
                                    "16", "--wait", NULL), 60), 0);
    doc = ht_get_json(url, "/api/workers");
    assert_true(worker_tiles(doc, "blue-1") > 12);
    assert_true(worker_tiles(doc, "red-1") > 12);
    json_object_put(doc);
    assert_int_equal(ft_count(log, "worker red-bad benched for this job"), 2);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), out), 0);

    kill(master, SIGTERM);
    assert_int_equal(ft_wait(master, 10), 130);
}

int main(int argc, char **argv)
{
    if (argc < 4 || !ft_init(argc, argv)) {
        fprintf(stderr, "usage: test_farm_service MASTER WORKER SUBMIT\n");
        return 2;
    }
    submit_bin = argv[3];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_token_malformed_and_cancel_running, ft_teardown),
        cmocka_unit_test_teardown(test_workers_lost_job_requeued, ft_teardown),
        cmocka_unit_test_teardown(test_pools_and_benching, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}

/*
 * test_farm_errors.c: the farm's errors and exit codes, with real
 * processes:
 *   - protocol version mismatch, both sides: a worker speaking version 2
 *     gets Reject VERSION_MISMATCH with the exact words and the master
 *     goes on rendering; a worker refused by a master (Reject, or a
 *     Welcome of version 2) prints the reason and exits 2;
 *   - a worker facing a fake master: Ask after Welcome, NeedJob for a
 *     grant of an unknown job, Failure for a Job whose hash does not
 *     match its content, Hello again after Reject HELLO_FIRST, exit 0 on
 *     Shutdown;
 *   - a shader over its instruction budget: retried on the workers, then
 *     the job fails with the shader's error, exit 1, no output file;
 *   - a shader that does not compile: exit 3 with the same diagnostics as
 *     the standalone renderer, before any worker is started or a socket
 *     bound;
 *   - usage errors: exit 2.
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
#include <zmq.h>

#include "farm_testutil.h"
#include "version.h"
#include "wire_pb.h"

static char *dir;

static int group_setup(void **state)
{
    (void)state;
    return ft_group_begin(&dir, FT_SCENE_WAVE, 8);
}

/* A ZeroMQ socket of the test with a receive timeout. */
static void *test_socket(void *ctx, int type)
{
    void *s = zmq_socket(ctx, type);
    int linger = 0, timeout = 20000;
    zmq_setsockopt(s, ZMQ_LINGER, &linger, sizeof linger);
    zmq_setsockopt(s, ZMQ_RCVTIMEO, &timeout, sizeof timeout);
    assert_int_equal(wire_socket_setup(s, NULL, NULL, 0), 0);
    zmq_setsockopt(s, ZMQ_LINGER, &linger, sizeof linger);
    return s;
}

static void test_farm_master_rejects_other_version(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "version.log"), *json = ft_path(dir, "version.json");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "version.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "8", "--stats-json", json, NULL};
    pid_t master = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 30));

    void *ctx = zmq_ctx_new();
    void *d = test_socket(ctx, ZMQ_DEALER);
    assert_int_equal(zmq_connect(d, ep), 0);
    Aafarm__Hello h = AAFARM__HELLO__INIT;
    h.protocol_version = AAFARM_PROTOCOL_VERSION + 1;
    h.worker_name = "future";
    h.host = "elsewhere";
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_HELLO;
    env.hello = &h;
    assert_int_equal(wire_send_envelope(d, NULL, NULL, 0, &env, NULL, 0, NULL, 0), 0);
    wire_msg *m = wire_recv(d, NULL, NULL, 0, NULL, 0);
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), PROTO_REJECT);
    const Aafarm__Reject *r = wire_msg_envelope(m)->reject;
    assert_int_equal(r->code, AAFARM__REJECT_CODE__REJECT_CODE_VERSION_MISMATCH);
    assert_int_equal(r->protocol_version, AAFARM_PROTOCOL_VERSION);
    char want[128];
    snprintf(want, sizeof want, "master speaks protocol %d, worker %d: upgrade the older side",
             AAFARM_PROTOCOL_VERSION, AAFARM_PROTOCOL_VERSION + 1);
    assert_string_equal(r->reason, want);
    wire_msg_destroy(&m);
    zmq_close(d);
    zmq_ctx_term(ctx);
    assert_true(ft_wait_for(log, "refused worker future on elsewhere", 1, 10));

    /* the master is unharmed: a real worker renders the image */
    const char *wargv[] = {ft_worker, "--connect", ep, "--name", "current", "--threads", "2", NULL};
    pid_t worker = ft_spawn(ft_path(dir, "current.log"), wargv);
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "version.exr")), 0);
    assert_int_equal(ft_json_number(json, "version_mismatches"), 1);
    kill(worker, SIGTERM);
    assert_int_equal(ft_wait(worker, 20), 130);
}

/* A fake master: receives the worker's Hello and answers with `answer`;
 * the worker must exit 2 saying why. */
static void worker_refused(const Aafarm__Envelope *answer, const char *log_name,
                           const char *why)
{
    void *ctx = zmq_ctx_new();
    void *r = test_socket(ctx, ZMQ_ROUTER);
    assert_int_equal(zmq_bind(r, "tcp://127.0.0.1:*"), 0);
    char ep[256];
    size_t len = sizeof ep;
    assert_int_equal(zmq_getsockopt(r, ZMQ_LAST_ENDPOINT, ep, &len), 0);
    const char *log = ft_path(dir, log_name);
    const char *argv[] = {ft_worker, "--connect", ep, "--name", "w", "--threads", "1", NULL};
    pid_t worker = ft_spawn(log, argv);
    wire_msg *m = wire_recv(r, NULL, NULL, 0, NULL, 0);
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), PROTO_HELLO);
    const Aafarm__Hello *h = wire_msg_envelope(m)->hello;
    assert_int_equal(h->protocol_version, AAFARM_PROTOCOL_VERSION);
    assert_string_equal(h->worker_name, "w");
    assert_int_equal(h->threads, 1);
    assert_int_equal(h->pid, (uint32_t)worker);
    size_t id_len;
    const uint8_t *id = wire_msg_identity(m, &id_len);
    assert_int_equal(wire_send_envelope(r, NULL, id, id_len, answer, NULL, 0, NULL, 0), 0);
    wire_msg_destroy(&m);
    assert_int_equal(ft_wait(worker, 20), 2);
    assert_int_equal(ft_count(log, why), 1);
    zmq_close(r);
    zmq_ctx_term(ctx);
}

static void test_farm_worker_refused_by_master(void **state)
{
    (void)state;
    char why[128];
    snprintf(why, sizeof why, "master speaks protocol %d, worker %d: upgrade the older side",
             AAFARM_PROTOCOL_VERSION + 1, AAFARM_PROTOCOL_VERSION);
    Aafarm__Reject rej = AAFARM__REJECT__INIT;
    rej.code = AAFARM__REJECT_CODE__REJECT_CODE_VERSION_MISMATCH;
    rej.reason = why;
    rej.protocol_version = AAFARM_PROTOCOL_VERSION + 1;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_REJECT;
    env.reject = &rej;
    worker_refused(&env, "refused.log", why);

    /* a master of another version that says Welcome: the worker sees it */
    Aafarm__Welcome wel = AAFARM__WELCOME__INIT;
    wel.protocol_version = AAFARM_PROTOCOL_VERSION + 1;
    wel.master_session = 42;
    wel.heartbeat_ms = 1000;
    wel.heartbeat_liveness = 3;
    Aafarm__Envelope env2 = AAFARM__ENVELOPE__INIT;
    env2.body_case = AAFARM__ENVELOPE__BODY_WELCOME;
    env2.welcome = &wel;
    worker_refused(&env2, "welcomed.log", why);
}

/* The next message from the worker that is not a Heartbeat. */
static wire_msg *recv_skipping_heartbeats(void *router)
{
    for (;;) {
        wire_msg *m = wire_recv(router, NULL, NULL, 0, NULL, 0);
        assert_non_null(m);
        if (wire_msg_kind(m) != PROTO_HEARTBEAT) return m;
        wire_msg_destroy(&m);
    }
}

static void send_to_worker(void *router, const wire_msg *from, Aafarm__Envelope *env)
{
    size_t id_len;
    const uint8_t *id = wire_msg_identity(from, &id_len);
    assert_int_equal(wire_send_envelope(router, NULL, id, id_len, env, NULL, 0, NULL, 0), 0);
}

/* A fake master walks a worker through its state machine: Welcome -> Ask,
 * a Grant of an unknown job -> NeedJob, a Job whose content does not match
 * its hash -> Failure (retryable), Reject HELLO_FIRST -> Hello again,
 * Shutdown -> exit 0. */
static void test_farm_worker_follows_the_protocol(void **state)
{
    (void)state;
    void *ctx = zmq_ctx_new();
    void *r = test_socket(ctx, ZMQ_ROUTER);
    assert_int_equal(zmq_bind(r, "tcp://127.0.0.1:*"), 0);
    char ep[256];
    size_t len = sizeof ep;
    assert_int_equal(zmq_getsockopt(r, ZMQ_LAST_ENDPOINT, ep, &len), 0);
    const char *log = ft_path(dir, "protocol.log");
    const char *argv[] = {ft_worker, "--connect", ep, "--name", "p", "--threads", "1", NULL};
    pid_t worker = ft_spawn(log, argv);

    wire_msg *hello = recv_skipping_heartbeats(r);
    assert_int_equal(wire_msg_kind(hello), PROTO_HELLO);
    Aafarm__Welcome wel = AAFARM__WELCOME__INIT;
    wel.protocol_version = AAFARM_PROTOCOL_VERSION;
    wel.master_session = 7;
    wel.heartbeat_ms = 1000;
    wel.heartbeat_liveness = 3;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_WELCOME;
    env.welcome = &wel;
    send_to_worker(r, hello, &env);

    wire_msg *m = recv_skipping_heartbeats(r);
    assert_int_equal(wire_msg_kind(m), PROTO_ASK);
    assert_int_equal(wire_msg_envelope(m)->ask->credits, 2);   /* two per thread */
    wire_msg_destroy(&m);

    static char hash[65];
    memset(hash, 'a', 64);
    Aafarm__Rect rect = AAFARM__RECT__INIT;
    rect.width = rect.height = 8;
    Aafarm__Grant g = AAFARM__GRANT__INIT;
    g.job_hash = hash;
    g.lease_id = 1;
    g.tile = &rect;
    g.deadline_ms = 60000;
    Aafarm__Envelope genv = AAFARM__ENVELOPE__INIT;
    genv.body_case = AAFARM__ENVELOPE__BODY_GRANT;
    genv.grant = &g;
    send_to_worker(r, hello, &genv);
    m = recv_skipping_heartbeats(r);
    assert_int_equal(wire_msg_kind(m), PROTO_NEED_JOB);
    assert_string_equal(wire_msg_envelope(m)->need_job->job_hash, hash);
    assert_int_equal(wire_msg_envelope(m)->need_job->lease_id, 1);
    wire_msg_destroy(&m);

    /* a Job whose content hashes to something else */
    static char scene[] = "Format 8 8 1\nWorldBegin\nWorldEnd\n";
    Aafarm__RenderOptions o = AAFARM__RENDER_OPTIONS__INIT;
    o.width = o.height = o.tile_size = 8;
    Aafarm__Job job = AAFARM__JOB__INIT;
    job.job_hash = hash;
    job.scene_name = "tiny.rib";
    job.scene_text.data = (uint8_t *)scene;
    job.scene_text.len = strlen(scene);
    job.options = &o;
    Aafarm__Envelope jenv = AAFARM__ENVELOPE__INIT;
    jenv.body_case = AAFARM__ENVELOPE__BODY_JOB;
    jenv.job = &job;
    send_to_worker(r, hello, &jenv);
    m = recv_skipping_heartbeats(r);
    assert_int_equal(wire_msg_kind(m), PROTO_FAILURE);
    const Aafarm__Failure *f = wire_msg_envelope(m)->failure;
    assert_int_equal(f->lease_id, 1);
    assert_true(f->retryable);
    assert_non_null(strstr(f->message, "its content hashes to"));
    wire_msg_destroy(&m);

    Aafarm__Reject rej = AAFARM__REJECT__INIT;
    rej.code = AAFARM__REJECT_CODE__REJECT_CODE_HELLO_FIRST;
    rej.reason = "who are you?";
    Aafarm__Envelope renv = AAFARM__ENVELOPE__INIT;
    renv.body_case = AAFARM__ENVELOPE__BODY_REJECT;
    renv.reject = &rej;
    send_to_worker(r, hello, &renv);
    m = recv_skipping_heartbeats(r);
    while (wire_msg_kind(m) == PROTO_ASK) {   /* sent after the Failure */
        wire_msg_destroy(&m);
        m = recv_skipping_heartbeats(r);
    }
    assert_int_equal(wire_msg_kind(m), PROTO_HELLO);
    wire_msg_destroy(&m);

    Aafarm__Shutdown sd = AAFARM__SHUTDOWN__INIT;
    Aafarm__Envelope senv = AAFARM__ENVELOPE__INIT;
    senv.body_case = AAFARM__ENVELOPE__BODY_SHUTDOWN;
    senv.shutdown = &sd;
    send_to_worker(r, hello, &senv);
    assert_int_equal(ft_wait(worker, 20), 0);
    wire_msg_destroy(&hello);
    zmq_close(r);
    zmq_ctx_term(ctx);
}

static void test_farm_shader_over_budget_fails_job(void **state)
{
    (void)state;
    char *sub = ft_tempdir();
    ft_write_scene(sub, FT_SCENE_BUDGET);
    const char *log = ft_path(sub, "budget.log"), *out = ft_path(sub, "budget.exr");
    const char *argv[] = {ft_master, ft_path(sub, "scene.rib"), "-o", out, "--local-workers", "2",
                          "--budget", "1000", "--tile", "16", NULL};
    pid_t master = ft_spawn(log, argv);
    assert_int_equal(ft_wait(master, 120), 1);
    /* retried, then failed with the shader's own words */
    assert_true(ft_count(log, "(attempt 1 of 3)") >= 1);
    assert_int_equal(ft_count(log, "render failed: tile "), 1);
    assert_int_equal(ft_count(log, "(attempts exhausted)"), 1);
    char *text = ft_read(log);
    const char *fail = strstr(text, "render failed: ");
    assert_non_null(fail);
    assert_non_null(strstr(fail, "shader 'spin': instruction budget of 1000 exceeded"));
    free(text);
    assert_int_equal(ft_count(log, "budget.exr not written"), 1);
    assert_int_equal(access(out, F_OK), -1);
    assert_int_equal(ft_count_files(sub, "budget.exr.tmp"), 0);
    ft_rmtree(sub);
    free(sub);
}

static void test_farm_bad_shader_fails_fast(void **state)
{
    (void)state;
    char *sub = ft_tempdir();
    ft_write_scene(sub, FT_SCENE_BROKEN);
    const char *slog = ft_path(sub, "standalone.log");
    const char *sargv[] = {ft_worker, "--standalone", ft_path(sub, "scene.rib"), "-o",
                           ft_path(sub, "s.exr"), NULL};
    assert_int_equal(ft_wait(ft_spawn(slog, sargv), 60), 3);
    const char *mlog = ft_path(sub, "master.log");
    const char *margv[] = {ft_master, ft_path(sub, "scene.rib"), "-o", ft_path(sub, "m.exr"),
                           "--bind", "tcp://127.0.0.1:*", "--local-workers", "2", NULL};
    assert_int_equal(ft_wait(ft_spawn(mlog, margv), 60), 3);
    /* the same diagnostics, file:line:col first; nothing started */
    char *s = ft_read(slog), *m = ft_read(mlog);
    assert_true(strlen(s) > 0);
    assert_string_equal(m, s);
    char where[4200];
    snprintf(where, sizeof where, "%s:3:", ft_path(sub, "shaders/twave.sl"));
    assert_non_null(strstr(m, where));
    assert_null(strstr(m, "listening on"));
    assert_null(strstr(m, "joined"));
    free(s);
    free(m);
    assert_int_equal(access(ft_path(sub, "m.exr"), F_OK), -1);
    ft_rmtree(sub);
    free(sub);
}

/* A scene file over the job's text limit (4 MiB) is refused from its
 * size before it is parsed (issue 23: a 59 MB RIB was parsed for a minute
 * first), with the way out; no worker is started, no output written. */
static void test_farm_scene_too_large_refused_before_parsing(void **state)
{
    (void)state;
    char *sub = ft_tempdir();
    const char *rib = ft_path(sub, "big.rib");
    FILE *f = fopen(rib, "w");
    assert_non_null(f);
    fputs("Format 8 8 1\nWorldBegin\n", f);
    /* not even valid RIB after the first lines: parsing it would fail */
    for (int i = 0; i < (5 << 20) / 64; i++)
        fputs("NoSuchRequest 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n", f);
    fclose(f);
    const char *mlog = ft_path(sub, "master.log");
    const char *margv[] = {ft_master, rib, "-o", ft_path(sub, "m.exr"), "--local-workers", "1",
                           NULL};
    assert_int_equal(ft_wait(ft_spawn(mlog, margv), 60), 3);
    assert_int_equal(ft_count(mlog, "the farm ships at most 4194304 (4 MiB) in a job: render it "
                                    "on one host with aafarm-worker --standalone"), 1);
    assert_int_equal(ft_count(mlog, "NoSuchRequest"), 0);
    assert_int_equal(ft_count(mlog, "joined"), 0);
    assert_int_equal(access(ft_path(sub, "m.exr"), F_OK), -1);
    ft_rmtree(sub);
    free(sub);
}

static void test_farm_usage_errors(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "usage.log");
    const char *no_output[] = {ft_master, ft_path(dir, "scene.rib"), NULL};
    assert_int_equal(ft_wait(ft_spawn(log, no_output), 30), 2);
    const char *nobody[] = {ft_master, ft_path(dir, "scene.rib"), "-o", "x.exr",
                            "--local-workers", "0", NULL};
    assert_int_equal(ft_wait(ft_spawn(log, nobody), 30), 2);
    const char *bad_tile[] = {ft_master, ft_path(dir, "scene.rib"), "-o", "x.exr", "--tile", "0",
                              NULL};
    assert_int_equal(ft_wait(ft_spawn(log, bad_tile), 30), 2);
    /* an out-of-range number names both bounds (issue 27: --budget) */
    const char *big_budget[] = {ft_master, ft_path(dir, "scene.rib"), "-o", "x.exr", "--budget",
                                "2000000000", NULL};
    assert_int_equal(ft_wait(ft_spawn(log, big_budget), 30), 2);
    const char *bad_bind[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "x.exr"),
                              "--bind", "nonsense://here", NULL};
    assert_int_equal(ft_wait(ft_spawn(log, bad_bind), 30), 2);
    assert_int_equal(access(ft_path(dir, "x.exr"), F_OK), -1);
    assert_int_equal(ft_count_files(dir, "x.exr.tmp"), 0);
    const char *bad_connect[] = {ft_worker, "--connect", "nonsense://here", NULL};
    assert_int_equal(ft_wait(ft_spawn(log, bad_connect), 30), 2);
    assert_int_equal(ft_count(log, "cannot bind nonsense://here"), 1);
    assert_int_equal(ft_count(log, "aafarm-master: --tile wants a size 1..1024, got '0'"), 1);
    assert_int_equal(ft_count(log, "aafarm-master: --budget wants a number 1000..1000000000, "
                                   "got '2000000000'"), 1);
    assert_int_equal(ft_count(log, "cannot connect to 'nonsense://here'"), 1);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_farm_master_rejects_other_version, ft_teardown),
        cmocka_unit_test_teardown(test_farm_worker_refused_by_master, ft_teardown),
        cmocka_unit_test_teardown(test_farm_worker_follows_the_protocol, ft_teardown),
        cmocka_unit_test_teardown(test_farm_shader_over_budget_fails_job, ft_teardown),
        cmocka_unit_test_teardown(test_farm_bad_shader_fails_fast, ft_teardown),
        cmocka_unit_test_teardown(test_farm_scene_too_large_refused_before_parsing, ft_teardown),
        cmocka_unit_test_teardown(test_farm_usage_errors, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}

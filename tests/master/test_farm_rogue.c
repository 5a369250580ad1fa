/*
 * test_farm_rogue.c: no single peer can end or stall a render (issue 11).
 * Real aafarm-master and aafarm-worker processes over tcp://127.0.0.1;
 * the rogue peers are ZeroMQ sockets of this test speaking the protocol:
 *   - a peer that answers every grant with a non-retryable Failure: the
 *     render completes (each such failure is retried on the honest worker;
 *     it would need a second worker to confirm it);
 *   - two peers that take tiles, keep heartbeating and never deliver
 *     (--lease 600 s): their leases pass the deadline derived from the
 *     honest worker's speed, their tiles go to it, they get nothing new;
 *   - peers pushing frames far larger than a tile: ZeroMQ cuts them off
 *     at the master's per-tile bound, the master's memory stays small.
 * In each case the image equals the standalone render.
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
#include <time.h>
#include <zmq.h>

#include "farm_testutil.h"
#include "version.h"
#include "wire_pb.h"

static char *dir;

static int group_setup(void **state)
{
    (void)state;
    dir = ft_tempdir();
    ft_write_scene(dir, FT_SCENE_WAVE);
    return ft_standalone(dir, 8) == 0 ? 0 : -1;
}

static int group_teardown(void **state)
{
    (void)state;
    ft_stop_all();
    ft_rmtree(dir);
    free(dir);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    ft_stop_all();
    return 0;
}

/* Each render below takes a few seconds; the loops that play the rogue
 * peers stop after 120 s whatever happens (then the test fails on the
 * master's exit status, and the teardown kills it). */
static pid_t start_master(const char *name, char *ep, size_t epsz)
{
    char out[4096], log[4096], json[4096];
    snprintf(out, sizeof out, "%s/%s.exr", dir, name);
    snprintf(log, sizeof log, "%s/%s.log", dir, name);
    snprintf(json, sizeof json, "%s/%s.json", dir, name);
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", out, "--bind",
                          "tcp://127.0.0.1:*", "--tile", "8", "--heartbeat", "250",
                          "--liveness", "8", "--lease", "600", "--stats-json", json, "-v", NULL};
    pid_t master = ft_spawn(log, argv);
    assert_true(ft_master_endpoint(log, ep, epsz, 30));
    return master;
}

static pid_t start_honest(const char *ep, const char *master_log)
{
    const char *argv[] = {ft_worker, "--connect", ep, "--name", "honest", "--threads", "1",
                          "--tile-delay", "30", NULL};
    pid_t w = ft_spawn(ft_path(dir, "honest.log"), argv);
    assert_true(ft_wait_for(master_log, "worker honest joined", 1, 30));
    return w;
}

typedef struct rogue {
    void *s;
    int grants;
    int64_t last_hb;
} rogue;

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void send_env(void *s, Aafarm__Envelope *env)
{
    wire_send_envelope(s, NULL, NULL, 0, env, NULL, 0, NULL, 0);   /* best effort, never blocks */
}

static void rogue_hello(rogue *r, void *ctx, const char *ep, const char *name)
{
    r->s = zmq_socket(ctx, ZMQ_DEALER);
    int linger = 0;
    zmq_setsockopt(r->s, ZMQ_LINGER, &linger, sizeof linger);
    assert_int_equal(zmq_connect(r->s, ep), 0);
    Aafarm__Hello h = AAFARM__HELLO__INIT;
    h.protocol_version = AAFARM_PROTOCOL_VERSION;
    h.worker_name = (char *)name;
    h.host = "rogue-host";
    h.pid = 1;
    h.threads = 1;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_HELLO;
    env.hello = &h;
    send_env(r->s, &env);
}

static void rogue_ask(rogue *r, uint32_t n)
{
    Aafarm__Ask a = AAFARM__ASK__INIT;
    a.credits = n;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_ASK;
    env.ask = &a;
    send_env(r->s, &env);
}

static void rogue_heartbeat(rogue *r)
{
    if (now_ms() - r->last_hb < 100) return;
    Aafarm__Heartbeat hb = AAFARM__HEARTBEAT__INIT;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_HEARTBEAT;
    env.heartbeat = &hb;
    send_env(r->s, &env);
    r->last_hb = now_ms();
}

/* Reads what the master sent; a Grant is answered with a non-retryable
 * Failure when `fail`, otherwise kept forever. Welcome: Ask. */
static void rogue_serve(rogue *r, bool fail)
{
    for (;;) {
        wire_msg *m = wire_recv(r->s, NULL, NULL, ZMQ_DONTWAIT, NULL, 0);
        if (!m) return;
        const Aafarm__Envelope *env = wire_msg_envelope(m);
        if (wire_msg_kind(m) == PROTO_WELCOME) rogue_ask(r, 4);
        if (wire_msg_kind(m) == PROTO_GRANT) {
            r->grants++;
            if (fail) {
                Aafarm__Failure x = AAFARM__FAILURE__INIT;
                x.job_hash = env->grant->job_hash;
                x.lease_id = env->grant->lease_id;
                x.tile_index = env->grant->tile_index;
                x.message = "rogue: this tile can never be rendered";
                x.retryable = false;
                Aafarm__Envelope out = AAFARM__ENVELOPE__INIT;
                out.body_case = AAFARM__ENVELOPE__BODY_FAILURE;
                out.failure = &x;
                send_env(r->s, &out);
            }
            rogue_ask(r, 1);   /* always hungry for more */
        }
        wire_msg_destroy(&m);
    }
}

static void test_nonretryable_failure_from_one_peer_does_not_end_render(void **state)
{
    (void)state;
    char ep[256];
    pid_t master = start_master("fail", ep, sizeof ep);
    const char *log = ft_path(dir, "fail.log");
    pid_t honest = start_honest(ep, log);
    void *ctx = zmq_ctx_new();
    rogue r = {0};
    rogue_hello(&r, ctx, ep, "liar");
    for (int64_t end = now_ms() + 120000; ft_running(master) && now_ms() < end;) {
        zmq_pollitem_t it = {r.s, 0, ZMQ_POLLIN, 0};
        zmq_poll(&it, 1, 50);
        rogue_serve(&r, true);
        rogue_heartbeat(&r);
    }
    assert_int_equal(ft_wait(master, 10), 0);
    assert_true(r.grants >= 1);
    assert_true(ft_count(log, "failed on liar") >= 1);
    assert_int_equal(ft_count(log, "render failed"), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "fail.exr")), 0);
    zmq_close(r.s);
    zmq_ctx_term(ctx);
    kill(honest, SIGTERM);
    assert_int_equal(ft_wait(honest, 20), 130);
}

static void test_hoarders_lose_their_tiles_and_get_no_more(void **state)
{
    (void)state;
    char ep[256];
    pid_t master = start_master("hoard", ep, sizeof ep);
    char log[4096];
    snprintf(log, sizeof log, "%s", ft_path(dir, "hoard.log"));
    void *ctx = zmq_ctx_new();
    rogue r[2] = {{0}, {0}};
    rogue_hello(&r[0], ctx, ep, "hoarder0");
    rogue_hello(&r[1], ctx, ep, "hoarder1");
    /* the hoarders take their tiles first */
    for (int64_t until = now_ms() + 10000; (r[0].grants < 1 || r[1].grants < 1) && now_ms() < until;) {
        zmq_pollitem_t it[2] = {{r[0].s, 0, ZMQ_POLLIN, 0}, {r[1].s, 0, ZMQ_POLLIN, 0}};
        zmq_poll(it, 2, 50);
        for (int i = 0; i < 2; i++) rogue_serve(&r[i], false), rogue_heartbeat(&r[i]);
    }
    assert_true(r[0].grants >= 1 && r[1].grants >= 1);
    pid_t honest = start_honest(ep, log);
    int snapshot[2] = {-1, -1};
    int64_t settle = 0;
    for (int64_t end = now_ms() + 120000; ft_running(master) && now_ms() < end;) {
        zmq_pollitem_t it[2] = {{r[0].s, 0, ZMQ_POLLIN, 0}, {r[1].s, 0, ZMQ_POLLIN, 0}};
        zmq_poll(it, 2, 50);
        for (int i = 0; i < 2; i++) rogue_serve(&r[i], false), rogue_heartbeat(&r[i]);
        /* once both hoarders' leases passed their deadline (and what was
         * in flight arrived), they must get nothing more */
        if (!settle && ft_count(log, "passed its deadline") + ft_count(log, "passed their deadline") >= 1)
            settle = now_ms() + 500;
        if (settle && snapshot[0] < 0 && now_ms() > settle) {
            snapshot[0] = r[0].grants;
            snapshot[1] = r[1].grants;
        }
    }
    assert_int_equal(ft_wait(master, 10), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "hoard.exr")), 0);
    const char *json = ft_path(dir, "hoard.json");
    assert_true(ft_json_number(json, "expired_leases") >= 2);
    assert_true(snapshot[0] >= 1);
    /* the block holds while a hoarder has an overdue lease (it always has) */
    assert_int_equal(r[0].grants, snapshot[0]);
    assert_int_equal(r[1].grants, snapshot[1]);
    /* and the honest worker did everything */
    char *text = ft_read(log);
    const char *row = strstr(text, "  honest ");
    assert_non_null(row);
    long tiles = -1;
    sscanf(row, " honest %*s %ld", &tiles);
    assert_int_equal(tiles, 48);
    free(text);
    for (int i = 0; i < 2; i++) zmq_close(r[i].s);
    zmq_ctx_term(ctx);
    kill(honest, SIGTERM);
    assert_int_equal(ft_wait(honest, 20), 130);
}

enum { PUSHERS = 8, PUSH_BYTES = 4 << 20 };

static void test_oversized_frames_are_cut_off(void **state)
{
    (void)state;
    char ep[256];
    pid_t master = start_master("push", ep, sizeof ep);
    const char *log = ft_path(dir, "push.log");
    pid_t honest = start_honest(ep, log);
    void *ctx = zmq_ctx_new();
    void *s[PUSHERS];
    uint8_t *junk = calloc(1, PUSH_BYTES);
    assert_non_null(junk);
    for (int i = 0; i < PUSHERS; i++) {
        s[i] = zmq_socket(ctx, ZMQ_DEALER);
        int linger = 0, hwm = 2;
        zmq_setsockopt(s[i], ZMQ_LINGER, &linger, sizeof linger);
        zmq_setsockopt(s[i], ZMQ_SNDHWM, &hwm, sizeof hwm);
        assert_int_equal(zmq_connect(s[i], ep), 0);
    }
    long pushed = 0;
    for (int64_t end = now_ms() + 120000; ft_running(master) && now_ms() < end;) {
        for (int i = 0; i < PUSHERS; i++) {
            /* a frame far over any tile, then another: ZeroMQ frames */
            if (zmq_send(s[i], "x", 1, ZMQ_SNDMORE | ZMQ_DONTWAIT) == 1) {
                zmq_send(s[i], junk, PUSH_BYTES, ZMQ_DONTWAIT);
                pushed++;
            }
        }
        ft_sleep_ms(20);
    }
    assert_int_equal(ft_wait(master, 10), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "push.exr")), 0);
    const char *json = ft_path(dir, "push.json");
    long bound = ft_json_number(json, "max_bulk_bytes");
    assert_true(bound > 0 && bound < (1 << 20));
    /* the pushers were cut off (and reconnected, and were cut off again) */
    assert_true(ft_json_number(json, "disconnects") >= PUSHERS);
    long rss_kb = ft_json_number(json, "master_peak_rss_kb");
    fprintf(stderr, "pushed %ld frames of %d MiB; master peak RSS %ld KiB\n", pushed,
            PUSH_BYTES >> 20, rss_kb);
    assert_true(pushed >= PUSHERS);
    assert_true(rss_kb > 0 && rss_kb < 128 * 1024);
    for (int i = 0; i < PUSHERS; i++) zmq_close(s[i]);
    zmq_ctx_term(ctx);
    free(junk);
    kill(honest, SIGTERM);
    assert_int_equal(ft_wait(honest, 20), 130);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_nonretryable_failure_from_one_peer_does_not_end_render,
                                  teardown),
        cmocka_unit_test_teardown(test_hoarders_lose_their_tiles_and_get_no_more, teardown),
        cmocka_unit_test_teardown(test_oversized_frames_are_cut_off, teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}

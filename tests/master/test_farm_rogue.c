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
 *   - (issue 27) a real worker behind a proxy of this test that alters
 *     its Results (a byte of the EXR), alone: its results are refused, it
 *     is blocklisted for the job, the render waits; an honest worker
 *     joining later renders the image;
 *   - a peer failing every grant non-retryably, alone: each tile it gave
 *     up on waits for another worker (--lease); an honest one joining
 *     later renders them;
 *   - a proxy answering each lease with another tile's index (issue 27,
 *     7(c)): refused as an invalid tile, the tile re-leased;
 *   - a shader over its budget on two honest workers: they agree, the
 *     render fails at once with the shader's words (no wait for a third);
 *     on one worker alone with --lease 3: it fails after the window.
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
#include <unistd.h>
#include <zmq.h>

#include "farm_testutil.h"
#include "version.h"
#include "wire_pb.h"

static char *dir;

static int group_setup(void **state)
{
    (void)state;
    /* ref24.exr: --tile 24 (6 tiles), the issue's case; ref.exr: --tile 8 */
    if (ft_group_begin(&dir, FT_SCENE_WAVE, 24) != 0) return -1;
    char ref24[4096];
    snprintf(ref24, sizeof ref24, "%s", ft_path(dir, "ref24.exr"));
    if (rename(ft_path(dir, "ref.exr"), ref24) != 0) return -1;
    return ft_standalone(dir, 8) == 0 ? 0 : -1;
}

/* Each render below takes a few seconds; the loops that play the rogue
 * peers stop after 120 s whatever happens (then the test fails on the
 * master's exit status, and the teardown kills it). */
static pid_t start_master_in(const char *where, const char *name, const char *tile,
                             const char *lease, const char *budget, char *ep, size_t epsz)
{
    char out[4096], log[4096], json[4096];
    snprintf(out, sizeof out, "%s/%s.exr", where, name);
    snprintf(log, sizeof log, "%s/%s.log", where, name);
    snprintf(json, sizeof json, "%s/%s.json", where, name);
    const char *argv[] = {ft_master, ft_path(where, "scene.rib"), "-o", out, "--bind",
                          "tcp://127.0.0.1:*", "--tile", tile, "--heartbeat", "250",
                          "--liveness", "8", "--lease", lease, "--budget", budget,
                          "--stats-json", json, "-v", NULL};
    pid_t master = ft_spawn(log, argv);
    assert_true(ft_master_endpoint(log, ep, epsz, 30));
    return master;
}

static pid_t start_master(const char *name, char *ep, size_t epsz)
{
    return start_master_in(dir, name, "8", "600", "1000000", ep, epsz);
}

static pid_t spawn_worker(const char *where, const char *ep, const char *name)
{
    char log[4096];
    snprintf(log, sizeof log, "%s/%s.log", where, name);
    const char *argv[] = {ft_worker, "--connect", ep, "--name", name, "--threads", "1",
                          "--tile-delay", "30", NULL};
    return ft_spawn(log, argv);
}

/* SIGTERM to each worker; each must exit 130. */
static void stop_workers(const pid_t *w, int n)
{
    for (int i = 0; i < n; i++) kill(w[i], SIGTERM);
    for (int i = 0; i < n; i++) assert_int_equal(ft_wait(w[i], 20), 130);
}

/* The worker's row of the master's summary: its "tiles" column, and
 * whether the row ends in the given state. */
static long summary_tiles(const char *log, const char *name, const char *state)
{
    char *text = ft_read(log), key[160];
    snprintf(key, sizeof key, "  %s ", name);
    const char *row = strstr(text, key);
    assert_non_null(row);
    long tiles = -1;
    snprintf(key, sizeof key, " %s %%*s %%ld", name);
    sscanf(row, key, &tiles);
    const char *eol = strchr(row, '\n');
    size_t n = strlen(state);
    if (state[0]) assert_true(eol && (size_t)(eol - row) > n && memcmp(eol - n, state, n) == 0);
    free(text);
    return tiles;
}

static pid_t start_honest(const char *ep, const char *master_log)
{
    pid_t w = spawn_worker(dir, ep, "honest");
    assert_true(ft_wait_for(master_log, "worker honest joined", 1, 30));
    return w;
}

typedef struct rogue {
    void *s;
    uint32_t threads;   /* what its Hello claims (0: 1) */
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
    h.threads = r->threads ? r->threads : 1;
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
    stop_workers(&honest, 1);
}

static void test_hoarders_lose_their_tiles_and_get_no_more(void **state)
{
    (void)state;
    char ep[256];
    pid_t master = start_master("hoard", ep, sizeof ep);
    char log[4096];
    snprintf(log, sizeof log, "%s", ft_path(dir, "hoard.log"));
    void *ctx = zmq_ctx_new();
    /* they claim many threads, so the end of the queue's rule (master/
     * scheduler.h) does not keep the last tiles from them: they take all */
    rogue r[2] = {{.threads = 32}, {.threads = 32}};
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
    assert_int_equal(summary_tiles(log, "honest", ""), 48);
    for (int i = 0; i < 2; i++) zmq_close(r[i].s);
    zmq_ctx_term(ctx);
    stop_workers(&honest, 1);
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
    stop_workers(&honest, 1);
}

/* ---- a proxy between a real worker and the master ---- */

typedef enum { ALTER_EXR, OTHER_INDEX } proxy_mode;

/* The worker connects to front (a ROUTER of this test), the proxy to the
 * master through back (a DEALER); every message is passed on, and each
 * Result is altered on its way: ALTER_EXR flips a byte of the tile's EXR
 * header, OTHER_INDEX names the next tile instead of the leased one (the
 * EXR stays the leased tile's, so only the index check can refuse it). */
typedef struct proxy {
    void *front, *back;
    uint8_t id[256];
    size_t id_len;
    proxy_mode mode;
    uint32_t ntiles;
    int results;
} proxy;

static void proxy_open(proxy *p, void *ctx, const char *master_ep, proxy_mode mode,
                       uint32_t ntiles, char *front_ep, size_t n)
{
    *p = (proxy){.mode = mode, .ntiles = ntiles};
    p->front = zmq_socket(ctx, ZMQ_ROUTER);
    p->back = zmq_socket(ctx, ZMQ_DEALER);
    int linger = 0;
    zmq_setsockopt(p->front, ZMQ_LINGER, &linger, sizeof linger);
    zmq_setsockopt(p->back, ZMQ_LINGER, &linger, sizeof linger);
    assert_int_equal(zmq_bind(p->front, "tcp://127.0.0.1:*"), 0);
    size_t len = n;
    assert_int_equal(zmq_getsockopt(p->front, ZMQ_LAST_ENDPOINT, front_ep, &len), 0);
    assert_int_equal(zmq_connect(p->back, master_ep), 0);
}

static void proxy_close(proxy *p)
{
    zmq_close(p->front);
    zmq_close(p->back);
}

/* Passes on what is queued in both directions (waits up to 50 ms). */
static void proxy_pump(proxy *p)
{
    zmq_pollitem_t it[2] = {{p->front, 0, ZMQ_POLLIN, 0}, {p->back, 0, ZMQ_POLLIN, 0}};
    zmq_poll(it, 2, 50);
    wire_msg *m;
    while ((m = wire_recv(p->front, NULL, NULL, ZMQ_DONTWAIT, NULL, 0))) {
        size_t id_len = 0, len = 0;
        const uint8_t *id = wire_msg_identity(m, &id_len);
        if (id_len <= sizeof p->id) {
            memcpy(p->id, id, id_len);
            p->id_len = id_len;
        }
        Aafarm__Envelope *env = (Aafarm__Envelope *)wire_msg_envelope(m);
        const uint8_t *bulk = wire_msg_bulk(m, &len);
        uint8_t *copy = NULL;
        if (wire_msg_kind(m) == PROTO_RESULT) {
            p->results++;
            if (p->mode == ALTER_EXR && len > 16) {
                copy = malloc(len);
                assert_non_null(copy);
                memcpy(copy, bulk, len);
                copy[12] ^= 0x20;   /* in the header's first attribute name */
                bulk = copy;
            } else if (p->mode == OTHER_INDEX) {
                env->result->tile_index = (env->result->tile_index + 1) % p->ntiles;
            }
        }
        wire_send_envelope(p->back, NULL, NULL, 0, env, bulk, len, NULL, 0);
        free(copy);
        wire_msg_destroy(&m);
    }
    while ((m = wire_recv(p->back, NULL, NULL, ZMQ_DONTWAIT, NULL, 0))) {
        size_t len = 0;
        const uint8_t *bulk = wire_msg_bulk(m, &len);
        if (p->id_len)
            wire_send_envelope(p->front, NULL, p->id, p->id_len, wire_msg_envelope(m), bulk, len,
                               NULL, 0);
        wire_msg_destroy(&m);
    }
}

/* Issue 27, item 4: the only worker, behind a proxy that alters its
 * Results, cannot end the render; it is blocklisted, and an honest worker
 * joining a second later renders the image. */
static void test_rogue_alone_then_honest_worker(void **state)
{
    (void)state;
    char ep[256], front[256];
    pid_t master = start_master_in(dir, "alter", "24", "600", "1000000", ep, sizeof ep);
    const char *log = ft_path(dir, "alter.log");
    void *ctx = zmq_ctx_new();
    proxy p;
    proxy_open(&p, ctx, ep, ALTER_EXR, 6, front, sizeof front);
    pid_t rw = spawn_worker(dir, front, "rogue-R");
    /* its results are refused until it is blocklisted */
    int64_t end = now_ms() + 60000;
    while (ft_running(master) && now_ms() < end && ft_count(log, "blocklisted") == 0)
        proxy_pump(&p);
    assert_int_equal(ft_count(log, "worker rogue-R blocklisted for this job: 3 of its results "
                                   "refused"), 1);
    for (int64_t wait = now_ms() + 1000; now_ms() < wait;) proxy_pump(&p);
    assert_true(ft_running(master));   /* the issue: exit 1 after 1.6 s */
    pid_t honest = spawn_worker(dir, ep, "honest");
    for (end = now_ms() + 120000; ft_running(master) && now_ms() < end;) proxy_pump(&p);
    assert_int_equal(ft_wait(master, 10), 0);
    assert_true(p.results >= 3);
    assert_true(ft_count(log, "invalid tile from the worker") >= 3);
    assert_int_equal(ft_count(log, "render failed"), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref24.exr"), ft_path(dir, "alter.exr")), 0);
    /* the summary: the rogue took nothing and stayed connected, blocklisted */
    assert_int_equal(summary_tiles(log, "rogue-R", "blocklisted"), 0);
    proxy_close(&p);
    zmq_ctx_term(ctx);
    stop_workers((pid_t[]){rw, honest}, 2);
}

/* A peer failing every grant non-retryably, alone: it gives each tile up
 * after --retries attempts, the tiles wait for another worker (--lease
 * 600), and the honest worker joining later renders them. */
static void test_liar_alone_then_honest_worker(void **state)
{
    (void)state;
    char ep[256];
    pid_t master = start_master("liar", ep, sizeof ep);
    const char *log = ft_path(dir, "liar.log");
    void *ctx = zmq_ctx_new();
    rogue r = {0};
    rogue_hello(&r, ctx, ep, "liar");
    int64_t end = now_ms() + 60000;
    while (ft_running(master) && now_ms() < end && ft_count(log, "waiting up to") == 0) {
        zmq_pollitem_t it = {r.s, 0, ZMQ_POLLIN, 0};
        zmq_poll(&it, 1, 50);
        rogue_serve(&r, true);
        rogue_heartbeat(&r);
    }
    assert_true(ft_count(log, "(attempt 3 of 3): rogue: this tile can never be rendered; no "
                              "other worker has tried it: waiting up to 600 s") >= 1);
    pid_t honest = 0;
    for (end = now_ms() + 120000; ft_running(master) && now_ms() < end;) {
        zmq_pollitem_t it = {r.s, 0, ZMQ_POLLIN, 0};
        zmq_poll(&it, 1, 50);
        rogue_serve(&r, true);
        rogue_heartbeat(&r);
        if (!honest && ft_count(log, "waiting up to") >= 1 && now_ms() > end - 119000) {
            assert_true(ft_running(master));
            honest = spawn_worker(dir, ep, "honest");
        }
    }
    assert_int_equal(ft_wait(master, 10), 0);
    assert_true(honest > 0);
    assert_int_equal(ft_count(log, "render failed"), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "liar.exr")), 0);
    zmq_close(r.s);
    zmq_ctx_term(ctx);
    stop_workers(&honest, 1);
}

/* Issue 27, item 7(c): a Result naming another tile than its lease's is
 * refused; the tile is leased again and the image is complete and equal. */
static void test_result_with_another_tiles_index_refused(void **state)
{
    (void)state;
    char ep[256], front[256];
    pid_t master = start_master("index", ep, sizeof ep);
    const char *log = ft_path(dir, "index.log");
    void *ctx = zmq_ctx_new();
    proxy p;
    proxy_open(&p, ctx, ep, OTHER_INDEX, 48, front, sizeof front);
    pid_t rw = spawn_worker(dir, front, "rogue-I");
    int64_t end = now_ms() + 60000;
    while (ft_running(master) && now_ms() < end && ft_count(log, "worker rogue-I joined") == 0)
        proxy_pump(&p);
    pid_t honest = spawn_worker(dir, ep, "honest");
    for (end = now_ms() + 120000; ft_running(master) && now_ms() < end;) proxy_pump(&p);
    assert_int_equal(ft_wait(master, 10), 0);
    assert_true(p.results >= 1);
    assert_true(ft_count(log, "invalid tile from the worker: its result names tile ") >= 1);
    assert_true(ft_json_number(ft_path(dir, "index.json"), "invalid_tiles") >= 1);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "index.exr")), 0);
    assert_int_equal(summary_tiles(log, "rogue-I", ""), 0);   /* none of its results taken */
    proxy_close(&p);
    zmq_ctx_term(ctx);
    stop_workers((pid_t[]){rw, honest}, 2);
}

/* A shader over its instruction budget is a failure every worker agrees
 * on: with two workers the render fails at once with the shader's words
 * (--lease 600: it does not wait for a third); with one worker alone it
 * fails once --lease (3 s) has passed without another one. */
static void test_deterministic_failure_agreed_or_alone(void **state)
{
    (void)state;
    char *sub = ft_tempdir();
    ft_write_scene(sub, FT_SCENE_BUDGET);
    char ep[256];
    /* two workers agree */
    pid_t master = start_master_in(sub, "two", "16", "600", "1000", ep, sizeof ep);
    const char *log2 = ft_path(sub, "two.log");
    pid_t w1 = spawn_worker(sub, ep, "w1"), w2 = spawn_worker(sub, ep, "w2");
    assert_int_equal(ft_wait(master, 60), 1);
    char *text = ft_read(log2);
    const char *fail = strstr(text, "render failed: ");
    assert_non_null(fail);
    assert_non_null(strstr(fail, "(attempts exhausted): "));
    assert_non_null(strstr(fail, "shader 'spin': instruction budget of 1000 exceeded"));
    free(text);
    /* both failed tiles: the failure is theirs together */
    assert_true(ft_count(log2, "failed on w1") + ft_count(log2, "failed on worker w1") >= 1);
    assert_true(ft_count(log2, "failed on w2") + ft_count(log2, "failed on worker w2") >= 1);
    assert_int_equal(access(ft_path(sub, "two.exr"), F_OK), -1);
    /* one worker alone: the window, then the failure with its words */
    master = start_master_in(sub, "one", "16", "3", "1000", ep, sizeof ep);
    const char *log1 = ft_path(sub, "one.log");
    pid_t w3 = spawn_worker(sub, ep, "w3");
    double t0 = ft_now();
    assert_int_equal(ft_wait(master, 60), 1);
    double took = ft_now() - t0;
    fprintf(stderr, "one worker alone, --lease 3: the render failed after %.1f s\n", took);
    assert_true(took >= 3.0);
    text = ft_read(log1);
    fail = strstr(text, "render failed: ");
    assert_non_null(fail);
    assert_non_null(strstr(fail, "failed on worker w3 only (attempts exhausted): "));
    assert_non_null(strstr(fail, "shader 'spin': instruction budget of 1000 exceeded"));
    assert_non_null(strstr(fail, "no other worker could try it within 3 s (--lease)"));
    free(text);
    stop_workers((pid_t[]){w1, w2, w3}, 3);
    ft_rmtree(sub);
    free(sub);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_nonretryable_failure_from_one_peer_does_not_end_render,
                                  ft_teardown),
        cmocka_unit_test_teardown(test_hoarders_lose_their_tiles_and_get_no_more, ft_teardown),
        cmocka_unit_test_teardown(test_oversized_frames_are_cut_off, ft_teardown),
        cmocka_unit_test_teardown(test_rogue_alone_then_honest_worker, ft_teardown),
        cmocka_unit_test_teardown(test_liar_alone_then_honest_worker, ft_teardown),
        cmocka_unit_test_teardown(test_result_with_another_tiles_index_refused, ft_teardown),
        cmocka_unit_test_teardown(test_deterministic_failure_agreed_or_alone, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}

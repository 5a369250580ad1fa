/*
 * test_farm_faults.c: the farm under faults, with real processes:
 *   - kill -9 a worker mid-render: its tiles are requeued, the render
 *     completes and equals the standalone render;
 *   - SIGSTOP a worker: after the heartbeat timeout its tiles are
 *     requeued, the result equals standalone; SIGCONT it and it carries
 *     on (says Hello again) and stops cleanly on SIGTERM;
 *   - random bytes, truncated ZMTP frames and malformed messages sent to
 *     the master's port while it renders: it keeps working, counts them,
 *     and answers a message from an unknown peer with Reject HELLO_FIRST;
 *   - a worker named with bytes that are not UTF-8: --stats-json stays
 *     valid (U+FFFD for each bad byte);
 *   - a worker whose job preparation takes longer than the heartbeat
 *     timeout (--prepare-delay) keeps heartbeating: never declared dead,
 *     nothing requeued, it renders its tiles; SIGTERM during a long
 *     preparation ends it at once (exit 130, Shutdown sent);
 *   - SIGINT to a master with local workers: exit 130, no output and no
 *     temporary file left, the local workers stopped.
 * Workers are slowed down with --tile-delay so that "mid-render" is
 * certain; liveness is measured in seconds, never speed.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
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

static pid_t start_worker(const char *endpoint, const char *name, const char *delay_ms)
{
    char log[64];
    snprintf(log, sizeof log, "%s.log", name);
    const char *argv[] = {ft_worker, "--connect", endpoint, "--name", name, "--threads", "1",
                          "--tile-delay", delay_ms, NULL};
    return ft_spawn(ft_path(dir, log), argv);
}

/* A master on tcp://127.0.0.1:<any> with a 1 s heartbeat timeout. */
static pid_t start_master(const char *out, const char *log, const char *json, char *ep,
                          size_t epsz)
{
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", out, "--bind",
                          "tcp://127.0.0.1:*", "--tile", "8", "--heartbeat", "250",
                          "--liveness", "4", "--stats-json", json, "-v", NULL};
    pid_t master = ft_spawn(log, argv);
    assert_true(ft_master_endpoint(log, ep, epsz, 30));
    return master;
}

static void test_farm_kill9_worker_mid_render(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "kill9.log"), *json = ft_path(dir, "kill9.json");
    char ep[256];
    pid_t master = start_master(ft_path(dir, "kill9.exr"), log, json, ep, sizeof ep);
    pid_t victim = start_worker(ep, "victim", "40");
    assert_true(ft_wait_for(log, " from victim (lease", 2, 60));
    pid_t other = start_worker(ep, "other", "20");
    assert_true(ft_wait_for(log, "worker other joined", 1, 30));
    /* the victim holds leases now (it asks for two per thread) */
    kill(victim, SIGKILL);
    assert_int_equal(ft_wait(victim, 10), 128 + SIGKILL);
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "kill9.exr")), 0);
    /* noticed by the missing heartbeats or by the closed connection */
    assert_int_equal(ft_count(log, "worker victim missed 4 heartbeats") +
                     ft_count(log, "worker victim disconnected"), 1);
    assert_true(ft_json_number(json, "requeued") >= 1);
    assert_true(ft_count(json, "\"tiles_done\": 48") == 1);
    kill(other, SIGTERM);
    assert_int_equal(ft_wait(other, 20), 130);
}

static void test_farm_sigstop_worker_requeued(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "stop.log"), *json = ft_path(dir, "stop.json");
    char ep[256];
    pid_t master = start_master(ft_path(dir, "stop.exr"), log, json, ep, sizeof ep);
    pid_t sleeper = start_worker(ep, "sleeper", "40");
    assert_true(ft_wait_for(log, " from sleeper (lease", 2, 60));
    kill(sleeper, SIGSTOP);
    pid_t other = start_worker(ep, "other", "60");
    /* 4 x 250 ms of silence: the master gives the sleeper's tiles away */
    assert_true(ft_wait_for(log, "worker sleeper missed 4 heartbeats", 1, 30));
    /* wake it while the render goes on: the master has forgotten it. It
     * either finds the master silent too long and reconnects, or its next
     * message gets Reject HELLO_FIRST; either way it says Hello again and
     * joins as a new worker, and its old results are stale */
    kill(sleeper, SIGCONT);
    assert_true(ft_wait_for(log, "worker sleeper joined", 2, 30));
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "stop.exr")), 0);
    assert_true(ft_json_number(json, "requeued") >= 1);
    assert_int_equal(ft_count(ft_path(dir, "sleeper.log"), "connected to master"), 2);
    /* and it is still a healthy worker */
    assert_true(ft_running(sleeper));
    kill(sleeper, SIGTERM);
    assert_int_equal(ft_wait(sleeper, 20), 130);
    kill(other, SIGTERM);
    assert_int_equal(ft_wait(other, 20), 130);
}

/* A worker may call itself anything: --stats-json stays valid UTF-8 JSON */
static void test_farm_raw_byte_worker_name(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "raw.log"), *json = ft_path(dir, "raw.json");
    char ep[256];
    pid_t master = start_master(ft_path(dir, "raw.exr"), log, json, ep, sizeof ep);
    pid_t worker = start_worker(ep, "w\xff\xc0\xe2\x82\xac\\q\xed\xa0\x80", "0");
    assert_int_equal(ft_wait(master, 120), 0);
    char *text = ft_read(json);
    /* invalid bytes as U+FFFD, the euro sign kept, the backslash escaped */
    assert_non_null(strstr(text, "\"name\": \"w\\ufffd\\ufffd\xe2\x82\xac\\\\q\\ufffd\\ufffd\\ufffd\""));
    for (const unsigned char *p = (const unsigned char *)text; *p; p++)
        assert_true(*p != 0xff && *p != 0xc0 && *p != 0xed);
    free(text);
    kill(worker, SIGTERM);
    assert_int_equal(ft_wait(worker, 20), 130);
}

static void test_farm_slow_preparation_keeps_heartbeating(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "prep.log"), *json = ft_path(dir, "prep.json");
    char ep[256];
    pid_t master = start_master(ft_path(dir, "prep.exr"), log, json, ep, sizeof ep);
    /* 2.5 s of preparation against a 4 x 250 ms heartbeat timeout */
    const char *argv[] = {ft_worker, "--connect", ep, "--name", "slowprep", "--threads", "1",
                          "--prepare-delay", "2500", NULL};
    pid_t worker = ft_spawn(ft_path(dir, "slowprep.log"), argv);
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "prep.exr")), 0);
    assert_int_equal(ft_count(log, "missed 4 heartbeats"), 0);
    assert_int_equal(ft_count(log, "worker slowprep joined"), 1);
    assert_int_equal(ft_json_number(json, "requeued"), 0);
    assert_true(ft_count(log, " from slowprep (lease") >= 1);
    kill(worker, SIGTERM);
    assert_int_equal(ft_wait(worker, 20), 130);
}

/* SIGTERM while the worker prepares: it says Shutdown and exits 130 at
 * once (not after the preparation); the master requeues its tiles */
static void test_farm_sigterm_during_preparation(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "prepint.log"), *json = ft_path(dir, "prepint.json");
    char ep[256];
    pid_t master = start_master(ft_path(dir, "prepint.exr"), log, json, ep, sizeof ep);
    const char *argv[] = {ft_worker, "--connect", ep, "--name", "quitter", "--threads", "1",
                          "--prepare-delay", "60000", NULL};
    pid_t quitter = ft_spawn(ft_path(dir, "quitter.log"), argv);
    assert_true(ft_wait_for(log, "granted tile ", 1, 30));
    assert_true(ft_wait_for(log, "sent the job ", 1, 30));
    kill(quitter, SIGTERM);
    assert_int_equal(ft_wait(quitter, 10), 130);   /* not 60 s */
    assert_true(ft_wait_for(log, "worker quitter left (the worker was stopped", 1, 10));
    pid_t other = start_worker(ep, "finisher", "0");
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "prepint.exr")), 0);
    kill(other, SIGTERM);
    assert_int_equal(ft_wait(other, 20), 130);
}

/* --max-workers 1: the second worker is refused (exit 2, the reason
 * printed), the first renders everything */
static void test_farm_max_workers(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "max.log"), *json = ft_path(dir, "max.json");
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", ft_path(dir, "max.exr"),
                          "--bind", "tcp://127.0.0.1:*", "--tile", "8", "--max-workers", "1",
                          "--stats-json", json, "-v", NULL};
    pid_t master = ft_spawn(log, argv);
    char ep[256];
    assert_true(ft_master_endpoint(log, ep, sizeof ep, 30));
    pid_t first = start_worker(ep, "first", "20");
    assert_true(ft_wait_for(log, "worker first joined", 1, 30));
    pid_t second = start_worker(ep, "second", "0");
    assert_int_equal(ft_wait(second, 30), 2);
    assert_int_equal(ft_count(ft_path(dir, "second.log"),
                              "refused this worker: the master serves at most 1 workers"), 1);
    assert_int_equal(ft_count(log, "refused worker second"), 1);
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "max.exr")), 0);
    kill(first, SIGTERM);
    assert_int_equal(ft_wait(first, 20), 130);
}

/* ---- garbage for the master's port ---- */

static int tcp_connect(int port)
{
    int s = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_true(s >= 0);
    assert_int_equal(connect(s, (struct sockaddr *)&a, sizeof a), 0);
    return s;
}

static void send_all(int s, const void *buf, size_t len)
{
    (void)!send(s, buf, len, MSG_NOSIGNAL);   /* the peer may hang up: fine */
}

/* The ZMTP 3.0 greeting and READY command of a DEALER (RFC 23). */
static void zmtp_handshake(int s)
{
    unsigned char g[64] = {0xFF, 0, 0, 0, 0, 0, 0, 0, 1, 0x7F, 3, 0, 'N', 'U', 'L', 'L'};
    send_all(s, g, sizeof g);
    unsigned char ready[] = {0x04, 28, 5, 'R', 'E', 'A', 'D', 'Y', 11, 'S', 'o', 'c', 'k', 'e',
                             't', '-', 'T', 'y', 'p', 'e', 0, 0, 0, 6, 'D', 'E', 'A', 'L',
                             'E', 'R'};
    send_all(s, ready, sizeof ready);
}

static void tcp_garbage(int port)
{
    srand(7);
    for (int i = 0; i < 20; i++) {          /* random bytes instead of a greeting */
        int s = tcp_connect(port);
        unsigned char junk[300];
        for (size_t k = 0; k < sizeof junk; k++) junk[k] = (unsigned char)rand();
        send_all(s, junk, (size_t)(1 + rand() % (int)sizeof junk));
        close(s);
    }
    for (int i = 0; i < 10; i++) {          /* a frame cut short, then hang up */
        int s = tcp_connect(port);
        zmtp_handshake(s);
        unsigned char frame[2 + 20] = {0x00, 200};
        send_all(s, frame, sizeof frame);
        close(s);
    }
    int s = tcp_connect(port);              /* a frame claiming 2^60 bytes */
    zmtp_handshake(s);
    unsigned char huge[9] = {0x02, 0x10, 0, 0, 0, 0, 0, 0, 0};
    send_all(s, huge, sizeof huge);
    close(s);
}

/* Malformed messages through a real DEALER, then one from a peer that
 * never said Hello: it must get Reject HELLO_FIRST. Returns how many
 * malformed messages were sent. */
static int dealer_garbage(const char *ep)
{
    void *ctx = zmq_ctx_new();
    void *d = zmq_socket(ctx, ZMQ_DEALER);
    int linger = 0, timeout = 20000;
    zmq_setsockopt(d, ZMQ_LINGER, &linger, sizeof linger);
    zmq_setsockopt(d, ZMQ_RCVTIMEO, &timeout, sizeof timeout);
    assert_int_equal(zmq_connect(d, ep), 0);
    int sent = 0;
    for (int i = 0; i < 300; i++) {         /* headers that cannot be protobuf */
        unsigned char junk[40];
        for (size_t k = 0; k < sizeof junk; k++) junk[k] = (unsigned char)rand();
        junk[0] = 0x07;                     /* field 0 with wire type 7: invalid */
        zmq_send(d, junk, (size_t)(1 + rand() % 40), 0);
        sent++;
    }
    for (int i = 0; i < 20; i++) {          /* four frames: never a message */
        zmq_send(d, "a", 1, ZMQ_SNDMORE);
        zmq_send(d, "b", 1, ZMQ_SNDMORE);
        zmq_send(d, "c", 1, ZMQ_SNDMORE);
        zmq_send(d, "d", 1, 0);
        sent++;
    }
    Aafarm__Heartbeat hb = AAFARM__HEARTBEAT__INIT;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_HEARTBEAT;
    env.heartbeat = &hb;
    assert_int_equal(wire_send_envelope(d, NULL, NULL, 0, &env, NULL, 0, NULL, 0), 0);
    wire_msg *m = wire_recv(d, NULL, NULL, 0, NULL, 0);
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), PROTO_REJECT);
    assert_int_equal(wire_msg_envelope(m)->reject->code,
                     AAFARM__REJECT_CODE__REJECT_CODE_HELLO_FIRST);
    wire_msg_destroy(&m);
    zmq_close(d);
    zmq_ctx_term(ctx);
    return sent;
}

static void test_farm_garbage_to_master_port(void **state)
{
    (void)state;
    const char *log = ft_path(dir, "junk.log"), *json = ft_path(dir, "junk.json");
    char ep[256];
    pid_t master = start_master(ft_path(dir, "junk.exr"), log, json, ep, sizeof ep);
    pid_t worker = start_worker(ep, "steady", "20");
    assert_true(ft_wait_for(log, " from steady (lease", 1, 60));
    int port = atoi(strrchr(ep, ':') + 1);
    tcp_garbage(port);
    int sent = dealer_garbage(ep);
    assert_int_equal(ft_wait(master, 120), 0);
    assert_int_equal(ft_exr_diff(ft_path(dir, "ref.exr"), ft_path(dir, "junk.exr")), 0);
    assert_true(ft_count(log, "dropped a message from peer") >= 1);
    /* every malformed message was counted */
    assert_true(ft_json_number(json, "malformed_messages") >= sent);
    /* the worker was never disturbed */
    assert_int_equal(ft_count(log, "worker steady joined"), 1);
    kill(worker, SIGTERM);
    assert_int_equal(ft_wait(worker, 20), 130);
}

/* ---- SIGINT ---- */

static void test_farm_sigint_master_cleans_up(void **state)
{
    (void)state;
    /* local workers slowed down through a wrapper the master starts */
    const char *wrapper = ft_slow_worker(dir, 100);
    const char *log = ft_path(dir, "int.log"), *out = ft_path(dir, "int.exr");
    setenv("TMPDIR", dir, 1);
    const char *argv[] = {ft_master, ft_path(dir, "scene.rib"), "-o", out, "--tile", "8",
                          "--local-workers", "2", "--worker-binary", wrapper, "-v", NULL};
    pid_t master = ft_spawn(log, argv);
    unsetenv("TMPDIR");
    assert_true(ft_wait_for(log, "took tile ", 2, 60));
    assert_int_equal(ft_count_files(dir, "int.exr.tmp"), 1);   /* being written */
    kill(master, SIGINT);
    assert_int_equal(ft_wait(master, 30), 130);
    assert_int_equal(ft_count(log, "interrupted; "), 1);
    assert_int_equal(access(out, F_OK), -1);
    assert_int_equal(ft_count_files(dir, "int.exr.tmp"), 0);
    assert_int_equal(ft_count_files(dir, "aafarm-"), 0);
    /* both local workers were stopped and reaped by the master */
    char *text = ft_read(log);
    int n = 0;
    for (const char *p = text; (p = strstr(p, ", pid ")); p++, n++) {
        pid_t pid = (pid_t)atoi(p + 6);
        errno = 0;
        assert_int_equal(kill(pid, 0), -1);
        assert_int_equal(errno, ESRCH);
    }
    free(text);
    assert_int_equal(n, 2);
}

int main(int argc, char **argv)
{
    if (!ft_init(argc, argv)) return 2;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_farm_kill9_worker_mid_render, ft_teardown),
        cmocka_unit_test_teardown(test_farm_sigstop_worker_requeued, ft_teardown),
        cmocka_unit_test_teardown(test_farm_garbage_to_master_port, ft_teardown),
        cmocka_unit_test_teardown(test_farm_slow_preparation_keeps_heartbeating, ft_teardown),
        cmocka_unit_test_teardown(test_farm_raw_byte_worker_name, ft_teardown),
        cmocka_unit_test_teardown(test_farm_sigterm_during_preparation, ft_teardown),
        cmocka_unit_test_teardown(test_farm_max_workers, ft_teardown),
        cmocka_unit_test_teardown(test_farm_sigint_master_cleans_up, ft_teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, ft_group_teardown);
}

/*
 * tests/proto/test_proto_wire.c: well-formed messages over real ZeroMQ
 * sockets (proto/wire.c), master ROUTER <-> worker DEALER, over inproc://
 * and tcp://127.0.0.1 on an ephemeral port.
 *
 *   roundtrip     every message kind in its direction arrives with every
 *                 field intact (re-packed bytes equal the sent bytes, and
 *                 chosen fields compared by value), a Result with its bulk
 *                 frame byte for byte, the ROUTER sees the worker's routing id
 *   both ways     Heartbeat and Shutdown travel in both directions
 *   send errors   wrong direction, invalid fields, a missing routing id, a
 *                 bulk frame on a kind without one, an unknown worker
 *                 (EHOSTUNREACH): refused with errno and words, nothing sent
 *   setup         wire_socket_setup sets ZMQ_MAXMSGSIZE from the limits
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <zmq.h>

#include "samples.h"
#include "wire_pb.h"

/* ---------------------------------------------------------------------- */
/* helpers                                                                 */
/* ---------------------------------------------------------------------- */

/* Fields compared by value, beyond the byte comparison. */
static void assert_fields(const sample *s, const Aafarm__Envelope *got)
{
    switch (s->env.body_case) {
    case PROTO_HELLO:
        assert_string_equal(got->hello->worker_name, "render07-w1");
        assert_int_equal(got->hello->threads, 8);
        assert_int_equal(got->hello->n_jobs_held, 2);
        assert_string_equal(got->hello->jobs_held[0], s->job_hash);
        break;
    case PROTO_JOB:
        assert_string_equal(got->job->job_hash, s->job_hash);
        assert_int_equal(got->job->n_sources, 2);
        assert_memory_equal(got->job->sources[0]->text.data, s->source[0].text.data,
                            s->source[0].text.len);
        assert_int_equal(got->job->n_shaders, 2);
        assert_string_equal(got->job->shaders[1]->source, "plastic.sl");
        assert_int_equal(got->job->options->arithmetic, AAFARM__ARITHMETIC__ARITHMETIC_INTERVAL);
        assert_string_equal(got->job->options->extra[0]->key, "seed");
        break;
    case PROTO_GRANT:
        assert_int_equal(got->grant->lease_id, 0x100000001ull);
        assert_int_equal(got->grant->tile->x, 48);
        assert_int_equal(got->grant->tile->height, 16);
        break;
    case PROTO_RESULT:
        assert_int_equal(got->result->stats->boxes, 174);
        assert_true(got->result->stats->cpu_seconds == 1.25);
        assert_int_equal(got->result->exr_bytes, s->bulk_len);
        break;
    case PROTO_HEARTBEAT:
        assert_int_equal(got->heartbeat->n_leases, 3);
        assert_int_equal(got->heartbeat->leases[2], 0xffffffffffffffffull);
        break;
    case PROTO_FAILURE:
        assert_string_equal(got->failure->message, s->failure.message);
        assert_true(got->failure->retryable);
        break;
    default:
        break;
    }
}

/* The received message equals the sample: same kind, same bytes when
 * packed again, chosen fields by value, the same bulk. */
static void assert_same(const sample *s, const wire_msg *m)
{
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), s->env.body_case);
    size_t want_len, got_len;
    uint8_t *want = sample_pack(&s->env, &want_len);
    uint8_t *got = sample_pack(wire_msg_envelope(m), &got_len);
    assert_int_equal(got_len, want_len);
    assert_memory_equal(got, want, want_len);
    free(want);
    free(got);
    assert_fields(s, wire_msg_envelope(m));

    size_t bulk_len;
    const uint8_t *bulk = wire_msg_bulk(m, &bulk_len);
    assert_int_equal(bulk_len, s->bulk_len);
    if (s->bulk_len)
        assert_memory_equal(bulk, s->bulk, s->bulk_len);
    else
        assert_null(bulk);
}

/* The worker says Hello; returns the routing id the master saw. */
static size_t hello(sock_pair *p, wire_stats *st, uint8_t id[256])
{
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_HELLO);
    assert_int_equal(wire_send_envelope(p->dealer, NULL, NULL, 0, &s->env, NULL, 0, wire_err, sizeof wire_err), 0);
    wire_msg *m = wire_recv(p->router, NULL, st, 0, wire_err, sizeof wire_err);
    assert_same(s, m);
    size_t len;
    const uint8_t *who = wire_msg_identity(m, &len);
    assert_non_null(who);
    assert_in_range(len, 1, 255);
    memcpy(id, who, len);
    wire_msg_destroy(&m);
    assert_null(m);
    free(s);
    return len;
}

static void roundtrip_all(const char *transport)
{
    sock_pair p;
    wire_stats to_master = {0}, to_worker = {0};
    pair_open(&p, transport, NULL);
    uint8_t id[256];
    size_t id_len = hello(&p, &to_master, id);
    sample *s = malloc(sizeof *s);
    size_t sent_up = 1, sent_down = 0;

    for (size_t k = 0; k < SAMPLE_KINDS; k++) {
        sample_make(s, sample_kinds[k]);
        if (proto_message_from_worker(sample_kinds[k])) {
            assert_int_equal(wire_send_envelope(p.dealer, NULL, NULL, 0, &s->env, sample_bulk(s), s->bulk_len, wire_err, sizeof wire_err), 0);
            wire_msg *m = wire_recv(p.router, NULL, &to_master, 0, wire_err, sizeof wire_err);
            assert_same(s, m);
            size_t len;
            const uint8_t *who = wire_msg_identity(m, &len);
            assert_int_equal(len, id_len);
            assert_memory_equal(who, id, id_len);
            wire_msg_destroy(&m);
            sent_up++;
        }
        if (proto_message_from_master(sample_kinds[k])) {
            assert_int_equal(wire_send_envelope(p.router, NULL, id, id_len, &s->env, sample_bulk(s), s->bulk_len, wire_err, sizeof wire_err),
                             0);
            wire_msg *m = wire_recv(p.dealer, NULL, &to_worker, 0, wire_err, sizeof wire_err);
            assert_same(s, m);
            assert_null(wire_msg_identity(m, NULL));
            wire_msg_destroy(&m);
            sent_down++;
        }
    }
    /* Hello + 9 kinds up (Heartbeat, Shutdown both ways), 8 down */
    assert_int_equal(sent_up, 10);
    assert_int_equal(sent_down, 8);
    assert_int_equal(to_master.received, sent_up);
    assert_int_equal(to_worker.received, sent_down);
    assert_int_equal(to_master.dropped + to_worker.dropped, 0);
    free(s);
    pair_close(&p);
}

/* ---------------------------------------------------------------------- */
/* tests                                                                   */
/* ---------------------------------------------------------------------- */

static void test_roundtrip_inproc(void **state)
{
    (void)state;
    roundtrip_all("inproc");
}

static void test_roundtrip_tcp(void **state)
{
    (void)state;
    roundtrip_all("tcp");
}

/* A bulk frame near the default limit travels intact over tcp. */
static void test_large_bulk_tcp(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "tcp", NULL);
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_RESULT);
    size_t n = proto_limits_default().max_bulk_bytes;
    uint8_t *big = malloc(n);
    assert_non_null(big);
    for (size_t i = 0; i < n; i++)
        big[i] = (uint8_t)(i * 2654435761u >> 24);
    s->result.exr_bytes = n;
    assert_int_equal(wire_send_envelope(p.dealer, NULL, NULL, 0, &s->env, big, n, wire_err, sizeof wire_err), 0);
    wire_msg *m = wire_recv(p.router, NULL, &st, 0, wire_err, sizeof wire_err);
    assert_non_null(m);
    size_t len;
    const uint8_t *got = wire_msg_bulk(m, &len);
    assert_int_equal(len, n);
    assert_memory_equal(got, big, n);
    wire_msg_destroy(&m);
    free(big);
    free(s);
    pair_close(&p);
}

static void expect_send_error(void *socket, const void *id, size_t id_len, const sample *s,
                              const void *bulk, size_t bulk_len, int err, const char *words)
{
    errno = 0;
    assert_int_equal(wire_send_envelope(socket, NULL, id, id_len, &s->env, bulk, bulk_len, wire_err, sizeof wire_err), -1);
    assert_int_equal(errno, err);
    if (words)
        assert_non_null(strstr(wire_err, words));
}

static void test_send_refusals(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "inproc", NULL);
    uint8_t id[256];
    size_t id_len = hello(&p, &st, id);
    sample *s = malloc(sizeof *s);

    sample_make(s, PROTO_GRANT); /* a master's message */
    expect_send_error(p.dealer, NULL, 0, s, NULL, 0, EPROTO,
                      "wire_send: Grant is not a message the worker sends");
    expect_send_error(p.router, NULL, 0, s, NULL, 0, EINVAL, "routing id");
    uint8_t nobody[5] = {0, 1, 2, 3, 4};
    expect_send_error(p.router, nobody, sizeof nobody, s, NULL, 0, EHOSTUNREACH, NULL);
    s->rect.width = 0;
    expect_send_error(p.router, id, id_len, s, NULL, 0, EPROTO,
                      "Grant.tile.width: 0 is outside 1..8192");

    sample_make(s, PROTO_ASK);
    expect_send_error(p.router, id, id_len, s, NULL, 0, EPROTO,
                      "Ask is not a message the master sends");
    expect_send_error(p.dealer, id, id_len, s, NULL, 0, EINVAL, "DEALER sends no routing id");
    expect_send_error(p.dealer, NULL, 0, s, "x", 1, EPROTO, "only Result has one");

    sample_make(s, PROTO_RESULT);
    expect_send_error(p.dealer, NULL, 0, s, NULL, 0, EPROTO, "bulk frame");
    expect_send_error(p.dealer, NULL, 0, s, s->bulk, s->bulk_len - 1, EPROTO,
                      "Result.exr_bytes: says 3000 but the bulk frame has 2999 bytes");

    /* nothing of the above reached either side */
    wire_msg *m = wire_recv(p.router, NULL, &st, ZMQ_DONTWAIT, wire_err, sizeof wire_err);
    assert_null(m);
    assert_int_equal(errno, EAGAIN);
    m = wire_recv(p.dealer, NULL, &st, ZMQ_DONTWAIT, wire_err, sizeof wire_err);
    assert_null(m);
    assert_int_equal(errno, EAGAIN);
    assert_int_equal(st.dropped, 0);
    free(s);
    pair_close(&p);
}

static void test_socket_setup(void **state)
{
    (void)state;
    void *ctx = zmq_ctx_new();
    void *router = zmq_socket(ctx, ZMQ_ROUTER);
    void *pub = zmq_socket(ctx, ZMQ_PUB);
    proto_limits l = proto_limits_default();
    l.max_header_bytes = 1000;
    l.max_bulk_bytes = 5000;
    assert_int_equal(wire_socket_setup(router, &l, wire_err, sizeof wire_err), 0);
    int64_t maxmsg = 0;
    size_t size = sizeof maxmsg;
    assert_int_equal(zmq_getsockopt(router, ZMQ_MAXMSGSIZE, &maxmsg, &size), 0);
    assert_int_equal(maxmsg, 5000);
    l.max_header_bytes = 9000;
    assert_int_equal(wire_socket_setup(router, &l, wire_err, sizeof wire_err), 0);
    assert_int_equal(zmq_getsockopt(router, ZMQ_MAXMSGSIZE, &maxmsg, &size), 0);
    assert_int_equal(maxmsg, 9000);

    /* wire_recv/wire_send refuse sockets that are neither ROUTER nor DEALER */
    errno = 0;
    assert_null(wire_recv(pub, NULL, NULL, ZMQ_DONTWAIT, wire_err, sizeof wire_err));
    assert_int_equal(errno, ENOTSUP);
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_SHUTDOWN);
    assert_int_equal(wire_send_envelope(pub, NULL, NULL, 0, &s->env, NULL, 0, wire_err, sizeof wire_err), -1);
    assert_int_equal(errno, EINVAL);
    free(s);
    zmq_close(pub);
    zmq_close(router);
    zmq_ctx_term(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roundtrip_inproc),
        cmocka_unit_test(test_roundtrip_tcp),
        cmocka_unit_test(test_large_bulk_tcp),
        cmocka_unit_test(test_send_refusals),
        cmocka_unit_test(test_socket_setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

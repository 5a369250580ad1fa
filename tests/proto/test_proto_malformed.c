/*
 * tests/proto/test_proto_malformed.c: what a broken or hostile peer can
 * send, over real sockets, and that each is counted, explained, dropped,
 * and that the socket then still delivers a good message intact.
 *
 *   random bytes      seeded random frames and bit-flipped valid headers
 *   truncated         every proper prefix of a packed Job
 *   frame counts      empty header, 3 frames from a worker, 4 at the master
 *                     side, a bulk frame after a kind without one, a Result
 *                     without its bulk frame
 *   oversized         header and bulk over the limits (inproc: our checks);
 *                     over ZMQ_MAXMSGSIZE on tcp, where ZeroMQ cuts the
 *                     peer off and the monitor counts the disconnect
 *   expansion         a small header that would unpack into a huge tree
 *   wrong side        a Grant sent by a worker, a Hello sent by the master
 *   inconsistent job  a Job binding a shader to a source it lacks
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
#include "test_rng.h"

/* ---------------------------------------------------------------------- */
/* helpers                                                                 */
/* ---------------------------------------------------------------------- */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

static uint64_t rng(void)
{
    return test_rng_next(&rng_state);
}

/* Sends frames[0..n) as one message with plain zmq_send (no checks). */
static void send_raw(void *socket, const void *const *frames, const size_t *lens, size_t n)
{
    for (size_t i = 0; i < n; i++)
        assert_true(zmq_send(socket, frames[i], lens[i], i + 1 < n ? ZMQ_SNDMORE : 0) >= 0);
}

static void send_raw1(void *socket, const void *data, size_t len)
{
    const void *frames[1] = {data};
    send_raw(socket, frames, &len, 1);
}

/* Receives on socket and expects one dropped message whose explanation
 * contains words; the counter *which must have grown by one. */
static void expect_drop(void *socket, const proto_limits *l, wire_stats *st,
                        const uint64_t *which, const char *words)
{
    uint64_t before = *which, dropped = st->dropped;
    errno = 0;
    wire_msg *m = wire_recv(socket, l, st, 0, wire_err, sizeof wire_err);
    assert_null(m);
    assert_int_equal(errno, EPROTO);
    assert_int_equal(*which, before + 1);
    assert_int_equal(st->dropped, dropped + 1);
    if (words && !strstr(st->last_error, words))
        fail_msg("error \"%s\" lacks \"%s\"", st->last_error, words);
    assert_string_equal(wire_err, st->last_error);
}

/* A good message of the kind from the worker arrives intact afterwards. */
static void expect_good_up(sock_pair *p, const proto_limits *l, wire_stats *st, proto_kind kind)
{
    sample *s = malloc(sizeof *s);
    sample_make(s, kind);
    uint64_t received = st->received;
    /* the sends are ZMQ_DONTWAIT, and the dealer learns that the router
     * read the frames before (2000 random ones fill the inproc pipe's two
     * default high-water marks) from commands it handles later: wait until
     * its pipe takes one more (about 1 run in 60 failed with EAGAIN) */
    zmq_pollitem_t out = {p->dealer, 0, ZMQ_POLLOUT, 0};
    assert_int_equal(zmq_poll(&out, 1, 5000), 1);
    assert_int_equal(wire_send_envelope(p->dealer, NULL, NULL, 0, &s->env, sample_bulk(s), s->bulk_len, wire_err, sizeof wire_err), 0);
    wire_msg *m = wire_recv(p->router, l, st, 0, wire_err, sizeof wire_err);
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), kind);
    size_t want_len, got_len;
    uint8_t *want = sample_pack(&s->env, &want_len);
    uint8_t *got = sample_pack(wire_msg_envelope(m), &got_len);
    assert_int_equal(got_len, want_len);
    assert_memory_equal(got, want, want_len);
    size_t bulk_len;
    const uint8_t *bulk = wire_msg_bulk(m, &bulk_len);
    assert_int_equal(bulk_len, s->bulk_len);
    if (bulk_len)
        assert_memory_equal(bulk, s->bulk, bulk_len);
    assert_int_equal(st->received, received + 1);
    free(want);
    free(got);
    wire_msg_destroy(&m);
    free(s);
}

/* The master learns the worker's routing id from a Hello. */
static size_t routing_id(sock_pair *p, wire_stats *st, uint8_t id[256])
{
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_HELLO);
    assert_int_equal(wire_send_envelope(p->dealer, NULL, NULL, 0, &s->env, NULL, 0, wire_err, sizeof wire_err), 0);
    wire_msg *m = wire_recv(p->router, NULL, st, 0, wire_err, sizeof wire_err);
    assert_non_null(m);
    size_t len;
    memcpy(id, wire_msg_identity(m, &len), 255);
    wire_msg_destroy(&m);
    free(s);
    return len;
}

/* A good Grant from the master arrives intact at the worker. */
static void expect_good_down(sock_pair *p, const uint8_t *id, size_t id_len, wire_stats *st)
{
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_GRANT);
    assert_int_equal(wire_send_envelope(p->router, NULL, id, id_len, &s->env, NULL, 0, wire_err, sizeof wire_err), 0);
    wire_msg *m = wire_recv(p->dealer, NULL, st, 0, wire_err, sizeof wire_err);
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), PROTO_GRANT);
    assert_int_equal(wire_msg_envelope(m)->grant->lease_id, s->grant.lease_id);
    assert_int_equal(wire_msg_envelope(m)->grant->tile->x, 48);
    wire_msg_destroy(&m);
    free(s);
}

/* ---------------------------------------------------------------------- */
/* tests                                                                   */
/* ---------------------------------------------------------------------- */

static void test_random_bytes(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "inproc", NULL);
    enum { N = 2000 };
    uint8_t buf[512];
    for (int i = 0; i < N; i++) {
        size_t len = 1 + rng() % sizeof buf;
        for (size_t j = 0; j < len; j++)
            buf[j] = (uint8_t)rng();
        send_raw1(p.dealer, buf, len);
        wire_msg *m = wire_recv(p.router, NULL, &st, 0, wire_err, sizeof wire_err);
        /* a random frame is (almost) never a well-formed message */
        if (m)
            wire_msg_destroy(&m);
        else
            assert_int_equal(errno, EPROTO);
    }
    print_message("%d random frames: %llu dropped (%llu undecodable, %llu invalid, "
                  "%llu bad frames), %llu well formed\n", N, (unsigned long long)st.dropped,
                  (unsigned long long)st.undecodable, (unsigned long long)st.invalid,
                  (unsigned long long)st.bad_frames, (unsigned long long)st.received);
    assert_int_equal(st.received + st.dropped, N);
    assert_true(st.dropped >= N - N / 100);
    assert_int_equal(st.dropped, st.bad_frames + st.oversized + st.undecodable + st.invalid);
    assert_true(st.undecodable >= N / 2);
    expect_good_up(&p, NULL, &st, PROTO_RESULT);
    pair_close(&p);
}

/* Valid headers of every worker kind with a few bits flipped: each is
 * either dropped or, if it still decodes, passes every check. */
static void test_flipped_bits(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "inproc", NULL);
    sample *s = malloc(sizeof *s);
    size_t sent = 0;
    for (size_t k = 0; k < SAMPLE_KINDS; k++) {
        sample_make(s, sample_kinds[k]);
        if (!proto_message_from_worker(sample_kinds[k]))
            continue;
        size_t len;
        uint8_t *packed = sample_pack(&s->env, &len);
        for (int round = 0; round < 300; round++) {
            uint8_t *copy = malloc(len);
            memcpy(copy, packed, len);
            for (int f = 0; f < 1 + round % 4; f++)
                copy[rng() % len] ^= (uint8_t)(1u << (rng() % 8));
            const void *frames[2] = {copy, s->bulk};
            size_t lens[2] = {len, s->bulk_len};
            send_raw(p.dealer, frames, lens, s->bulk_len ? 2 : 1);
            sent++;
            wire_msg *m = wire_recv(p.router, NULL, &st, 0, wire_err, sizeof wire_err);
            if (m) {
                char why[200];
                size_t bl;
                bool has = wire_msg_bulk(m, &bl) != NULL;
                assert_true(proto_message_check(wire_msg_envelope(m), has, bl, NULL, why,
                                                sizeof why));
                wire_msg_destroy(&m);
            }
            free(copy);
        }
        free(packed);
    }
    print_message("%zu bit-flipped headers: %llu dropped (%llu undecodable, %llu invalid), "
                  "%llu still well formed\n", sent, (unsigned long long)st.dropped,
                  (unsigned long long)st.undecodable, (unsigned long long)st.invalid,
                  (unsigned long long)st.received);
    assert_int_equal(st.received + st.dropped, sent);
    assert_true(st.dropped > 0 && st.received > 0); /* both outcomes occur */
    expect_good_up(&p, NULL, &st, PROTO_HEARTBEAT);
    free(s);
    pair_close(&p);
}

static void test_truncated(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "tcp", NULL);
    uint8_t id[256];
    size_t id_len = routing_id(&p, &st, id);
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_JOB);
    size_t len;
    uint8_t *packed = sample_pack(&s->env, &len);
    assert_true(len > 300);
    for (size_t cut = 1; cut < len; cut++) {
        const void *frames[2] = {id, packed};
        size_t lens[2] = {id_len, cut};
        send_raw(p.router, frames, lens, 2);
        expect_drop(p.dealer, NULL, &st, &st.undecodable, "protobuf decoding failed");
    }
    assert_int_equal(st.undecodable, len - 1);
    expect_good_down(&p, id, id_len, &st);
    free(packed);
    free(s);
    pair_close(&p);
}

static void test_frame_counts(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats up = {0}, down = {0};
    pair_open(&p, "inproc", NULL);
    uint8_t id[256];
    size_t id_len = routing_id(&p, &up, id);
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_HEARTBEAT);
    size_t len;
    uint8_t *hb = sample_pack(&s->env, &len);

    send_raw1(p.dealer, "", 0);
    expect_drop(p.router, NULL, &up, &up.bad_frames, "empty header frame");

    const void *three[3] = {hb, "bulk", "more"};
    size_t three_lens[3] = {len, 4, 4};
    send_raw(p.dealer, three, three_lens, 3);
    expect_drop(p.router, NULL, &up, &up.bad_frames,
                "message of 4 frames; expected 3 at most (routing id, header, bulk)");

    send_raw(p.dealer, three, three_lens, 2); /* Heartbeat + bulk */
    expect_drop(p.router, NULL, &up, &up.invalid,
                "Heartbeat: comes with a bulk frame of 4 bytes; only Result has one");

    sample_make(s, PROTO_RESULT);
    size_t rlen;
    uint8_t *result = sample_pack(&s->env, &rlen);
    send_raw1(p.dealer, result, rlen); /* Result without its bulk */
    expect_drop(p.router, NULL, &up, &up.invalid,
                "Result: the bulk frame with the tile's EXR bytes is missing");

    /* on the worker's side: 3 frames after the routing id */
    const void *four[4] = {id, hb, "a", "b"};
    size_t four_lens[4] = {id_len, len, 1, 1};
    send_raw(p.router, four, four_lens, 4);
    expect_drop(p.dealer, NULL, &down, &down.bad_frames,
                "from the master: message of 3 frames; expected 1 or 2 (header, bulk)");
    assert_int_equal(up.dropped, 4);
    assert_int_equal(down.dropped, 1);

    expect_good_up(&p, NULL, &up, PROTO_RESULT);
    expect_good_down(&p, id, id_len, &down);
    free(result);
    free(hb);
    free(s);
    pair_close(&p);
}

/* Our own size checks (inproc frames never meet ZMQ_MAXMSGSIZE). */
static void test_oversized_inproc(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    proto_limits l = proto_limits_default();
    l.max_header_bytes = 1024;
    l.max_bulk_bytes = 4096;
    pair_open(&p, "inproc", &l);
    uint8_t *big = calloc(1, 10000);

    send_raw1(p.dealer, big, 1025);
    expect_drop(p.router, &l, &st, &st.oversized, "header frame of 1025 bytes, the limit is 1024");

    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_RESULT);
    s->result.exr_bytes = 4097;
    size_t len;
    uint8_t *packed = sample_pack(&s->env, &len);
    const void *frames[2] = {packed, big};
    size_t lens[2] = {len, 4097};
    send_raw(p.dealer, frames, lens, 2);
    expect_drop(p.router, &l, &st, &st.oversized, "bulk frame of 4097 bytes, the limit is 4096");
    assert_int_equal(st.oversized, 2);

    /* the sender refuses the same with its limits */
    errno = 0;
    assert_int_equal(wire_send_envelope(p.dealer, &l, NULL, 0, &s->env, big, 4097, wire_err, sizeof wire_err), -1);
    assert_int_equal(errno, EPROTO);
    assert_non_null(strstr(wire_err, "the limit is 4096"));

    sample_make(s, PROTO_RESULT); /* 3000-byte bulk: fits */
    expect_good_up(&p, &l, &st, PROTO_RESULT);
    free(packed);
    free(s);
    free(big);
    pair_close(&p);
}

/* Over tcp a frame above ZMQ_MAXMSGSIZE never reaches wire_recv: ZeroMQ
 * disconnects the peer. The monitor counts it; the worker's DEALER
 * reconnects by itself and the next good message arrives. */
static void test_oversized_tcp(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    proto_limits l = proto_limits_default();
    l.max_header_bytes = 1024;
    l.max_bulk_bytes = 4096;
    pair_open(&p, "tcp", &l);
    wire_monitor *mon = wire_monitor_new(p.ctx, p.router, wire_err, sizeof wire_err);
    assert_non_null(mon);
    expect_good_up(&p, &l, &st, PROTO_ASK);

    uint8_t *big = calloc(1, 100000);
    send_raw1(p.dealer, big, 100000);
    /* wait for the disconnect to be reported */
    for (int i = 0; i < 100 && st.disconnects == 0; i++) {
        zmq_pollitem_t item = {wire_monitor_socket(mon), 0, ZMQ_POLLIN, 0};
        zmq_poll(&item, 1, 50);
        assert_true(wire_monitor_poll(mon, &st, wire_err, sizeof wire_err) >= 0);
    }
    assert_int_equal(st.disconnects, 1);

    /* the DEALER reconnects; resend until a good message gets through */
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_HEARTBEAT);
    int timeout = 200;
    zmq_setsockopt(p.router, ZMQ_RCVTIMEO, &timeout, sizeof timeout);
    wire_msg *m = NULL;
    for (int i = 0; i < 50 && !m; i++) {
        assert_int_equal(wire_send_envelope(p.dealer, NULL, NULL, 0, &s->env, NULL, 0, wire_err, sizeof wire_err), 0);
        m = wire_recv(p.router, &l, &st, 0, wire_err, sizeof wire_err);
    }
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), PROTO_HEARTBEAT);
    assert_int_equal(wire_msg_envelope(m)->heartbeat->n_leases, 3);
    wire_msg_destroy(&m);
    assert_int_equal(st.dropped, 0); /* ZeroMQ dropped it, not wire_recv */
    /* the reconnection was accepted before the message could arrive */
    for (int i = 0; i < 100 && st.connects == 0; i++) {
        zmq_pollitem_t item = {wire_monitor_socket(mon), 0, ZMQ_POLLIN, 0};
        zmq_poll(&item, 1, 50);
        assert_true(wire_monitor_poll(mon, &st, wire_err, sizeof wire_err) >= 0);
    }
    assert_true(st.connects >= 1);
    assert_int_equal(st.disconnects, 1);
    free(s);
    free(big);
    wire_monitor_destroy(&mon);
    assert_null(mon);
    pair_close(&p);
}

/* 64 KiB of empty Shader entries: each 2 bytes on the wire, each a struct
 * of ~50 bytes unpacked; the budget stops it. */
static void test_expansion(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "inproc", NULL);
    uint8_t id[256];
    size_t id_len = routing_id(&p, &st, id);
    enum { ENTRIES = 32768, BODY = 2 * ENTRIES };
    uint8_t *frame = malloc(BODY + 8);
    size_t n = 0;
    frame[n++] = 0x2a; /* Envelope field 5 (job), length-delimited */
    uint32_t v = BODY;
    do { /* varint length */
        frame[n++] = (uint8_t)((v & 0x7f) | (v > 0x7f ? 0x80 : 0));
        v >>= 7;
    } while (v);
    for (int i = 0; i < ENTRIES; i++) {
        frame[n++] = 0x22; /* Job field 4 (shaders), length 0 */
        frame[n++] = 0x00;
    }
    const void *frames[2] = {id, frame};
    size_t lens[2] = {id_len, n};
    send_raw(p.router, frames, lens, 2);
    expect_drop(p.dealer, NULL, &st, &st.undecodable, "of memory unpacked");
    expect_good_down(&p, id, id_len, &st);
    free(frame);
    pair_close(&p);
}

static void test_wrong_side(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats up = {0}, down = {0};
    pair_open(&p, "inproc", NULL);
    uint8_t id[256];
    size_t id_len = routing_id(&p, &up, id);
    sample *s = malloc(sizeof *s);
    size_t len;

    sample_make(s, PROTO_GRANT);
    uint8_t *grant = sample_pack(&s->env, &len);
    send_raw1(p.dealer, grant, len);
    expect_drop(p.router, NULL, &up, &up.invalid,
                "Grant is a master's message; it cannot arrive at the master");
    free(grant);

    sample_make(s, PROTO_HELLO);
    uint8_t *hello = sample_pack(&s->env, &len);
    const void *frames[2] = {id, hello};
    size_t lens[2] = {id_len, len};
    send_raw(p.router, frames, lens, 2);
    expect_drop(p.dealer, NULL, &down, &down.invalid,
                "Hello is a worker's message; it cannot arrive at the worker");
    free(hello);

    /* an Envelope with no body at all: one unknown field (number 99) */
    const uint8_t unknown[] = {0x98, 0x06, 0x01};
    send_raw1(p.dealer, unknown, sizeof unknown);
    expect_drop(p.router, NULL, &up, &up.invalid, "Envelope: carries no message");

    expect_good_up(&p, NULL, &up, PROTO_FAILURE);
    expect_good_down(&p, id, id_len, &down);
    free(s);
    pair_close(&p);
}

/* A Job that binds a shader to a source it does not carry. */
static void test_inconsistent_job(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "tcp", NULL);
    uint8_t id[256];
    size_t id_len = routing_id(&p, &st, id);
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_JOB);
    s->job.n_sources = 1; /* plastic.sl left out, still bound */
    size_t len;
    uint8_t *job = sample_pack(&s->env, &len);
    const void *frames[2] = {id, job};
    size_t lens[2] = {id_len, len};
    send_raw(p.router, frames, lens, 2);
    expect_drop(p.dealer, NULL, &st, &st.invalid,
                "dropped a message from the master: Job.shaders.source: \"plastic.sl\" "
                "(for shader \"plastic\") is not among Job.sources");
    expect_good_down(&p, id, id_len, &st);
    free(job);
    free(s);
    pair_close(&p);
}

/* The master's explanation names the worker by routing id (hex). */
static void test_peer_named(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats st = {0};
    pair_open(&p, "inproc", NULL);
    /* reconnect the DEALER under a chosen routing id */
    assert_int_equal(zmq_disconnect(p.dealer, p.endpoint), 0);
    assert_int_equal(zmq_setsockopt(p.dealer, ZMQ_ROUTING_ID, "w-1", 3), 0);
    assert_int_equal(zmq_connect(p.dealer, p.endpoint), 0);
    send_raw1(p.dealer, "\xff", 1);
    expect_drop(p.router, NULL, &st, &st.undecodable, "dropped a message from peer 772d31: ");
    pair_close(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_bytes),
        cmocka_unit_test(test_flipped_bits),
        cmocka_unit_test(test_truncated),
        cmocka_unit_test(test_frame_counts),
        cmocka_unit_test(test_oversized_inproc),
        cmocka_unit_test(test_oversized_tcp),
        cmocka_unit_test(test_expansion),
        cmocka_unit_test(test_wrong_side),
        cmocka_unit_test(test_inconsistent_job),
        cmocka_unit_test(test_peer_named),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * tests/fuzz/fuzz_proto.c: fuzz target for the protocol decoder
 * (proto/wire.c wire_recv: frame checks, protobuf-c unpack within a memory
 * budget, proto_message_check and the direction check) on the master's
 * side, where messages from workers arrive. The input's first byte says
 * whether a bulk frame follows (bit 0) and the second its length (0..255
 * bytes of 0x5a); the rest is the header frame. A DEALER sends the frames
 * over inproc, and the master's ROUTER receives them with wire_recv.
 * Checked: the message is either accepted (a kind a worker may send, whose
 * bulk is there exactly when the kind has one) or dropped with EPROTO and
 * a reason; never another outcome (a timeout would mean a lost message).
 */
#include <errno.h>
#include <string.h>
#include <zmq.h>

#include "fuzz_target.h"
#include "message.h"
#include "wire_pb.h"

static char wire_err[ERR_LEN];

static void *ctx, *router, *dealer;

static void setup(void)
{
    int timeout = 2000, linger = 0;
    ctx = zmq_ctx_new();
    fuzz_check(ctx != NULL);
    router = zmq_socket(ctx, ZMQ_ROUTER);
    dealer = zmq_socket(ctx, ZMQ_DEALER);
    fuzz_check(router && dealer);
    fuzz_check(wire_socket_setup(router, NULL, wire_err, sizeof wire_err) == 0);
    fuzz_check(zmq_setsockopt(router, ZMQ_RCVTIMEO, &timeout, sizeof timeout) == 0);
    fuzz_check(zmq_setsockopt(router, ZMQ_LINGER, &linger, sizeof linger) == 0);
    fuzz_check(zmq_setsockopt(dealer, ZMQ_LINGER, &linger, sizeof linger) == 0);
    fuzz_check(zmq_bind(router, "inproc://aafarm-fuzz-proto") == 0);
    fuzz_check(zmq_connect(dealer, "inproc://aafarm-fuzz-proto") == 0);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!ctx)
        setup();
    if (size < 2)
        return 0;
    bool has_bulk = data[0] & 1;
    size_t bulk_len = data[1];
    uint8_t bulk[256];
    memset(bulk, 0x5a, sizeof bulk);
    fuzz_check(zmq_send(dealer, data + 2, size - 2, has_bulk ? ZMQ_SNDMORE : 0) ==
               (int)(size - 2));
    if (has_bulk)
        fuzz_check(zmq_send(dealer, bulk, bulk_len, 0) == (int)bulk_len);

    wire_stats stats;
    memset(&stats, 0, sizeof stats);
    wire_msg *m = wire_recv(router, NULL, &stats, 0, wire_err, sizeof wire_err);
    if (m) {
        proto_kind kind = wire_msg_kind(m);
        fuzz_check(proto_message_from_worker(kind));
        size_t got = 0;
        const uint8_t *b = wire_msg_bulk(m, &got);
        fuzz_check((b != NULL) == proto_message_has_bulk(kind));
        fuzz_check(!b || (has_bulk && got == bulk_len));
        fuzz_check(wire_msg_envelope(m) != NULL);
        wire_msg_destroy(&m);
    } else {
        fuzz_check(errno == EPROTO);
        const char *why = wire_err;
        fuzz_check(why != NULL && why[0] != '\0');
    }
    return 0;
}

/*
 * wire.h: messages of the farm on ZeroMQ sockets, safely.
 *
 * A thin layer over the libzmq C API and the protobuf-c code generated
 * from aafarm.proto. The master binds a ROUTER, each worker connects a
 * DEALER (docs/protocol.md, "Framing"):
 *
 *     worker DEALER sends / receives   [header] [bulk]?
 *     master ROUTER sends / receives   [routing id] [header] [bulk]?
 *
 * header is one packed aafarm.Envelope; bulk follows only a Result (the
 * tile's EXR bytes, never copied into the header). wire_recv() reads every
 * frame of one message, bounds each frame, unpacks the header with a
 * memory budget, runs proto_message_check() and refuses messages from the
 * wrong side (a Grant arriving at the master). Anything malformed is
 * counted in a wire_stats, described in words, and dropped; the caller
 * logs it and carries on. Nothing a peer sends can crash the process or
 * make it allocate without bound.
 *
 * wire_send() checks the outgoing message the same way, so a bug on one
 * side shows up where it is made and not as a dropped message at the other.
 *
 * The master and the worker send and receive proto_msg (message.h); the
 * Envelope they travel in is proto's business (wire_pb.h, internal).
 *
 * Errors: functions that fail return -1 or NULL, set errno, and write
 * the words into err (err_set, util/err.h; err may be NULL).
 */
#ifndef PROTO_WIRE_H
#define PROTO_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "message.h"
#include "util/err.h"

/* Counters of one socket's traffic (zero-initialise; share one per socket). */
typedef struct wire_stats {
    uint64_t received;     /* well-formed messages handed to the caller */
    uint64_t dropped;      /* malformed messages dropped (sum of the next 4) */
    uint64_t bad_frames;   /* wrong frame count, empty header or routing id */
    uint64_t oversized;    /* a frame over max_header_bytes or max_bulk_bytes */
    uint64_t undecodable;  /* not a protobuf Envelope, or over the unpack budget */
    uint64_t invalid;      /* decoded but failed the checks or the direction */
    uint64_t connects;     /* wire_monitor: peers connected or accepted */
    uint64_t disconnects;  /* wire_monitor: peers gone, including those ZeroMQ
                              cut off for a frame over ZMQ_MAXMSGSIZE */
    uint64_t handshake_failures; /* wire_monitor: ZMTP handshakes that failed */
    uint64_t auth_failures;      /* of those: refused by authentication (CURVE
                                    key not allowed, ZAP status 400) */
    char last_handshake[160];    /* the last failure: its kind and endpoint */
    char last_error[ERR_LEN];  /* why the last message was dropped */
} wire_stats;

/* Sets the options aafarm relies on: ZMQ_MAXMSGSIZE to the largest frame
 * the limits allow (ZeroMQ then refuses a bigger frame before allocating it
 * and disconnects the peer), ZMQ_LINGER to 200 ms, and on a ROUTER
 * ZMQ_ROUTER_MANDATORY (sending to an unknown worker fails with
 * EHOSTUNREACH instead of vanishing). Call before bind/connect. limits NULL
 * means proto_limits_default(). Returns 0, or -1 with errno set. */
int wire_socket_setup(void *socket, const proto_limits *limits, char *err, size_t errsz);

/* Sends one message and never blocks. On a ROUTER, identity[0..id_len) is
 * the worker's routing id (1..255 bytes); on a DEALER identity must be NULL.
 * bulk[0..bulk_len) becomes the bulk frame (Result only; NULL otherwise).
 * The message is checked with proto_message_check() and for its direction
 * first. Returns 0, or -1 with errno: EINVAL (bad arguments or socket type),
 * EPROTO (the message fails the checks; err says how), EMSGSIZE
 * (the header exceeds max_header_bytes), or ZeroMQ's (EAGAIN: the peer's
 * queue is full; EHOSTUNREACH: no such worker on this ROUTER). */
int wire_send(void *socket, const void *identity, size_t id_len, const proto_msg *msg,
              const void *bulk, size_t bulk_len, char *err, size_t errsz);

/* wire_send with explicit limits (NULL: the defaults). */
int wire_send_limited(void *socket, const proto_limits *limits, const void *identity,
                      size_t id_len, const proto_msg *msg, const void *bulk,
                      size_t bulk_len, char *err, size_t errsz);

/* One received, checked message. */
typedef struct wire_msg wire_msg;

/* Receives one message from a ROUTER (worker messages) or a DEALER (master
 * messages). flags: 0 waits, ZMQ_DONTWAIT does not. Returns the message,
 * or NULL with errno:
 *   EAGAIN  nothing queued (ZMQ_DONTWAIT), or the socket's ZMQ_RCVTIMEO ran out;
 *   EPROTO  one malformed message was read, counted in stats (when not
 *           NULL) and dropped; stats->last_error and err say why and
 *           from which peer. The socket is fine: call again;
 *   ENOTSUP the socket is neither ROUTER nor DEALER;
 *   otherwise ZeroMQ's error (ETERM, EINTR, ...).
 * limits NULL means proto_limits_default(). */
wire_msg *wire_recv(void *socket, const proto_limits *limits, wire_stats *stats, int flags,
                    char *err, size_t errsz);

/* Frees the message and everything it points to; sets *self_p to NULL. */
void wire_msg_destroy(wire_msg **self_p);

/* The checked message; valid until the wire_msg is destroyed (its strings
 * and arrays point into it). */
const proto_msg *wire_msg_body(const wire_msg *self);

/* The kind of message (the Envelope's oneof case). */
proto_kind wire_msg_kind(const wire_msg *self);

/* The bulk frame (a Result's EXR bytes) and its length, or NULL and 0. */
const uint8_t *wire_msg_bulk(const wire_msg *self, size_t *len);

/* The sender's routing id (ROUTER side), or NULL and 0 (DEALER side). */
const uint8_t *wire_msg_identity(const wire_msg *self, size_t *len);

/* ---- socket monitor: what ZeroMQ does without telling the socket ----
 *
 * ZeroMQ handles a frame over ZMQ_MAXMSGSIZE itself: it never delivers it
 * and disconnects the peer (which reconnects). A wire_monitor watches the
 * socket's connection events so these show up in wire_stats
 * (connects, disconnects, handshake_failures). */
typedef struct wire_monitor wire_monitor;

/* Starts monitoring socket (created in ctx). Returns NULL with errno on
 * failure. Destroy the monitor before closing the socket. */
wire_monitor *wire_monitor_new(void *ctx, void *socket, char *err, size_t errsz);

/* Reads every pending event without waiting and adds it to stats. Returns
 * the number of events read, or -1 with errno. */
int wire_monitor_poll(wire_monitor *self, wire_stats *stats, char *err, size_t errsz);

/* The PAIR socket the events arrive on, to include in a zmq_poll set. */
void *wire_monitor_socket(wire_monitor *self);

/* Stops monitoring, closes the PAIR socket, sets *self_p to NULL. */
void wire_monitor_destroy(wire_monitor **self_p);

#endif

/*
 * wire_pb.h: the wire layer on raw Envelopes, for proto's own tests and
 * fuzzers, which must send what no proto_msg can say (a missing
 * submessage, an unknown kind) and look at exactly what arrived. The
 * master and the worker use wire.h.
 */
#ifndef PROTO_WIRE_PB_H
#define PROTO_WIRE_PB_H

#include "message_pb.h"
#include "wire.h"

/* wire_send_limited on an Envelope (same checks, same errors). */
int wire_send_envelope(void *socket, const proto_limits *limits, const void *identity,
                       size_t id_len, const Aafarm__Envelope *msg, const void *bulk,
                       size_t bulk_len, char *err, size_t errsz);

/* The checked Envelope as unpacked; valid until the message is destroyed. */
const Aafarm__Envelope *wire_msg_envelope(const wire_msg *self);

#endif

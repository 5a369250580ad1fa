/*
 * message.h: what a well-formed message of the farm is.
 *
 * The schema (aafarm.proto) says which fields exist; protobuf-c decodes
 * any bytes into its structs without judging them. This is the judge:
 * proto_message_check() looks at every field of an unpacked Envelope
 * against the limits below and the rules of docs/protocol.md (required
 * fields present, hashes well formed, names unique, a job's shader
 * bindings pointing at sources it carries, tile rectangles inside the
 * image limits, lengths and counts bounded, no control characters in
 * names) and says in words what is wrong. The wire layer (wire.h) runs
 * it on everything it sends and receives, so the master and the worker
 * only ever see messages that passed.
 *
 * Also here: the names and directions of the message kinds.
 *
 * Not here: whether a Job's job_hash matches its content. Which fields
 * make up a job's identity is the job model's decision (common/job,
 * hashing with common/util/hash.h); the worker recomputes the hash from
 * the fields it received and compares (docs/protocol.md, "Job hash").
 */
#ifndef PROTO_MESSAGE_H
#define PROTO_MESSAGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "aafarm.pb-c.h"

/* Bounds on what a peer may send. proto_limits_default() gives the values
 * documented in docs/protocol.md ("Limits"); a deployment may raise them,
 * on both sides alike. */
typedef struct proto_limits {
    size_t max_header_bytes;  /* the packed Envelope frame           (4 MiB) */
    size_t max_bulk_bytes;    /* the bulk frame (a tile's EXR)      (64 MiB) */
    size_t max_name_bytes;    /* names, hosts, keys, option values   (4096) */
    size_t max_text_bytes;    /* scene text, one shader, a message  (4 MiB) */
    size_t max_list;          /* entries of any repeated field       (4096) */
    uint32_t max_image_side;  /* image width/height, tile right edge (65536) */
    uint32_t max_tile_side;   /* tile width/height, tile_size        (8192) */
    uint32_t max_threads;     /* Hello.threads                       (4096) */
    uint32_t max_credits;     /* Ask.credits                         (4096) */
    uint32_t max_deadline_ms; /* Grant.deadline_ms           (86400000: 1 day) */
    size_t unpack_factor;     /* an unpacked header may use this many times
                                 its wire size (+ 64 KiB) of memory  (16) */
} proto_limits;

proto_limits proto_limits_default(void);

/* Welcome.heartbeat_ms and Welcome.heartbeat_liveness must lie in these
 * ranges (fixed by the protocol, not by a deployment). */
#define PROTO_HEARTBEAT_MS_MIN 10u
#define PROTO_HEARTBEAT_MS_MAX 3600000u
#define PROTO_LIVENESS_MAX 1000u

/* NeedFile.length and FileChunk.length are at most this (FileChunk's also
 * at most the receiver's max_bulk_bytes). */
#define PROTO_MAX_FILE_CHUNK (16u << 20)

/* File bytes the master sends a worker beyond what the worker says it has
 * received (NeedFile.received): a peer cannot make the master queue more. */
#define PROTO_MAX_FILE_INFLIGHT (64u << 20)

typedef Aafarm__Envelope__BodyCase proto_kind;

/* "Hello", "Welcome", ..., "Shutdown"; "(no message)" for NOT_SET and
 * "(unknown message)" for anything else. */
const char *proto_message_name(proto_kind kind);

/* Which side may send a kind: workers send Hello, Ask, NeedJob, Result,
 * Failure, Heartbeat, Shutdown, NeedFile, FilesReady; the master sends
 * Welcome, Reject, Job, Grant, Heartbeat, JobDone, Shutdown, FileChunk. */
bool proto_message_from_worker(proto_kind kind);
bool proto_message_from_master(proto_kind kind);

/* True for the kinds that carry a bulk frame (Result, FileChunk). */
bool proto_message_has_bulk(proto_kind kind);

/* Checks one message. has_bulk/bulk_len describe the bulk frame that came
 * (or goes) with it. Returns 0 when the message is well formed; otherwise
 * -1 and, when err is not NULL, a sentence naming the field and the
 * problem, e.g. "Grant.tile.width: 0 is outside 1..8192". limits NULL
 * means proto_limits_default().
 *
 * A Hello or Welcome whose protocol_version differs from ours is checked
 * only for its frozen fields (aafarm.proto), so that it still reaches the
 * code that answers a mismatch clearly instead of being dropped. */
int proto_message_check(const Aafarm__Envelope *msg, bool has_bulk, size_t bulk_len,
                        const proto_limits *limits, char *err, size_t errlen);

#endif

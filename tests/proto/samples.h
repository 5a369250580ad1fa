/*
 * tests/proto/samples.h: one valid message of every kind, and the
 * ROUTER/DEALER socket pair the wire tests talk over (shared by the
 * tests/proto test programs; not a test itself).
 *
 * A sample owns every struct its Envelope points into, so it must not be
 * copied or moved after sample_make(). Tests mutate one field of a valid
 * sample to make each kind of invalid message.
 */
#ifndef TESTS_PROTO_SAMPLES_H
#define TESTS_PROTO_SAMPLES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "message.h"
#include "util/hash.h"
#include "wire_pb.h"

/* Where the tests' wire_ calls write their error (err_set, util/err.h). */
extern char wire_err[ERR_LEN];

typedef struct sample {
    Aafarm__Envelope env;
    Aafarm__Hello hello;
    char *jobs_held[2];
    Aafarm__Welcome welcome;
    Aafarm__Reject reject;
    Aafarm__Ask ask;
    Aafarm__Job job;
    Aafarm__Source source[2];
    Aafarm__Source *sources[2];
    Aafarm__ShaderBinding binding[2];
    Aafarm__ShaderBinding *bindings[2];
    Aafarm__RenderOptions options;
    char *layers[2];
    Aafarm__Option option[2];
    Aafarm__Option *extra[2];
    Aafarm__NeedJob need_job;
    Aafarm__Grant grant;
    Aafarm__Rect rect;
    Aafarm__Result result;
    Aafarm__TileStats stats;
    Aafarm__Failure failure;
    Aafarm__Heartbeat heartbeat;
    uint64_t leases[3];
    Aafarm__JobDone job_done;
    Aafarm__Shutdown shutdown;
    Aafarm__FileRef file_ref[2];
    Aafarm__FileRef *file_refs[2];
    Aafarm__NeedFile need_file;
    Aafarm__FileChunk file_chunk;
    Aafarm__FilesReady files_ready;
    char job_hash[HASH_HEX_SIZE];
    char file_hash[HASH_HEX_SIZE];
    uint8_t bulk[3000];  /* the Result's / FileChunk's bulk frame (pseudo-random bytes) */
    size_t bulk_len;     /* 0 for every other kind */
} sample;

/* All fifteen kinds, in schema order. */
enum { SAMPLE_KINDS = 15 };
extern const proto_kind sample_kinds[SAMPLE_KINDS];

/* Fills s with a valid message of the kind (passes proto_message_check). */
void sample_make(sample *s, proto_kind kind);

/* The bulk pointer to send with s (NULL unless a Result or a FileChunk). */
const void *sample_bulk(const sample *s);

/* s packed with protobuf-c; *len receives the size. free() the result. */
uint8_t *sample_pack(const Aafarm__Envelope *env, size_t *len);

/* ROUTER (the master) bound and DEALER (a worker) connected, in one ctx. */
typedef struct sock_pair {
    void *ctx;
    void *router;
    void *dealer;
    char endpoint[256];
} sock_pair;

/* transport "inproc" or "tcp" (tcp://127.0.0.1:* with ZMQ_LAST_ENDPOINT).
 * Both sockets get wire_socket_setup(limits) and a 5 s receive timeout. */
void pair_open(sock_pair *p, const char *transport, const proto_limits *limits);
void pair_close(sock_pair *p);

#endif

/*
 * packed.c: a Job as bytes outside ZeroMQ (message.h, proto_job_pack):
 * the form a job queue's submission carries it in (docs/farm.md, "A job
 * queue"). The same Envelope a worker receives, packed by protobuf-c and,
 * on the way back, unpacked, checked against the limits (as wire.c checks
 * what arrives on the socket) and deep-copied into a proto_saved_job.
 */
#include <stdlib.h>
#include <string.h>

#include "message_pb.h"
#include "util/err.h"
#include "util/xalloc.h"

uint8_t *proto_job_pack(const proto_job *job, size_t *len)
{
    proto_msg msg = {.kind = PROTO_JOB, .job = *job};
    envelope_out out;
    envelope_out_init(&out, &msg);
    size_t n = aafarm__envelope__get_packed_size(&out.env);
    uint8_t *buf = xmalloc(n ? n : 1);
    aafarm__envelope__pack(&out.env, buf);
    envelope_out_clear(&out);
    *len = n;
    return buf;
}

proto_saved_job *proto_job_unpack(const void *data, size_t len, const proto_limits *limits,
                                  char *err, size_t errsz)
{
    proto_limits l = limits ? *limits : proto_limits_default();
    if (len > l.max_header_bytes) {
        err_set(err, errsz, "a job of %zu bytes: at most %zu", len, l.max_header_bytes);
        return NULL;
    }
    Aafarm__Envelope *env = aafarm__envelope__unpack(NULL, len, data);
    if (!env) {
        err_set(err, errsz, "%zu bytes that are not an aafarm Envelope (protobuf decoding failed)",
                len);
        return NULL;
    }
    char why[ERR_LEN];
    proto_saved_job *saved = NULL;
    if (env->body_case != AAFARM__ENVELOPE__BODY_JOB) {
        err_set(err, errsz, "an Envelope that holds no Job");
    } else if (!proto_message_check(env, false, 0, &l, why, sizeof why)) {
        err_set(err, errsz, "%s", why);
    } else {
        proto_msg msg;
        void *block = NULL;
        if (proto_msg_view(env, &msg, &block)) saved = proto_saved_job_new(&msg.job);
        else err_set(err, errsz, "out of memory for the Job's arrays");
        free(block);
    }
    aafarm__envelope__free_unpacked(env, NULL);
    return saved;
}

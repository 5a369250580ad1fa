/*
 * message_pb.h: proto's internal header, where the plain messages of
 * message.h meet the protobuf-c structs generated from aafarm.proto.
 * Only the .c files of proto/ (and the protocol's own tests, which build malformed
 * Envelopes on purpose) include it; the master and the worker never see
 * an Aafarm__ type.
 *
 * envelope_out: a proto_msg dressed as an Envelope for packing. It
 * borrows the message's strings; the pointer arrays a Job needs are its
 * own (envelope_out_clear frees them).
 *
 * proto_msg_view: the other way, a proto_msg pointing into an unpacked
 * Envelope. The arrays of structs it needs come from one try_malloc
 * block: NULL (out of memory, after a size a peer chose) is a refusal,
 * never an abort.
 */
#ifndef PROTO_MESSAGE_PB_H
#define PROTO_MESSAGE_PB_H

#include "aafarm.pb-c.h"
#include "message.h"

typedef struct envelope_out {
    Aafarm__Envelope env;
    union {
        Aafarm__Hello hello;
        Aafarm__Welcome welcome;
        Aafarm__Reject reject;
        Aafarm__Ask ask;
        Aafarm__Job job;
        Aafarm__NeedJob need_job;
        Aafarm__Grant grant;
        Aafarm__Result result;
        Aafarm__Failure failure;
        Aafarm__Heartbeat heartbeat;
        Aafarm__JobDone job_done;
        Aafarm__Shutdown shutdown;
        Aafarm__NeedFile need_file;
        Aafarm__FileChunk file_chunk;
        Aafarm__FilesReady files_ready;
    } body;
    Aafarm__RenderOptions options;  /* a Job's */
    Aafarm__Rect rect;              /* a Grant's */
    Aafarm__TileStats stats;        /* a Result's */
    void *arrays;                   /* a Job's pointer arrays, one block */
} envelope_out;

/* Fills out from msg (never fails: the arrays come from xmalloc). */
void envelope_out_init(envelope_out *out, const proto_msg *msg);
void envelope_out_clear(envelope_out *out);

/* Fills msg with a view of env (which must outlive it); *block receives
 * the memory to free() afterwards (NULL when none was needed). False when
 * that memory could not be had. */
bool proto_msg_view(const Aafarm__Envelope *env, proto_msg *msg, void **block);

/* The check of message.h on an Envelope as it came off the wire (or as a
 * test made it): the same rules and the same sentences. */
bool proto_message_check(const Aafarm__Envelope *msg, bool has_bulk, size_t bulk_len,
                         const proto_limits *limits, char *err, size_t errsz);

#endif

/*
 * message.h: what a well-formed message of the farm is, and the messages
 * themselves as plain C structs.
 *
 * The schema (aafarm.proto) says which fields exist; protobuf-c decodes
 * any bytes into its structs without judging them. This is the judge:
 * the check looks at every field of a message against the limits below
 * and the rules of docs/protocol.md (required fields present, hashes well
 * formed, names unique, a job's shader bindings pointing at sources it
 * carries, tile rectangles inside the image limits, lengths and counts
 * bounded, no control characters in names) and says in words what is
 * wrong. The wire layer (wire.h) runs it on everything it sends and
 * receives, so the master and the worker only ever see messages that
 * passed.
 *
 * The master and the worker see a message as a proto_msg: its kind and
 * one plain struct per kind (proto_hello, proto_job, ...), one field per
 * field of aafarm.proto. The structs borrow their strings and arrays: a
 * sender points them at its own data for the time of wire_send; a
 * received one points into the wire_msg it came in. The generated
 * protobuf-c types (Aafarm__*) never leave proto/ (message_pb.h is
 * proto's internal header), as CZMQ's zproto codecs keep theirs.
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

/* The kinds of message: the Envelope's oneof, numbered as its fields. */
typedef enum proto_kind {
    PROTO_NONE = 0,         /* no message (an unknown kind from a newer peer) */
    PROTO_HELLO = 1,        /* worker -> master, first message */
    PROTO_WELCOME = 2,      /* master -> worker, answer to hello */
    PROTO_REJECT = 3,       /* master -> worker, refusal */
    PROTO_ASK = 4,          /* worker -> master, more tiles please */
    PROTO_JOB = 5,          /* master -> worker, a job description */
    PROTO_NEED_JOB = 6,     /* worker -> master, "send me that job" */
    PROTO_GRANT = 7,        /* master -> worker, one tile lease */
    PROTO_RESULT = 8,       /* worker -> master, a rendered tile (+ bulk) */
    PROTO_FAILURE = 9,      /* worker -> master, a tile that failed */
    PROTO_HEARTBEAT = 10,   /* both ways, liveness */
    PROTO_JOB_DONE = 11,    /* master -> worker, a job is over */
    PROTO_SHUTDOWN = 12,    /* both ways, orderly goodbye */
    PROTO_NEED_FILE = 13,   /* worker -> master, a chunk of a file it lacks */
    PROTO_FILE_CHUNK = 14,  /* master -> worker, that chunk (+ bulk) */
    PROTO_FILES_READY = 15, /* worker -> master, a job's files are here */
} proto_kind;

/* ---- the messages (aafarm.proto says what each field means) ---- */

typedef struct proto_hello {
    uint32_t protocol_version;
    const char *worker_name;
    const char *host;
    uint32_t pid;
    uint32_t threads;
    size_t n_jobs_held;
    const char *const *jobs_held;
    const char *software;
    const char *pool;              /* "" or NULL: no pool */
} proto_hello;

typedef struct proto_welcome {
    uint32_t protocol_version;
    const char *master_name;
    uint64_t master_session;
    uint32_t heartbeat_ms;
    uint32_t heartbeat_liveness;
} proto_welcome;

typedef enum proto_reject_code {
    PROTO_REJECT_UNSPECIFIED = 0,
    PROTO_REJECT_VERSION_MISMATCH = 1,  /* fatal: the worker stops */
    PROTO_REJECT_HELLO_FIRST = 2,       /* the master does not know this peer */
    PROTO_REJECT_REFUSED = 3,           /* the master will not serve this worker */
} proto_reject_code;

typedef struct proto_reject {
    proto_reject_code code;
    const char *reason;
    uint32_t protocol_version;
} proto_reject;

typedef struct proto_ask {
    uint32_t credits;
} proto_ask;

typedef struct proto_source {
    const char *name;
    const uint8_t *text;
    size_t text_len;
} proto_source;

typedef struct proto_shader_binding {
    const char *name;
    const char *source;
} proto_shader_binding;

typedef struct proto_option {
    const char *key;
    const char *value;
} proto_option;

typedef enum proto_arithmetic {
    PROTO_ARITH_AFFINE = 0,
    PROTO_ARITH_INTERVAL = 1,
} proto_arithmetic;

typedef struct proto_render_options {
    uint32_t width;
    uint32_t height;
    uint32_t tile_size;
    proto_arithmetic arithmetic;
    uint64_t cache_bytes;
    uint64_t instruction_budget;
    size_t n_layers;
    const char *const *layers;
    size_t n_extra;
    const proto_option *extra;
    uint32_t frame;
} proto_render_options;

typedef struct proto_file_ref {
    const char *name;
    const char *sha256;
    uint64_t size;
} proto_file_ref;

typedef struct proto_job {
    const char *job_hash;
    const char *scene_name;
    const uint8_t *scene_text;
    size_t scene_len;
    size_t n_sources;
    const proto_source *sources;
    proto_render_options options;   /* always present (required) */
    size_t n_shaders;
    const proto_shader_binding *shaders;
    size_t n_files;
    const proto_file_ref *files;
} proto_job;

typedef struct proto_need_job {
    const char *job_hash;
    uint64_t lease_id;
} proto_need_job;

typedef struct proto_rect {
    uint32_t x, y, width, height;
} proto_rect;

typedef struct proto_grant {
    const char *job_hash;
    uint64_t lease_id;
    uint32_t tile_index;
    proto_rect tile;                /* always present (required) */
    uint32_t deadline_ms;
} proto_grant;

typedef struct proto_tile_stats {
    uint64_t rays;
    uint64_t boxes;
    uint64_t shader_evals;
    uint64_t cache_hits;
    uint64_t cache_misses;
    uint64_t cache_evictions;
    uint64_t peak_cache_bytes;
    double cpu_seconds;
    double wall_seconds;
    uint64_t nonfinite_samples;
} proto_tile_stats;

typedef struct proto_result {
    const char *job_hash;
    uint64_t lease_id;
    uint32_t tile_index;
    proto_tile_stats stats;         /* always present (required) */
    uint64_t exr_bytes;
} proto_result;

typedef struct proto_failure {
    const char *job_hash;
    uint64_t lease_id;
    uint32_t tile_index;
    const char *message;
    bool retryable;
} proto_failure;

typedef struct proto_heartbeat {
    size_t n_leases;
    const uint64_t *leases;
} proto_heartbeat;

typedef enum proto_job_status {
    PROTO_JOB_STATUS_DONE = 0,
    PROTO_JOB_STATUS_FAILED = 1,
    PROTO_JOB_STATUS_CANCELLED = 2,
} proto_job_status;

typedef struct proto_job_done {
    const char *job_hash;
    proto_job_status status;
    const char *message;
} proto_job_done;

typedef struct proto_shutdown {
    const char *reason;
} proto_shutdown;

typedef struct proto_need_file {
    const char *job_hash;
    const char *sha256;
    uint64_t offset;
    uint32_t length;
    uint64_t received;
} proto_need_file;

typedef struct proto_file_chunk {
    const char *sha256;
    uint64_t offset;
    uint64_t file_size;
    uint64_t length;
} proto_file_chunk;

typedef struct proto_files_ready {
    const char *job_hash;
    uint32_t hits;
    uint32_t misses;
    uint64_t fetched_bytes;
} proto_files_ready;

/* One message: its kind and the struct of that kind. A string left NULL
 * is sent as "" (protobuf has no absent string); received strings are
 * never NULL. */
typedef struct proto_msg {
    proto_kind kind;
    union {
        proto_hello hello;
        proto_welcome welcome;
        proto_reject reject;
        proto_ask ask;
        proto_job job;
        proto_need_job need_job;
        proto_grant grant;
        proto_result result;
        proto_failure failure;
        proto_heartbeat heartbeat;
        proto_job_done job_done;
        proto_shutdown shutdown;
        proto_need_file need_file;
        proto_file_chunk file_chunk;
        proto_files_ready files_ready;
    };
} proto_msg;

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
 * (or goes) with it. Returns true when the message is well formed;
 * otherwise false and, in err, a sentence naming the field and the
 * problem, e.g. "Grant.tile.width: 0 is outside 1..8192". limits NULL
 * means proto_limits_default().
 *
 * A Hello or Welcome whose protocol_version differs from ours is checked
 * only for its frozen fields (aafarm.proto), so that it still reaches the
 * code that answers a mismatch clearly instead of being dropped. */
bool proto_msg_check(const proto_msg *msg, bool has_bulk, size_t bulk_len,
                     const proto_limits *limits, char *err, size_t errsz);

/* A worker pool's name (Hello.pool, a job's --pool): 1 to PROTO_POOL_MAX
 * letters, digits, '.', '_' or '-'. False with the reason. */
enum { PROTO_POOL_MAX = 63 };
bool proto_pool_name_check(const char *name, char *err, size_t errsz);

/* Bytes of the message packed (the header frame wire_send would send). */
size_t proto_msg_packed_size(const proto_msg *msg);

/* A Job kept beyond its wire_msg (a worker holds it while its files come):
 * a deep copy, with strings and arrays of its own. */
typedef struct proto_saved_job proto_saved_job;

proto_saved_job *proto_saved_job_new(const proto_job *job);
const proto_job *proto_saved_job_get(const proto_saved_job *self);
void proto_saved_job_destroy(proto_saved_job **self_p);

/* A Job as bytes outside ZeroMQ (packed.c; a job queue's submission): the
 * packed Envelope, xmalloc'd, its size in *len. */
uint8_t *proto_job_pack(const proto_job *job, size_t *len);
/* The reverse, checked as a received message is (limits NULL: the
 * defaults): NULL with the reason in err. */
proto_saved_job *proto_job_unpack(const void *data, size_t len, const proto_limits *limits,
                                  char *err, size_t errsz);

#endif

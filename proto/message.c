/*
 * message.c: the checks every message passes before the master or a
 * worker reads it (the rules: message.h and docs/protocol.md, "Messages"
 * and "Limits"), the names and directions of the message kinds.
 *
 * One check_<kind>() per message kind, built from a few field checks
 * (hash, name, text, range, count). Each failing check writes one
 * sentence "<Message>.<field>: <problem>" and returns -1; nothing here
 * trusts a length or a count that it has not compared with a limit.
 */
#include "message_pb.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/err.h"
#include "util/xalloc.h"
#include "util/hash.h"
#include "version.h"

proto_limits proto_limits_default(void)
{
    proto_limits l = {
        .max_header_bytes = 4u << 20,
        .max_bulk_bytes = 64u << 20,
        .max_name_bytes = 4096,
        .max_text_bytes = 4u << 20,
        .max_list = 4096,
        .max_image_side = 65536,
        .max_tile_side = 8192,
        .max_threads = 4096,
        .max_credits = 4096,
        .max_deadline_ms = 86400000u,
        .unpack_factor = 16,
    };
    return l;
}

/* ---------------------------------------------------------------------- */
/* kinds                                                                   */
/* ---------------------------------------------------------------------- */

const char *proto_message_name(proto_kind kind)
{
    switch (kind) {
    case PROTO_NONE: return "(no message)";
    case PROTO_HELLO: return "Hello";
    case PROTO_WELCOME: return "Welcome";
    case PROTO_REJECT: return "Reject";
    case PROTO_ASK: return "Ask";
    case PROTO_JOB: return "Job";
    case PROTO_NEED_JOB: return "NeedJob";
    case PROTO_GRANT: return "Grant";
    case PROTO_RESULT: return "Result";
    case PROTO_FAILURE: return "Failure";
    case PROTO_HEARTBEAT: return "Heartbeat";
    case PROTO_JOB_DONE: return "JobDone";
    case PROTO_SHUTDOWN: return "Shutdown";
    case PROTO_NEED_FILE: return "NeedFile";
    case PROTO_FILE_CHUNK: return "FileChunk";
    case PROTO_FILES_READY: return "FilesReady";
    default: return "(unknown message)";
    }
}

bool proto_message_from_worker(proto_kind kind)
{
    switch (kind) {
    case PROTO_HELLO:
    case PROTO_ASK:
    case PROTO_NEED_JOB:
    case PROTO_RESULT:
    case PROTO_FAILURE:
    case PROTO_HEARTBEAT:
    case PROTO_SHUTDOWN:
    case PROTO_NEED_FILE:
    case PROTO_FILES_READY:
        return true;
    default:
        return false;
    }
}

bool proto_message_from_master(proto_kind kind)
{
    switch (kind) {
    case PROTO_WELCOME:
    case PROTO_REJECT:
    case PROTO_JOB:
    case PROTO_GRANT:
    case PROTO_HEARTBEAT:
    case PROTO_JOB_DONE:
    case PROTO_SHUTDOWN:
    case PROTO_FILE_CHUNK:
        return true;
    default:
        return false;
    }
}

bool proto_message_has_bulk(proto_kind kind)
{
    return kind == PROTO_RESULT || kind == PROTO_FILE_CHUNK;
}

/* ---------------------------------------------------------------------- */
/* field checks                                                            */
/* ---------------------------------------------------------------------- */

/* Where a check writes its sentence. */
typedef struct checker {
    const proto_limits *limits;
    char *err;
    size_t errsz;
} checker;

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static int fail(checker *c, const char *field, const char *fmt, ...)
{
    if (c->err && c->errsz > 0) {
        char what[ERR_LEN];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(what, sizeof what, fmt, ap);
        va_end(ap);
        err_set(c->err, c->errsz, "%s: %s", field, what);
    }
    return -1;
}

static int check_hash(checker *c, const char *field, const char *s)
{
    if (!s || !*s)
        return fail(c, field, "missing (a job hash is 64 lowercase hex digits)");
    if (!hash_hex_valid(s))
        return fail(c, field, "not a job hash (64 lowercase hex digits, got %zu bytes)",
                    strnlen(s, 1000));
    return 0;
}

/* A control character other than the allowed ones, or -1. */
static long control_at(const char *s, size_t len, bool multiline)
{
    for (size_t i = 0; i < len; i++) {
        unsigned char ch = (unsigned char)s[i];
        bool layout = ch == '\n' || ch == '\t' || ch == '\r';
        if ((ch < 0x20 || ch == 0x7f) && !(multiline && layout))
            return (long)i;
    }
    return -1;
}

/* A one-line name: at most max_name_bytes, no control characters. */
static int check_name(checker *c, const char *field, const char *s, bool required)
{
    size_t len = s ? strlen(s) : 0;
    if (len == 0)
        return required ? fail(c, field, "missing (must not be empty)") : 0;
    if (len > c->limits->max_name_bytes)
        return fail(c, field, "%zu bytes, the limit is %zu", len, c->limits->max_name_bytes);
    long at = control_at(s, len, false);
    if (at >= 0)
        return fail(c, field, "control character 0x%02x at byte %ld",
                    (unsigned)(unsigned char)s[at], at);
    return 0;
}

/* Free text (a reason, an error message): at most max_text_bytes; line
 * breaks and tabs allowed, other control characters not. */
static int check_prose(checker *c, const char *field, const char *s, bool required)
{
    size_t len = s ? strlen(s) : 0;
    if (len == 0)
        return required ? fail(c, field, "missing (must not be empty)") : 0;
    if (len > c->limits->max_text_bytes)
        return fail(c, field, "%zu bytes, the limit is %zu", len, c->limits->max_text_bytes);
    long at = control_at(s, len, true);
    if (at >= 0)
        return fail(c, field, "control character 0x%02x at byte %ld",
                    (unsigned)(unsigned char)s[at], at);
    return 0;
}

/* Source text (scene, shader) in a bytes field: non-empty, bounded, no
 * NUL byte (the parsers read C strings). */
static int check_source(checker *c, const char *field, ProtobufCBinaryData text)
{
    if (text.len == 0 || !text.data)
        return fail(c, field, "missing (must not be empty)");
    if (text.len > c->limits->max_text_bytes)
        return fail(c, field, "%zu bytes, the limit is %zu", text.len, c->limits->max_text_bytes);
    const uint8_t *nul = memchr(text.data, 0, text.len);
    if (nul)
        return fail(c, field, "NUL byte at offset %zu (source text must be text)",
                    (size_t)(nul - text.data));
    return 0;
}

static int check_range(checker *c, const char *field, uint64_t v, uint64_t lo, uint64_t hi)
{
    if (v < lo || v > hi)
        return fail(c, field, "%llu is outside %llu..%llu", (unsigned long long)v,
                    (unsigned long long)lo, (unsigned long long)hi);
    return 0;
}

static int check_count(checker *c, const char *field, size_t n)
{
    if (n > c->limits->max_list)
        return fail(c, field, "%zu entries, the limit is %zu", n, c->limits->max_list);
    return 0;
}

static int check_present(checker *c, const char *field, const void *p)
{
    return p ? 0 : fail(c, field, "missing");
}

static int check_seconds(checker *c, const char *field, double v)
{
    if (!isfinite(v) || v < 0)
        return fail(c, field, "%g is not a finite number of seconds >= 0", v);
    return 0;
}

static int by_string(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Fails when two of names[0..n) are equal (names already checked). */
static int check_unique(checker *c, const char *field, const char *const *names, size_t n)
{
    if (n < 2)
        return 0;
    const char **v = try_malloc(n * sizeof *v);
    if (!v)
        return fail(c, field, "out of memory checking %zu names", n);
    memcpy(v, names, n * sizeof *v);
    qsort(v, n, sizeof *v, by_string);
    int rc = 0;
    for (size_t i = 1; i < n && rc == 0; i++)
        if (strcmp(v[i - 1], v[i]) == 0)
            rc = fail(c, field, "\"%s\" appears twice", v[i]);
    free(v);
    return rc;
}

/* ---------------------------------------------------------------------- */
/* one check per message kind                                              */
/* ---------------------------------------------------------------------- */

bool proto_pool_name_check(const char *name, char *err, size_t errsz)
{
    size_t len = strlen(name);
    if (len == 0 || len > PROTO_POOL_MAX)
        return err_set(err, errsz, "a pool name has 1 to %d characters, '%.80s' has %zu",
                       PROTO_POOL_MAX, name, len);
    for (size_t i = 0; i < len; i++) {
        char ch = name[i];
        bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
                  ch == '.' || ch == '_' || ch == '-';
        if (!ok)
            return err_set(err, errsz, "pool name '%.80s': character %zu is not a letter, digit, "
                           "'.', '_' or '-'", name, i + 1);
    }
    return true;
}

static int check_hello(checker *c, const Aafarm__Hello *m)
{
    if (m->protocol_version == 0)
        return fail(c, "Hello.protocol_version", "missing");
    if (m->protocol_version != AAFARM_PROTOCOL_VERSION)
        return 0; /* frozen fields only: the master answers with a Reject */
    if (check_name(c, "Hello.worker_name", m->worker_name, true) ||
        check_name(c, "Hello.host", m->host, true) ||
        check_range(c, "Hello.threads", m->threads, 1, c->limits->max_threads) ||
        check_name(c, "Hello.software", m->software, false) ||
        (m->pool && *m->pool && !proto_pool_name_check(m->pool, NULL, 0) &&
         fail(c, "Hello.pool", "not a pool name (letters, digits, '.', '_', '-'; at most %d)",
              PROTO_POOL_MAX)) ||
        check_count(c, "Hello.jobs_held", m->n_jobs_held))
        return -1;
    for (size_t i = 0; i < m->n_jobs_held; i++)
        if (check_hash(c, "Hello.jobs_held", m->jobs_held[i]))
            return -1;
    return 0;
}

static int check_welcome(checker *c, const Aafarm__Welcome *m)
{
    if (m->protocol_version == 0)
        return fail(c, "Welcome.protocol_version", "missing");
    if (m->protocol_version != AAFARM_PROTOCOL_VERSION)
        return 0; /* frozen fields only: the worker reports the mismatch */
    if (check_name(c, "Welcome.master_name", m->master_name, false))
        return -1;
    if (m->master_session == 0)
        return fail(c, "Welcome.master_session", "missing (must not be 0)");
    return check_range(c, "Welcome.heartbeat_ms", m->heartbeat_ms, PROTO_HEARTBEAT_MS_MIN,
                       PROTO_HEARTBEAT_MS_MAX) ||
                   check_range(c, "Welcome.heartbeat_liveness", m->heartbeat_liveness, 1,
                               PROTO_LIVENESS_MAX)
               ? -1
               : 0;
}

/* Reject is frozen: any code (a newer master may have more; unknown codes
 * read as REFUSED), a reason in words. */
static int check_reject(checker *c, const Aafarm__Reject *m)
{
    return check_prose(c, "Reject.reason", m->reason, true);
}

static int check_ask(checker *c, const Aafarm__Ask *m)
{
    return check_range(c, "Ask.credits", m->credits, 1, c->limits->max_credits);
}

/* The source files: names unique, texts present. */
static int check_sources(checker *c, const Aafarm__Job *m)
{
    if (check_count(c, "Job.sources", m->n_sources))
        return -1;
    const char **names = try_malloc((m->n_sources + 1) * sizeof *names);
    if (!names)
        return fail(c, "Job.sources", "out of memory");
    int rc = 0;
    for (size_t i = 0; i < m->n_sources && rc == 0; i++) {
        const Aafarm__Source *s = m->sources[i];
        if (!s) {
            rc = fail(c, "Job.sources", "entry %zu is missing", i);
            break;
        }
        rc = check_name(c, "Job.sources.name", s->name, true) ||
             check_source(c, "Job.sources.text", s->text);
        names[i] = s->name;
    }
    if (rc == 0)
        rc = check_unique(c, "Job.sources.name", names, m->n_sources);
    free(names);
    return rc ? -1 : 0;
}

static bool has_source(const Aafarm__Job *m, const char *name)
{
    for (size_t i = 0; i < m->n_sources; i++)
        if (strcmp(m->sources[i]->name, name) == 0)
            return true;
    return false;
}

/* The shader bindings: names unique, each naming a source of the job
 * (sources already checked). */
static int check_bindings(checker *c, const Aafarm__Job *m)
{
    if (check_count(c, "Job.shaders", m->n_shaders))
        return -1;
    const char **names = try_malloc((m->n_shaders + 1) * sizeof *names);
    if (!names)
        return fail(c, "Job.shaders", "out of memory");
    int rc = 0;
    for (size_t i = 0; i < m->n_shaders && rc == 0; i++) {
        const Aafarm__ShaderBinding *b = m->shaders[i];
        if (!b) {
            rc = fail(c, "Job.shaders", "entry %zu is missing", i);
            break;
        }
        rc = check_name(c, "Job.shaders.name", b->name, true) ||
             check_name(c, "Job.shaders.source", b->source, true);
        if (rc == 0 && !has_source(m, b->source))
            rc = fail(c, "Job.shaders.source", "\"%s\" (for shader \"%s\") is not among Job.sources",
                      b->source, b->name);
        names[i] = b->name;
    }
    if (rc == 0)
        rc = check_unique(c, "Job.shaders.name", names, m->n_shaders);
    free(names);
    return rc ? -1 : 0;
}

static int check_extra(checker *c, const Aafarm__RenderOptions *o)
{
    if (check_count(c, "Job.options.extra", o->n_extra))
        return -1;
    const char **keys = try_malloc((o->n_extra + 1) * sizeof *keys);
    if (!keys)
        return fail(c, "Job.options.extra", "out of memory");
    int rc = 0;
    for (size_t i = 0; i < o->n_extra && rc == 0; i++) {
        const Aafarm__Option *kv = o->extra[i];
        if (!kv) {
            rc = fail(c, "Job.options.extra", "entry %zu is missing", i);
            break;
        }
        rc = check_name(c, "Job.options.extra.key", kv->key, true) ||
             check_name(c, "Job.options.extra.value", kv->value, false);
        keys[i] = kv->key;
    }
    if (rc == 0)
        rc = check_unique(c, "Job.options.extra.key", keys, o->n_extra);
    free(keys);
    return rc ? -1 : 0;
}

static int check_layers(checker *c, const Aafarm__RenderOptions *o)
{
    if (check_count(c, "Job.options.layers", o->n_layers))
        return -1;
    for (size_t i = 0; i < o->n_layers; i++)
        if (check_name(c, "Job.options.layers", o->layers[i], true))
            return -1;
    return check_unique(c, "Job.options.layers", (const char *const *)o->layers, o->n_layers);
}

static int check_options(checker *c, const Aafarm__RenderOptions *o)
{
    const proto_limits *l = c->limits;
    if (check_present(c, "Job.options", o) ||
        check_range(c, "Job.options.width", o->width, 1, l->max_image_side) ||
        check_range(c, "Job.options.height", o->height, 1, l->max_image_side) ||
        check_range(c, "Job.options.tile_size", o->tile_size, 1, l->max_tile_side))
        return -1;
    if (o->arithmetic != AAFARM__ARITHMETIC__ARITHMETIC_AFFINE &&
        o->arithmetic != AAFARM__ARITHMETIC__ARITHMETIC_INTERVAL)
        return fail(c, "Job.options.arithmetic", "%d is neither affine (0) nor interval (1)",
                    (int)o->arithmetic);
    return check_layers(c, o) || check_extra(c, o) ? -1 : 0;
}

/* The file references: names unique, hashes well formed. */
static int check_files(checker *c, const Aafarm__Job *m)
{
    if (check_count(c, "Job.files", m->n_files))
        return -1;
    const char **names = try_malloc((m->n_files + 1) * sizeof *names);
    if (!names)
        return fail(c, "Job.files", "out of memory");
    int rc = 0;
    for (size_t i = 0; i < m->n_files && rc == 0; i++) {
        const Aafarm__FileRef *f = m->files[i];
        if (!f) {
            rc = fail(c, "Job.files", "entry %zu is missing", i);
            break;
        }
        rc = check_name(c, "Job.files.name", f->name, true) ||
             check_hash(c, "Job.files.sha256", f->sha256);
        names[i] = f->name;
    }
    if (rc == 0)
        rc = check_unique(c, "Job.files.name", names, m->n_files);
    free(names);
    return rc ? -1 : 0;
}

static int check_job(checker *c, const Aafarm__Job *m)
{
    return check_hash(c, "Job.job_hash", m->job_hash) ||
                   check_name(c, "Job.scene_name", m->scene_name, true) ||
                   check_source(c, "Job.scene_text", m->scene_text) || check_sources(c, m) ||
                   check_bindings(c, m) || check_options(c, m->options) || check_files(c, m)
               ? -1
               : 0;
}

static int check_need_job(checker *c, const Aafarm__NeedJob *m)
{
    return check_hash(c, "NeedJob.job_hash", m->job_hash);
}

static int check_lease(checker *c, const char *field, uint64_t lease)
{
    return lease == 0 ? fail(c, field, "missing (must not be 0)") : 0;
}

static int check_rect(checker *c, const Aafarm__Rect *r)
{
    const proto_limits *l = c->limits;
    if (check_present(c, "Grant.tile", r) ||
        check_range(c, "Grant.tile.width", r->width, 1, l->max_tile_side) ||
        check_range(c, "Grant.tile.height", r->height, 1, l->max_tile_side))
        return -1;
    if ((uint64_t)r->x + r->width > l->max_image_side)
        return fail(c, "Grant.tile", "right edge x + width = %llu is beyond the image limit %u",
                    (unsigned long long)r->x + r->width, l->max_image_side);
    if ((uint64_t)r->y + r->height > l->max_image_side)
        return fail(c, "Grant.tile", "bottom edge y + height = %llu is beyond the image limit %u",
                    (unsigned long long)r->y + r->height, l->max_image_side);
    return 0;
}

static int check_grant(checker *c, const Aafarm__Grant *m)
{
    return check_hash(c, "Grant.job_hash", m->job_hash) ||
                   check_lease(c, "Grant.lease_id", m->lease_id) || check_rect(c, m->tile) ||
                   check_range(c, "Grant.deadline_ms", m->deadline_ms, 1,
                               c->limits->max_deadline_ms)
               ? -1
               : 0;
}

static int check_result(checker *c, const Aafarm__Result *m, bool has_bulk, size_t bulk_len)
{
    if (check_hash(c, "Result.job_hash", m->job_hash) ||
        check_lease(c, "Result.lease_id", m->lease_id) ||
        check_present(c, "Result.stats", m->stats) ||
        check_seconds(c, "Result.stats.cpu_seconds", m->stats->cpu_seconds) ||
        check_seconds(c, "Result.stats.wall_seconds", m->stats->wall_seconds))
        return -1;
    if (!has_bulk)
        return fail(c, "Result", "the bulk frame with the tile's EXR bytes is missing");
    if (m->exr_bytes == 0 || m->exr_bytes != bulk_len)
        return fail(c, "Result.exr_bytes", "says %llu but the bulk frame has %zu bytes",
                    (unsigned long long)m->exr_bytes, bulk_len);
    return 0;
}

static int check_failure(checker *c, const Aafarm__Failure *m)
{
    return check_hash(c, "Failure.job_hash", m->job_hash) ||
                   check_lease(c, "Failure.lease_id", m->lease_id) ||
                   check_prose(c, "Failure.message", m->message, true)
               ? -1
               : 0;
}

static int check_heartbeat(checker *c, const Aafarm__Heartbeat *m)
{
    if (check_count(c, "Heartbeat.leases", m->n_leases))
        return -1;
    for (size_t i = 0; i < m->n_leases; i++)
        if (check_lease(c, "Heartbeat.leases", m->leases[i]))
            return -1;
    return 0;
}

static int check_job_done(checker *c, const Aafarm__JobDone *m)
{
    if (check_hash(c, "JobDone.job_hash", m->job_hash))
        return -1;
    switch (m->status) {
    case AAFARM__JOB_STATUS__JOB_STATUS_DONE:
        return check_prose(c, "JobDone.message", m->message, false);
    case AAFARM__JOB_STATUS__JOB_STATUS_FAILED:
    case AAFARM__JOB_STATUS__JOB_STATUS_CANCELLED:
        return check_prose(c, "JobDone.message", m->message, true);
    default:
        return fail(c, "JobDone.status", "%d is not DONE, FAILED or CANCELLED", (int)m->status);
    }
}

static int check_shutdown(checker *c, const Aafarm__Shutdown *m)
{
    return check_prose(c, "Shutdown.reason", m->reason, false);
}

static uint64_t max_chunk(const checker *c)
{
    return c->limits->max_bulk_bytes < PROTO_MAX_FILE_CHUNK ? c->limits->max_bulk_bytes
                                                            : PROTO_MAX_FILE_CHUNK;
}

static int check_need_file(checker *c, const Aafarm__NeedFile *m)
{
    return check_hash(c, "NeedFile.job_hash", m->job_hash) ||
                   check_hash(c, "NeedFile.sha256", m->sha256) ||
                   check_range(c, "NeedFile.length", m->length, 1, PROTO_MAX_FILE_CHUNK)
               ? -1
               : 0;
}

static int check_file_chunk(checker *c, const Aafarm__FileChunk *m, bool has_bulk,
                            size_t bulk_len)
{
    if (check_hash(c, "FileChunk.sha256", m->sha256) ||
        check_range(c, "FileChunk.length", m->length, 1, max_chunk(c)))
        return -1;
    if (!has_bulk)
        return fail(c, "FileChunk", "the bulk frame with the file's bytes is missing");
    if (m->length != bulk_len)
        return fail(c, "FileChunk.length", "says %llu but the bulk frame has %zu bytes",
                    (unsigned long long)m->length, bulk_len);
    if (m->offset > m->file_size || m->length > m->file_size - m->offset)
        return fail(c, "FileChunk", "bytes %llu..%llu lie outside the file of %llu bytes",
                    (unsigned long long)m->offset,
                    (unsigned long long)(m->offset + m->length),
                    (unsigned long long)m->file_size);
    return 0;
}

static int check_files_ready(checker *c, const Aafarm__FilesReady *m)
{
    return check_hash(c, "FilesReady.job_hash", m->job_hash);
}

/* The body for its kind; a oneof member can still be NULL if a sender
 * built the struct by hand. */
static const void *body_of(const Aafarm__Envelope *m)
{
    switch (m->body_case) {
    case AAFARM__ENVELOPE__BODY_HELLO: return m->hello;
    case AAFARM__ENVELOPE__BODY_WELCOME: return m->welcome;
    case AAFARM__ENVELOPE__BODY_REJECT: return m->reject;
    case AAFARM__ENVELOPE__BODY_ASK: return m->ask;
    case AAFARM__ENVELOPE__BODY_JOB: return m->job;
    case AAFARM__ENVELOPE__BODY_NEED_JOB: return m->need_job;
    case AAFARM__ENVELOPE__BODY_GRANT: return m->grant;
    case AAFARM__ENVELOPE__BODY_RESULT: return m->result;
    case AAFARM__ENVELOPE__BODY_FAILURE: return m->failure;
    case AAFARM__ENVELOPE__BODY_HEARTBEAT: return m->heartbeat;
    case AAFARM__ENVELOPE__BODY_JOB_DONE: return m->job_done;
    case AAFARM__ENVELOPE__BODY_SHUTDOWN: return m->shutdown;
    case AAFARM__ENVELOPE__BODY_NEED_FILE: return m->need_file;
    case AAFARM__ENVELOPE__BODY_FILE_CHUNK: return m->file_chunk;
    case AAFARM__ENVELOPE__BODY_FILES_READY: return m->files_ready;
    default: return NULL;
    }
}

static int check_body(checker *c, const Aafarm__Envelope *m, bool has_bulk, size_t bulk_len)
{
    switch (m->body_case) {
    case AAFARM__ENVELOPE__BODY_HELLO: return check_hello(c, m->hello);
    case AAFARM__ENVELOPE__BODY_WELCOME: return check_welcome(c, m->welcome);
    case AAFARM__ENVELOPE__BODY_REJECT: return check_reject(c, m->reject);
    case AAFARM__ENVELOPE__BODY_ASK: return check_ask(c, m->ask);
    case AAFARM__ENVELOPE__BODY_JOB: return check_job(c, m->job);
    case AAFARM__ENVELOPE__BODY_NEED_JOB: return check_need_job(c, m->need_job);
    case AAFARM__ENVELOPE__BODY_GRANT: return check_grant(c, m->grant);
    case AAFARM__ENVELOPE__BODY_RESULT: return check_result(c, m->result, has_bulk, bulk_len);
    case AAFARM__ENVELOPE__BODY_FAILURE: return check_failure(c, m->failure);
    case AAFARM__ENVELOPE__BODY_HEARTBEAT: return check_heartbeat(c, m->heartbeat);
    case AAFARM__ENVELOPE__BODY_JOB_DONE: return check_job_done(c, m->job_done);
    case AAFARM__ENVELOPE__BODY_SHUTDOWN: return check_shutdown(c, m->shutdown);
    case AAFARM__ENVELOPE__BODY_NEED_FILE: return check_need_file(c, m->need_file);
    case AAFARM__ENVELOPE__BODY_FILE_CHUNK:
        return check_file_chunk(c, m->file_chunk, has_bulk, bulk_len);
    case AAFARM__ENVELOPE__BODY_FILES_READY: return check_files_ready(c, m->files_ready);
    default: return fail(c, "Envelope", "unknown message kind %d", (int)m->body_case);
    }
}

bool proto_message_check(const Aafarm__Envelope *msg, bool has_bulk, size_t bulk_len,
                         const proto_limits *limits, char *err, size_t errsz)
{
    proto_limits defaults = proto_limits_default();
    checker c = {limits ? limits : &defaults, err, errsz};
    if (!msg)
        return fail(&c, "Envelope", "missing") == 0;
    if (msg->body_case == AAFARM__ENVELOPE__BODY__NOT_SET)
        return fail(&c, "Envelope", "carries no message (an unknown kind from a newer peer?)") == 0;
    if (msg->body_case < AAFARM__ENVELOPE__BODY_HELLO ||
        msg->body_case > AAFARM__ENVELOPE__BODY_FILES_READY)
        return fail(&c, "Envelope", "unknown message kind %d", (int)msg->body_case) == 0;
    proto_kind kind = (proto_kind)msg->body_case;
    const char *name = proto_message_name(kind);
    if (!body_of(msg))
        return check_present(&c, name, NULL) == 0;
    if (has_bulk && !proto_message_has_bulk(kind))
        return fail(&c, name, "comes with a bulk frame of %zu bytes; only Result has one",
                    bulk_len) == 0;
    if (has_bulk && bulk_len > c.limits->max_bulk_bytes)
        return fail(&c, name, "bulk frame of %zu bytes, the limit is %zu", bulk_len,
                    c.limits->max_bulk_bytes) == 0;
    return check_body(&c, msg, has_bulk, bulk_len) == 0;
}

bool proto_msg_check(const proto_msg *msg, bool has_bulk, size_t bulk_len,
                     const proto_limits *limits, char *err, size_t errsz)
{
    if (!msg)
        return proto_message_check(NULL, has_bulk, bulk_len, limits, err, errsz);
    envelope_out out;
    envelope_out_init(&out, msg);
    bool ok = proto_message_check(&out.env, has_bulk, bulk_len, limits, err, errsz);
    envelope_out_clear(&out);
    return ok;
}

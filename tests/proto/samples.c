/*
 * tests/proto/samples.c: valid sample messages and the socket pair used by
 * the proto tests (interface: samples.h).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zmq.h>

#include "samples.h"
#include "version.h"

char wire_err[ERR_LEN];

const proto_kind sample_kinds[SAMPLE_KINDS] = {
    PROTO_HELLO,    PROTO_WELCOME,
    PROTO_REJECT,   PROTO_ASK,
    PROTO_JOB,      PROTO_NEED_JOB,
    PROTO_GRANT,    PROTO_RESULT,
    PROTO_FAILURE,  PROTO_HEARTBEAT,
    PROTO_JOB_DONE, PROTO_SHUTDOWN,
    PROTO_NEED_FILE, PROTO_FILE_CHUNK,
    PROTO_FILES_READY,
};

static const char scene_text[] =
    "Format 64 32 1\n"
    "WorldBegin\n"
    "  Displacement \"wave\" \"float amp\" [0.1]\n"
    "  Surface \"plastic\"\n"
    "  Sphere 1 -1 1 360\n"
    "WorldEnd\n";
static const char wave_sl[] =
    "displacement wave(float amp = 0.1) {\n"
    "    P += amp * sin(10 * u) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";
static const char plastic_sl[] = "surface plastic() { Ci = Cs; }\n";

static void make_sources(sample *s)
{
    Aafarm__Source source = AAFARM__SOURCE__INIT;
    Aafarm__ShaderBinding binding = AAFARM__SHADER_BINDING__INIT;
    s->source[0] = s->source[1] = source;
    s->binding[0] = s->binding[1] = binding;
    s->source[0].name = "wave.sl";
    s->source[0].text.data = (uint8_t *)wave_sl;
    s->source[0].text.len = strlen(wave_sl);
    s->source[1].name = "plastic.sl";
    s->source[1].text.data = (uint8_t *)plastic_sl;
    s->source[1].text.len = strlen(plastic_sl);
    s->sources[0] = &s->source[0];
    s->sources[1] = &s->source[1];
    s->binding[0].name = "wave";
    s->binding[0].source = "wave.sl";
    s->binding[1].name = "plastic";
    s->binding[1].source = "plastic.sl";
    s->bindings[0] = &s->binding[0];
    s->bindings[1] = &s->binding[1];
}

static void make_options(sample *s)
{
    Aafarm__RenderOptions options = AAFARM__RENDER_OPTIONS__INIT;
    Aafarm__Option option = AAFARM__OPTION__INIT;
    s->options = options;
    s->option[0] = s->option[1] = option;
    s->options.width = 64;
    s->options.height = 32;
    s->options.tile_size = 16;
    s->options.arithmetic = AAFARM__ARITHMETIC__ARITHMETIC_INTERVAL;
    s->options.cache_bytes = 400u << 10;
    s->options.instruction_budget = 1000000;
    s->layers[0] = "Ci";
    s->layers[1] = "N";
    s->options.n_layers = 2;
    s->options.layers = s->layers;
    s->option[0].key = "seed";
    s->option[0].value = "7";
    s->option[1].key = "preview";
    s->option[1].value = "";
    s->extra[0] = &s->option[0];
    s->extra[1] = &s->option[1];
    s->options.n_extra = 2;
    s->options.extra = s->extra;
}

static void make_job(sample *s)
{
    Aafarm__Job job = AAFARM__JOB__INIT;
    s->job = job;
    make_sources(s);
    make_options(s);
    s->job.scene_name = "scenes/wave.rib";
    s->job.scene_text.data = (uint8_t *)scene_text;
    s->job.scene_text.len = strlen(scene_text);
    s->job.n_sources = 2;
    s->job.sources = s->sources;
    s->job.n_shaders = 2;
    s->job.shaders = s->bindings;
    s->job.options = &s->options;
    /* a well-formed hash; which fields it covers is the job model's matter */
    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_digest(scene_text, strlen(scene_text), digest);
    hash_hex(digest, s->job_hash);
    s->job.job_hash = s->job_hash;
    /* two files, by name and content hash */
    sha256_digest(wave_sl, strlen(wave_sl), digest);
    hash_hex(digest, s->file_hash);
    for (int i = 0; i < 2; i++) {
        Aafarm__FileRef f = AAFARM__FILE_REF__INIT;
        s->file_ref[i] = f;
        s->file_ref[i].sha256 = s->file_hash;
        s->file_ref[i].size = 1u << 20;
        s->file_refs[i] = &s->file_ref[i];
    }
    s->file_ref[0].name = "maps/height.exr";
    s->file_ref[1].name = "height copy.exr";
    s->job.n_files = 2;
    s->job.files = s->file_refs;
    s->env.job = &s->job;
}

static void fill_bulk(sample *s)
{
    uint32_t x = 2463534242u; /* xorshift32: bytes that compress badly */
    s->bulk_len = sizeof s->bulk;
    for (size_t i = 0; i < s->bulk_len; i++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        s->bulk[i] = (uint8_t)x;
    }
}

static void make_need_file(sample *s)
{
    Aafarm__NeedFile m = AAFARM__NEED_FILE__INIT;
    s->need_file = m;
    s->need_file.job_hash = s->job_hash;
    s->need_file.sha256 = s->file_hash;
    s->need_file.offset = 3000;
    s->need_file.length = 3000;
    s->env.need_file = &s->need_file;
}

static void make_file_chunk(sample *s)
{
    Aafarm__FileChunk m = AAFARM__FILE_CHUNK__INIT;
    s->file_chunk = m;
    fill_bulk(s);
    s->file_chunk.sha256 = s->file_hash;
    s->file_chunk.offset = 3000;
    s->file_chunk.file_size = 1u << 20;
    s->file_chunk.length = s->bulk_len;
    s->env.file_chunk = &s->file_chunk;
}

static void make_files_ready(sample *s)
{
    Aafarm__FilesReady m = AAFARM__FILES_READY__INIT;
    s->files_ready = m;
    s->files_ready.job_hash = s->job_hash;
    s->files_ready.hits = 1;
    s->files_ready.misses = 1;
    s->files_ready.fetched_bytes = 1u << 20;
    s->env.files_ready = &s->files_ready;
}

static void make_hello(sample *s)
{
    Aafarm__Hello m = AAFARM__HELLO__INIT;
    s->hello = m;
    s->hello.protocol_version = AAFARM_PROTOCOL_VERSION;
    s->hello.worker_name = "render07-w1";
    s->hello.host = "render07";
    s->hello.pid = 4242;
    s->hello.threads = 8;
    s->jobs_held[0] = s->job_hash;
    s->jobs_held[1] = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
    s->hello.n_jobs_held = 2;
    s->hello.jobs_held = s->jobs_held;
    s->hello.software = "aafarm 0.1.0";
    s->env.hello = &s->hello;
}

static void make_welcome(sample *s)
{
    Aafarm__Welcome m = AAFARM__WELCOME__INIT;
    s->welcome = m;
    s->welcome.protocol_version = AAFARM_PROTOCOL_VERSION;
    s->welcome.master_name = "master@studio";
    s->welcome.master_session = 0x1234567890abcdefull;
    s->welcome.heartbeat_ms = 1000;
    s->welcome.heartbeat_liveness = 3;
    s->env.welcome = &s->welcome;
}

static void make_reject(sample *s)
{
    Aafarm__Reject m = AAFARM__REJECT__INIT;
    s->reject = m;
    s->reject.code = AAFARM__REJECT_CODE__REJECT_CODE_VERSION_MISMATCH;
    s->reject.reason = "master speaks protocol 1, worker 2: upgrade the older side";
    s->reject.protocol_version = AAFARM_PROTOCOL_VERSION;
    s->env.reject = &s->reject;
}

static void make_ask(sample *s)
{
    Aafarm__Ask m = AAFARM__ASK__INIT;
    s->ask = m;
    s->ask.credits = 16;
    s->env.ask = &s->ask;
}

static void make_need_job(sample *s)
{
    Aafarm__NeedJob m = AAFARM__NEED_JOB__INIT;
    s->need_job = m;
    s->need_job.job_hash = s->job_hash;
    s->need_job.lease_id = 77;
    s->env.need_job = &s->need_job;
}

static void make_grant(sample *s)
{
    Aafarm__Grant m = AAFARM__GRANT__INIT;
    Aafarm__Rect r = AAFARM__RECT__INIT;
    s->grant = m;
    s->rect = r;
    s->rect.x = 48;
    s->rect.y = 16;
    s->rect.width = 16;
    s->rect.height = 16;
    s->grant.job_hash = s->job_hash;
    s->grant.lease_id = 0x100000001ull;
    s->grant.tile_index = 7;
    s->grant.tile = &s->rect;
    s->grant.deadline_ms = 60000;
    s->env.grant = &s->grant;
}

static void make_result(sample *s)
{
    Aafarm__Result m = AAFARM__RESULT__INIT;
    Aafarm__TileStats st = AAFARM__TILE_STATS__INIT;
    s->result = m;
    s->stats = st;
    s->stats.rays = 256;
    s->stats.boxes = 174;
    s->stats.shader_evals = 9000;
    s->stats.cache_hits = 120;
    s->stats.cache_misses = 54;
    s->stats.cache_evictions = 3;
    s->stats.peak_cache_bytes = 409600;
    s->stats.cpu_seconds = 1.25;
    s->stats.wall_seconds = 0.5;
    s->result.job_hash = s->job_hash;
    s->result.lease_id = 0x100000001ull;
    s->result.tile_index = 7;
    s->result.stats = &s->stats;
    uint32_t x = 2463534242u; /* xorshift32: bytes that compress badly */
    s->bulk_len = sizeof s->bulk;
    for (size_t i = 0; i < s->bulk_len; i++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        s->bulk[i] = (uint8_t)x;
    }
    s->result.exr_bytes = s->bulk_len;
    s->env.result = &s->result;
}

static void make_failure(sample *s)
{
    Aafarm__Failure m = AAFARM__FAILURE__INIT;
    s->failure = m;
    s->failure.job_hash = s->job_hash;
    s->failure.lease_id = 9;
    s->failure.tile_index = 3;
    s->failure.message = "wave.sl:2:5: error: instruction budget of 1000000 exceeded\n"
                         "    P += amp * sin(10 * u) * normalize(N);\n"
                         "    ^";
    s->failure.retryable = 1;
    s->env.failure = &s->failure;
}

static void make_heartbeat(sample *s)
{
    Aafarm__Heartbeat m = AAFARM__HEARTBEAT__INIT;
    s->heartbeat = m;
    s->leases[0] = 1;
    s->leases[1] = 2;
    s->leases[2] = 0xffffffffffffffffull;
    s->heartbeat.n_leases = 3;
    s->heartbeat.leases = s->leases;
    s->env.heartbeat = &s->heartbeat;
}

static void make_job_done(sample *s)
{
    Aafarm__JobDone m = AAFARM__JOB_DONE__INIT;
    s->job_done = m;
    s->job_done.job_hash = s->job_hash;
    s->job_done.status = AAFARM__JOB_STATUS__JOB_STATUS_FAILED;
    s->job_done.message = "tile 3 failed on 3 workers: instruction budget exceeded";
    s->env.job_done = &s->job_done;
}

static void make_shutdown(sample *s)
{
    Aafarm__Shutdown m = AAFARM__SHUTDOWN__INIT;
    s->shutdown = m;
    s->shutdown.reason = "render finished";
    s->env.shutdown = &s->shutdown;
}

void sample_make(sample *s, proto_kind kind)
{
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    memset(s, 0, sizeof *s);
    s->env = env;
    make_job(s); /* every kind refers to the job's hash */
    s->env.body_case = (Aafarm__Envelope__BodyCase)kind;
    switch (kind) {
    case PROTO_HELLO: make_hello(s); break;
    case PROTO_WELCOME: make_welcome(s); break;
    case PROTO_REJECT: make_reject(s); break;
    case PROTO_ASK: make_ask(s); break;
    case PROTO_JOB: break;
    case PROTO_NEED_JOB: make_need_job(s); break;
    case PROTO_GRANT: make_grant(s); break;
    case PROTO_RESULT: make_result(s); break;
    case PROTO_FAILURE: make_failure(s); break;
    case PROTO_HEARTBEAT: make_heartbeat(s); break;
    case PROTO_JOB_DONE: make_job_done(s); break;
    case PROTO_SHUTDOWN: make_shutdown(s); break;
    case PROTO_NEED_FILE: make_need_file(s); break;
    case PROTO_FILE_CHUNK: make_file_chunk(s); break;
    case PROTO_FILES_READY: make_files_ready(s); break;
    default: fail_msg("sample_make: kind %d", (int)kind);
    }
}

const void *sample_bulk(const sample *s)
{
    return s->bulk_len > 0 ? s->bulk : NULL;
}

uint8_t *sample_pack(const Aafarm__Envelope *env, size_t *len)
{
    *len = aafarm__envelope__get_packed_size(env);
    uint8_t *buf = malloc(*len + 1);
    assert_non_null(buf);
    assert_int_equal(aafarm__envelope__pack(env, buf), *len);
    return buf;
}

/* ---------------------------------------------------------------------- */

void pair_open(sock_pair *p, const char *transport, const proto_limits *limits)
{
    static unsigned serial;
    int timeout = 5000;
    memset(p, 0, sizeof *p);
    p->ctx = zmq_ctx_new();
    assert_non_null(p->ctx);
    p->router = zmq_socket(p->ctx, ZMQ_ROUTER);
    p->dealer = zmq_socket(p->ctx, ZMQ_DEALER);
    assert_non_null(p->router);
    assert_non_null(p->dealer);
    assert_int_equal(wire_socket_setup(p->router, limits, wire_err, sizeof wire_err), 0);
    assert_int_equal(wire_socket_setup(p->dealer, limits, wire_err, sizeof wire_err), 0);
    assert_int_equal(zmq_setsockopt(p->router, ZMQ_RCVTIMEO, &timeout, sizeof timeout), 0);
    assert_int_equal(zmq_setsockopt(p->dealer, ZMQ_RCVTIMEO, &timeout, sizeof timeout), 0);
    if (strcmp(transport, "tcp") == 0) {
        assert_int_equal(zmq_bind(p->router, "tcp://127.0.0.1:*"), 0);
        size_t size = sizeof p->endpoint;
        assert_int_equal(zmq_getsockopt(p->router, ZMQ_LAST_ENDPOINT, p->endpoint, &size), 0);
    } else {
        snprintf(p->endpoint, sizeof p->endpoint, "inproc://proto-test-%u", ++serial);
        assert_int_equal(zmq_bind(p->router, p->endpoint), 0);
    }
    assert_int_equal(zmq_connect(p->dealer, p->endpoint), 0);
}

void pair_close(sock_pair *p)
{
    int linger = 0;
    zmq_setsockopt(p->router, ZMQ_LINGER, &linger, sizeof linger);
    zmq_setsockopt(p->dealer, ZMQ_LINGER, &linger, sizeof linger);
    zmq_close(p->dealer);
    zmq_close(p->router);
    zmq_ctx_term(p->ctx);
    memset(p, 0, sizeof *p);
}

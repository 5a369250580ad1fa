/*
 * tests/proto/test_proto_check.c: the message checks (proto/message.c)
 * and the version rule (proto/version.c).
 *
 *   valid         a sample of every kind passes
 *   each rule     one field of a valid sample broken at a time: refused with
 *                 the exact sentence naming field and problem
 *   limits        the same message passes or fails with tighter limits
 *   versions      proto_version_check's words; a Hello or Welcome of
 *                 another version passes on its frozen fields alone; over a
 *                 socket, a Hello from a newer worker reaches the master,
 *                 whose Reject reaches the worker with the reason in words
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zmq.h>

#include "samples.h"
#include "version.h"

static char err[512];

static int check(const sample *s, const proto_limits *l)
{
    err[0] = '\0';
    return proto_message_check(&s->env, s->bulk_len > 0, s->bulk_len, l, err, sizeof err) ? 0 : -1;
}

static void test_valid_samples(void **state)
{
    (void)state;
    sample *s = malloc(sizeof *s);
    for (size_t k = 0; k < SAMPLE_KINDS; k++) {
        sample_make(s, sample_kinds[k]);
        if (check(s, NULL) != 0)
            fail_msg("%s: %s", proto_message_name(sample_kinds[k]), err);
        assert_int_equal(proto_message_has_bulk(sample_kinds[k]), s->bulk_len > 0);
        /* each kind has at least one side that sends it */
        assert_true(proto_message_from_worker(sample_kinds[k]) ||
                    proto_message_from_master(sample_kinds[k]));
    }
    free(s);
}

/* ---------------------------------------------------------------------- */
/* one broken field at a time                                              */
/* ---------------------------------------------------------------------- */

typedef struct bad_case {
    proto_kind kind;
    int id;              /* which mutation (see mutate) */
    const char *expect;  /* the whole sentence */
} bad_case;

static char long_name[5001];
static const uint8_t scene_with_nul[] = "Format\0 64 32 1\n";

static void mutate(sample *s, int id)
{
    switch (id) {
    case 1: s->hello.worker_name = ""; break;
    case 2: s->hello.host = "render\n07"; break;
    case 3: s->hello.threads = 0; break;
    case 4: s->jobs_held[1] = "ABC"; break;
    case 5: s->hello.protocol_version = 0; break;
    case 6: s->hello.worker_name = long_name; break;
    case 7: s->welcome.master_session = 0; break;
    case 8: s->welcome.heartbeat_ms = 5; break;
    case 9: s->welcome.heartbeat_liveness = 0; break;
    case 10: s->reject.reason = ""; break;
    case 11: s->ask.credits = 0; break;
    case 12: s->job.job_hash = ""; break;
    case 13:
        s->job.scene_text.data = (uint8_t *)scene_with_nul;
        s->job.scene_text.len = sizeof scene_with_nul - 1;
        break;
    case 14: s->source[1].name = "wave.sl"; break;
    case 15: s->job.options = NULL; break;
    case 16: s->options.width = 0; break;
    case 17: s->options.tile_size = 9000; break;
    case 18: s->options.arithmetic = (Aafarm__Arithmetic)7; break;
    case 19: s->binding[1].source = "plastic2.sl"; break;
    case 20: s->layers[1] = "Ci"; break;
    case 21: s->source[0].text.len = 0; break;
    case 22: s->job.scene_name = ""; break;
    case 23: s->binding[1].name = "wave"; break;
    case 24: s->option[1].key = "seed"; break;
    case 25:
        s->need_job.job_hash = "0123456789ABCDEF0123456789ABCDEF0123456789ABCDEF0123456789ABCDEF";
        break;
    case 26: s->grant.lease_id = 0; break;
    case 27: s->grant.tile = NULL; break;
    case 28: s->rect.x = 65530; break;
    case 29: s->rect.y = 4294967295u; break;
    case 30: s->grant.deadline_ms = 0; break;
    case 31: s->result.stats = NULL; break;
    case 32: s->stats.cpu_seconds = NAN; break;
    case 33: s->stats.wall_seconds = -1; break;
    case 34: s->result.exr_bytes = 0; break;
    case 35: s->failure.message = ""; break;
    case 36: s->failure.message = "\x1b[31merror"; break;
    case 37: s->leases[1] = 0; break;
    case 38: s->job_done.status = (Aafarm__JobStatus)9; break;
    case 39: s->job_done.message = ""; break;
    case 40: s->shutdown.reason = "bye\a"; break;
    case 41: s->env.body_case = AAFARM__ENVELOPE__BODY__NOT_SET; break;
    case 42: s->env.ask = NULL; break;
    case 43: s->env.body_case = (Aafarm__Envelope__BodyCase)99; break;
    case 44: s->job.sources[0] = NULL; break;
    case 46: s->job.shaders[1] = NULL; break;
    case 47: s->binding[0].source = ""; break;
    case 45: s->hello.worker_name = NULL; break;
    case 48: s->file_ref[1].name = "maps/height.exr"; break;
    case 49: s->file_ref[0].sha256 = "not a hash"; break;
    case 50: s->need_file.length = 0; break;
    case 51: s->need_file.length = (16u << 20) + 1; break;
    case 52: s->file_chunk.length = 10; break;
    case 53: s->file_chunk.offset = (1u << 20) - 100; break;
    case 54: s->files_ready.job_hash = ""; break;
    default: fail_msg("mutate: no case %d", id);
    }
}

#define K(x) PROTO_##x
static const bad_case bad_cases[] = {
    {K(HELLO), 1, "Hello.worker_name: missing (must not be empty)"},
    {K(HELLO), 2, "Hello.host: control character 0x0a at byte 6"},
    {K(HELLO), 3, "Hello.threads: 0 is outside 1..4096"},
    {K(HELLO), 4, "Hello.jobs_held: not a job hash (64 lowercase hex digits, got 3 bytes)"},
    {K(HELLO), 5, "Hello.protocol_version: missing"},
    {K(HELLO), 6, "Hello.worker_name: 5000 bytes, the limit is 4096"},
    {K(WELCOME), 7, "Welcome.master_session: missing (must not be 0)"},
    {K(WELCOME), 8, "Welcome.heartbeat_ms: 5 is outside 10..3600000"},
    {K(WELCOME), 9, "Welcome.heartbeat_liveness: 0 is outside 1..1000"},
    {K(REJECT), 10, "Reject.reason: missing (must not be empty)"},
    {K(ASK), 11, "Ask.credits: 0 is outside 1..4096"},
    {K(JOB), 12, "Job.job_hash: missing (a job hash is 64 lowercase hex digits)"},
    {K(JOB), 13, "Job.scene_text: NUL byte at offset 6 (source text must be text)"},
    {K(JOB), 14, "Job.sources.name: \"wave.sl\" appears twice"},
    {K(JOB), 15, "Job.options: missing"},
    {K(JOB), 16, "Job.options.width: 0 is outside 1..65536"},
    {K(JOB), 17, "Job.options.tile_size: 9000 is outside 1..8192"},
    {K(JOB), 18, "Job.options.arithmetic: 7 is neither affine (0) nor interval (1)"},
    {K(JOB), 19,
     "Job.shaders.source: \"plastic2.sl\" (for shader \"plastic\") is not among Job.sources"},
    {K(JOB), 20, "Job.options.layers: \"Ci\" appears twice"},
    {K(JOB), 21, "Job.sources.text: missing (must not be empty)"},
    {K(JOB), 22, "Job.scene_name: missing (must not be empty)"},
    {K(JOB), 23, "Job.shaders.name: \"wave\" appears twice"},
    {K(JOB), 24, "Job.options.extra.key: \"seed\" appears twice"},
    {K(JOB), 44, "Job.sources: entry 0 is missing"},
    {K(JOB), 46, "Job.shaders: entry 1 is missing"},
    {K(JOB), 47, "Job.shaders.source: missing (must not be empty)"},
    {K(NEED_JOB), 25, "NeedJob.job_hash: not a job hash (64 lowercase hex digits, got 64 bytes)"},
    {K(GRANT), 26, "Grant.lease_id: missing (must not be 0)"},
    {K(GRANT), 27, "Grant.tile: missing"},
    {K(GRANT), 28, "Grant.tile: right edge x + width = 65546 is beyond the image limit 65536"},
    {K(GRANT), 29,
     "Grant.tile: bottom edge y + height = 4294967311 is beyond the image limit 65536"},
    {K(GRANT), 30, "Grant.deadline_ms: 0 is outside 1..86400000"},
    {K(RESULT), 31, "Result.stats: missing"},
    {K(RESULT), 32, "Result.stats.cpu_seconds: nan is not a finite number of seconds >= 0"},
    {K(RESULT), 33, "Result.stats.wall_seconds: -1 is not a finite number of seconds >= 0"},
    {K(RESULT), 34, "Result.exr_bytes: says 0 but the bulk frame has 3000 bytes"},
    {K(FAILURE), 35, "Failure.message: missing (must not be empty)"},
    {K(FAILURE), 36, "Failure.message: control character 0x1b at byte 0"},
    {K(HEARTBEAT), 37, "Heartbeat.leases: missing (must not be 0)"},
    {K(JOB_DONE), 38, "JobDone.status: 9 is not DONE, FAILED or CANCELLED"},
    {K(JOB_DONE), 39, "JobDone.message: missing (must not be empty)"},
    {K(SHUTDOWN), 40, "Shutdown.reason: control character 0x07 at byte 3"},
    {K(ASK), 41, "Envelope: carries no message (an unknown kind from a newer peer?)"},
    {K(ASK), 42, "Ask: missing"},
    {K(ASK), 43, "Envelope: unknown message kind 99"},
    {K(HELLO), 45, "Hello.worker_name: missing (must not be empty)"},
    {K(JOB), 48, "Job.files.name: \"maps/height.exr\" appears twice"},
    {K(JOB), 49, "Job.files.sha256: not a job hash (64 lowercase hex digits, got 10 bytes)"},
    {K(NEED_FILE), 50, "NeedFile.length: 0 is outside 1..16777216"},
    {K(NEED_FILE), 51, "NeedFile.length: 16777217 is outside 1..16777216"},
    {K(FILE_CHUNK), 52, "FileChunk.length: says 10 but the bulk frame has 3000 bytes"},
    {K(FILE_CHUNK), 53, "FileChunk: bytes 1048476..1051476 lie outside the file of 1048576 bytes"},
    {K(FILES_READY), 54, "FilesReady.job_hash: missing (a job hash is 64 lowercase hex digits)"},
};
#undef K

static void test_each_rule(void **state)
{
    (void)state;
    memset(long_name, 'w', sizeof long_name - 1);
    sample *s = malloc(sizeof *s);
    size_t n = sizeof bad_cases / sizeof bad_cases[0];
    for (size_t i = 0; i < n; i++) {
        const bad_case *c = &bad_cases[i];
        sample_make(s, c->kind);
        assert_int_equal(check(s, NULL), 0);
        mutate(s, c->id);
        if (check(s, NULL) != -1)
            fail_msg("case %d: accepted, expected \"%s\"", c->id, c->expect);
        if (strcmp(err, c->expect) != 0)
            fail_msg("case %d:\n  got      \"%s\"\n  expected \"%s\"", c->id, err, c->expect);
    }
    free(s);
}

/* A short error buffer gets a truncated, terminated sentence. */
static void test_short_error_buffer(void **state)
{
    (void)state;
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_ASK);
    s->ask.credits = 0;
    char small[8];
    memset(small, 'x', sizeof small);
    assert_false(proto_message_check(&s->env, false, 0, NULL, small, sizeof small));
    assert_string_equal(small, "Ask.cre");
    assert_false(proto_message_check(&s->env, false, 0, NULL, NULL, 0));
    free(s);
}

static void test_limits(void **state)
{
    (void)state;
    sample *s = malloc(sizeof *s);
    proto_limits l = proto_limits_default();

    sample_make(s, PROTO_HELLO);
    l.max_list = 2;
    assert_int_equal(check(s, &l), 0);
    l.max_list = 1;
    assert_int_equal(check(s, &l), -1);
    assert_string_equal(err, "Hello.jobs_held: 2 entries, the limit is 1");

    l = proto_limits_default();
    sample_make(s, PROTO_GRANT); /* x + width = 64 */
    l.max_image_side = 64;
    assert_int_equal(check(s, &l), 0);
    l.max_image_side = 63;
    assert_int_equal(check(s, &l), -1);
    assert_string_equal(err, "Grant.tile: right edge x + width = 64 is beyond the image limit 63");

    l = proto_limits_default();
    sample_make(s, PROTO_JOB);
    l.max_text_bytes = s->job.scene_text.len;
    assert_int_equal(check(s, &l), 0);
    l.max_text_bytes--;
    assert_int_equal(check(s, &l), -1);
    char want[128];
    snprintf(want, sizeof want, "Job.scene_text: %zu bytes, the limit is %zu",
             s->job.scene_text.len, s->job.scene_text.len - 1);
    assert_string_equal(err, want);

    l = proto_limits_default();
    sample_make(s, PROTO_RESULT);
    l.max_bulk_bytes = 2999;
    assert_int_equal(check(s, &l), -1);
    assert_string_equal(err, "Result: bulk frame of 3000 bytes, the limit is 2999");
    free(s);
}

/* ---------------------------------------------------------------------- */
/* versions                                                                */
/* ---------------------------------------------------------------------- */

static void test_version_check(void **state)
{
    (void)state;
    char buf[200] = "untouched";
    assert_int_equal(proto_version_check(1, 1, buf, sizeof buf), 0);
    assert_string_equal(buf, "untouched");
    assert_int_equal(proto_version_check(1, 2, buf, sizeof buf), -1);
    assert_string_equal(buf, "master speaks protocol 1, worker 2: upgrade the older side");
    assert_int_equal(proto_version_check(3, 1, buf, sizeof buf), -1);
    assert_string_equal(buf, "master speaks protocol 3, worker 1: upgrade the older side");
    assert_int_equal(proto_version_check(1, 0, buf, sizeof buf), -1);
    assert_string_equal(buf, "the worker sent no protocol version (master 1, worker 0): "
                             "it is not an aafarm worker, or a broken one");
    assert_int_equal(proto_version_check(0, 0, NULL, 0), -1);
    char tiny[7];
    assert_int_equal(proto_version_check(1, 2, tiny, sizeof tiny), -1);
    assert_string_equal(tiny, "master");
}

/* Only the frozen fields of another version's Hello or Welcome are
 * judged, so the mismatch can be answered in words. */
static void test_other_version_passes(void **state)
{
    (void)state;
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_HELLO);
    s->hello.protocol_version = AAFARM_PROTOCOL_VERSION + 1;
    s->hello.worker_name = "";
    s->hello.threads = 0;
    assert_int_equal(check(s, NULL), 0);
    s->hello.protocol_version = AAFARM_PROTOCOL_VERSION;
    assert_int_equal(check(s, NULL), -1);

    sample_make(s, PROTO_WELCOME);
    s->welcome.protocol_version = AAFARM_PROTOCOL_VERSION + 1;
    s->welcome.master_session = 0;
    assert_int_equal(check(s, NULL), 0);
    free(s);
}

/* The first exchange with a newer worker, both sides as the farm will do
 * it: the master reads the Hello, compares, answers with a Reject; the
 * worker reads the Reject and can say why it stops. */
static void test_version_mismatch_exchange(void **state)
{
    (void)state;
    sock_pair p;
    wire_stats up = {0}, down = {0};
    pair_open(&p, "tcp", NULL);
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_HELLO);
    s->hello.protocol_version = AAFARM_PROTOCOL_VERSION + 1;
    assert_int_equal(wire_send_envelope(p.dealer, NULL, NULL, 0, &s->env, NULL, 0, wire_err, sizeof wire_err), 0);

    wire_msg *m = wire_recv(p.router, NULL, &up, 0, wire_err, sizeof wire_err);
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), PROTO_HELLO);
    uint32_t theirs = wire_msg_envelope(m)->hello->protocol_version;
    char reason[200];
    assert_int_equal(proto_version_check(AAFARM_PROTOCOL_VERSION, theirs, reason, sizeof reason),
                     -1);
    Aafarm__Reject reject = AAFARM__REJECT__INIT;
    reject.code = AAFARM__REJECT_CODE__REJECT_CODE_VERSION_MISMATCH;
    reject.reason = reason;
    reject.protocol_version = AAFARM_PROTOCOL_VERSION;
    Aafarm__Envelope env = AAFARM__ENVELOPE__INIT;
    env.body_case = AAFARM__ENVELOPE__BODY_REJECT;
    env.reject = &reject;
    size_t id_len;
    const uint8_t *id = wire_msg_identity(m, &id_len);
    assert_int_equal(wire_send_envelope(p.router, NULL, id, id_len, &env, NULL, 0, wire_err, sizeof wire_err), 0);
    wire_msg_destroy(&m);

    m = wire_recv(p.dealer, NULL, &down, 0, wire_err, sizeof wire_err);
    assert_non_null(m);
    assert_int_equal(wire_msg_kind(m), PROTO_REJECT);
    const Aafarm__Reject *got = wire_msg_envelope(m)->reject;
    assert_int_equal(got->code, AAFARM__REJECT_CODE__REJECT_CODE_VERSION_MISMATCH);
    char want[100];
    snprintf(want, sizeof want, "master speaks protocol %d, worker %d: upgrade the older side",
             AAFARM_PROTOCOL_VERSION, AAFARM_PROTOCOL_VERSION + 1);
    assert_string_equal(got->reason, want);
    assert_int_equal(got->protocol_version, AAFARM_PROTOCOL_VERSION);
    wire_msg_destroy(&m);
    free(s);
    pair_close(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_valid_samples),
        cmocka_unit_test(test_each_rule),
        cmocka_unit_test(test_short_error_buffer),
        cmocka_unit_test(test_limits),
        cmocka_unit_test(test_version_check),
        cmocka_unit_test(test_other_version_passes),
        cmocka_unit_test(test_version_mismatch_exchange),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

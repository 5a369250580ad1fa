/*
 * tests/proto/test_proto_codec.c: the plain messages of message.h against
 * the generated Envelope (proto/codec.c). The wire format does not depend
 * on which side of proto/ built a message:
 *
 *   view+out      every sample kind, viewed as a proto_msg and dressed as
 *                 an Envelope again, packs to the same bytes; its packed
 *                 size and its check agree with the Envelope's
 *   wire          a proto_msg sent with wire_send arrives as the same bytes
 *                 and the same fields (wire_msg_body), in each direction
 *   saved job     proto_saved_job_new's copy outlives the message it was
 *                 made from and packs to the same bytes
 *   NULL strings  a plain message's NULL string goes out as ""
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "samples.h"

/* The Envelope of a proto_msg, packed. */
static uint8_t *pack_msg(const proto_msg *msg, size_t *len)
{
    envelope_out out;
    envelope_out_init(&out, msg);
    uint8_t *b = sample_pack(&out.env, len);
    envelope_out_clear(&out);
    return b;
}

static void test_view_and_back(void **state)
{
    (void)state;
    sample *s = malloc(sizeof *s);
    for (size_t k = 0; k < SAMPLE_KINDS; k++) {
        sample_make(s, sample_kinds[k]);
        size_t len0, len1;
        uint8_t *b0 = sample_pack(&s->env, &len0);
        proto_msg msg;
        void *block;
        assert_true(proto_msg_view(&s->env, &msg, &block));
        assert_int_equal(msg.kind, sample_kinds[k]);
        uint8_t *b1 = pack_msg(&msg, &len1);
        assert_int_equal(len1, len0);
        assert_memory_equal(b1, b0, len0);
        assert_int_equal(proto_msg_packed_size(&msg), len0);
        char err[ERR_LEN] = "";
        assert_true(proto_msg_check(&msg, s->bulk_len > 0, s->bulk_len, NULL, err, sizeof err));
        free(block);
        free(b0);
        free(b1);
    }
    free(s);
}

/* A check that fails says the same words for both forms. */
static void test_check_words(void **state)
{
    (void)state;
    proto_msg msg = {.kind = PROTO_ASK, .ask = {0}};
    char err[ERR_LEN];
    assert_false(proto_msg_check(&msg, false, 0, NULL, err, sizeof err));
    assert_string_equal(err, "Ask.credits: 0 is outside 1..4096");
}

static void test_wire_both_ways(void **state)
{
    (void)state;
    sock_pair p;
    pair_open(&p, "inproc", NULL);
    sample *s = malloc(sizeof *s);
    uint8_t id[256];
    size_t id_len = 0;
    for (int round = 0; round < 2; round++) {   /* round 0: worker kinds (and the id) */
        for (size_t k = 0; k < SAMPLE_KINDS; k++) {
            bool up = round == 0;
            if (up ? !proto_message_from_worker(sample_kinds[k])
                   : !proto_message_from_master(sample_kinds[k]))
                continue;
            sample_make(s, sample_kinds[k]);
            proto_msg msg;
            void *block;
            assert_true(proto_msg_view(&s->env, &msg, &block));
            if (up)
                assert_int_equal(wire_send(p.dealer, NULL, 0, &msg, sample_bulk(s), s->bulk_len,
                                           wire_err, sizeof wire_err), 0);
            else
                assert_int_equal(wire_send(p.router, id, id_len, &msg, sample_bulk(s),
                                           s->bulk_len, wire_err, sizeof wire_err), 0);
            wire_msg *m = wire_recv(up ? p.router : p.dealer, NULL, NULL, 0, wire_err,
                                    sizeof wire_err);
            assert_non_null(m);
            if (up) {
                const uint8_t *who = wire_msg_identity(m, &id_len);
                memcpy(id, who, id_len);
            }
            const proto_msg *got = wire_msg_body(m);
            assert_int_equal(got->kind, sample_kinds[k]);
            size_t len0, len1;
            uint8_t *b0 = sample_pack(&s->env, &len0), *b1 = pack_msg(got, &len1);
            assert_int_equal(len1, len0);
            assert_memory_equal(b1, b0, len0);
            if (got->kind == PROTO_JOB) {
                assert_int_equal(got->job.n_sources, msg.job.n_sources);
                assert_string_equal(got->job.sources[0].name, msg.job.sources[0].name);
                assert_int_equal(got->job.options.width, msg.job.options.width);
            }
            if (got->kind == PROTO_GRANT)
                assert_int_equal(got->grant.tile.width, msg.grant.tile.width);
            free(b0);
            free(b1);
            free(block);
            wire_msg_destroy(&m);
        }
    }
    free(s);
    pair_close(&p);
}

static void test_saved_job(void **state)
{
    (void)state;
    sample *s = malloc(sizeof *s);
    sample_make(s, PROTO_JOB);
    size_t len0, len1;
    uint8_t *b0 = sample_pack(&s->env, &len0);
    proto_msg msg;
    void *block;
    assert_true(proto_msg_view(&s->env, &msg, &block));
    proto_saved_job *saved = proto_saved_job_new(&msg.job);
    free(block);
    memset(s, 0x5a, sizeof *s);   /* the original is gone */
    free(s);
    proto_msg copy = {.kind = PROTO_JOB, .job = *proto_saved_job_get(saved)};
    uint8_t *b1 = pack_msg(&copy, &len1);
    assert_int_equal(len1, len0);
    assert_memory_equal(b1, b0, len0);
    proto_saved_job_destroy(&saved);
    assert_null(saved);
    proto_saved_job_destroy(&saved);   /* NULL: nothing */
    free(b0);
    free(b1);
}

static void test_null_strings(void **state)
{
    (void)state;
    proto_msg msg = {.kind = PROTO_SHUTDOWN, .shutdown = {NULL}};
    envelope_out out;
    envelope_out_init(&out, &msg);
    assert_string_equal(out.env.shutdown->reason, "");
    envelope_out_clear(&out);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_view_and_back),
        cmocka_unit_test(test_check_words),
        cmocka_unit_test(test_wire_both_ways),
        cmocka_unit_test(test_saved_job),
        cmocka_unit_test(test_null_strings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

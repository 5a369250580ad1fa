/*
 * tests/proto/test_proto_sha256.c: SHA-256 and the generic job hash
 * (common/util/hash.c), which name jobs on the wire.
 *
 *   vectors       the FIPS 180-4 / NIST examples: "abc", "", the 448-bit
 *                 and 896-bit messages, one million 'a'
 *   incremental   every split of a message into two updates, byte-at-a-time
 *                 and odd chunk sizes give the one-shot digest; lengths
 *                 around the 55/56/64-byte padding boundaries agree
 *   hex           hash_hex spelling, hash_hex_valid accepts only its output
 *   hash_job      canonical encoding written out by hand, order
 *                 independence, injectivity at field boundaries, refusals
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "util/hash.h"

static const char *hex_of(const void *data, size_t len)
{
    static char hex[HASH_HEX_SIZE];
    uint8_t d[SHA256_DIGEST_SIZE];
    sha256_digest(data, len, d);
    hash_hex(d, hex);
    return hex;
}

static const char msg448[] = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
static const char msg896[] = "abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmn"
                             "hijklmnoijklmnopjklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu";

static void test_vectors(void **state)
{
    (void)state;
    assert_string_equal(hex_of("abc", 3),
                        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    assert_string_equal(hex_of("", 0),
                        "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    assert_int_equal(strlen(msg448) * 8, 448);
    assert_string_equal(hex_of(msg448, strlen(msg448)),
                        "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
    assert_int_equal(strlen(msg896) * 8, 896);
    assert_string_equal(hex_of(msg896, strlen(msg896)),
                        "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
}

static void test_million_a(void **state)
{
    (void)state;
    const char *want = "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0";
    char *a = malloc(1000000);
    memset(a, 'a', 1000000);
    assert_string_equal(hex_of(a, 1000000), want);

    /* the same in chunks of 1, 7, 63, 64, 65 and 1000 bytes */
    static const size_t chunks[] = {1, 7, 63, 64, 65, 1000};
    for (size_t c = 0; c < sizeof chunks / sizeof chunks[0]; c++) {
        sha256 ctx;
        sha256_init(&ctx);
        for (size_t done = 0; done < 1000000;) {
            size_t n = chunks[c] < 1000000 - done ? chunks[c] : 1000000 - done;
            sha256_update(&ctx, a + done, n);
            done += n;
        }
        uint8_t d[SHA256_DIGEST_SIZE];
        char hex[HASH_HEX_SIZE];
        sha256_final(&ctx, d);
        hash_hex(d, hex);
        assert_string_equal(hex, want);
    }
    free(a);
}

static void test_every_split(void **state)
{
    (void)state;
    size_t len = strlen(msg896);
    char whole[HASH_HEX_SIZE];
    strcpy(whole, hex_of(msg896, len));
    for (size_t cut = 0; cut <= len; cut++) {
        sha256 ctx;
        sha256_init(&ctx);
        sha256_update(&ctx, msg896, cut);
        sha256_update(&ctx, msg896 + cut, len - cut);
        uint8_t d[SHA256_DIGEST_SIZE];
        char hex[HASH_HEX_SIZE];
        sha256_final(&ctx, d);
        hash_hex(d, hex);
        assert_string_equal(hex, whole);
    }
}

/* Lengths 0..200 (every padding case: the length field fits in the last
 * block or needs one more) hashed one-shot and byte at a time agree, and
 * no two of these prefixes collide. */
static void test_padding_boundaries(void **state)
{
    (void)state;
    uint8_t buf[200];
    for (size_t i = 0; i < sizeof buf; i++)
        buf[i] = (uint8_t)(i * 37 + 11);
    static char seen[201][HASH_HEX_SIZE];
    for (size_t len = 0; len <= sizeof buf; len++) {
        sha256 ctx;
        sha256_init(&ctx);
        for (size_t i = 0; i < len; i++)
            sha256_update(&ctx, buf + i, 1);
        uint8_t d[SHA256_DIGEST_SIZE];
        sha256_final(&ctx, d);
        hash_hex(d, seen[len]);
        assert_string_equal(seen[len], hex_of(buf, len));
        for (size_t j = 0; j < len; j++)
            assert_string_not_equal(seen[j], seen[len]);
    }
}

static void test_hex(void **state)
{
    (void)state;
    uint8_t d[SHA256_DIGEST_SIZE];
    for (int i = 0; i < SHA256_DIGEST_SIZE; i++)
        d[i] = (uint8_t)(i * 8 + 1);
    char hex[HASH_HEX_SIZE];
    hash_hex(d, hex);
    assert_string_equal(hex, "0109111921293139414951596169717981899199a1a9b1b9c1c9d1d9e1e9f1f9");
    assert_true(hash_hex_valid(hex));
    assert_false(hash_hex_valid(NULL));
    assert_false(hash_hex_valid(""));
    hex[10] = 'A';
    assert_false(hash_hex_valid(hex)); /* upper case */
    hex[10] = 'g';
    assert_false(hash_hex_valid(hex));
    hex[10] = '9';
    hex[63] = '\0';
    assert_false(hash_hex_valid(hex)); /* 63 digits */
    char longer[HASH_HEX_SIZE + 1];
    hash_hex(d, longer);
    longer[64] = '0';
    longer[65] = '\0';
    assert_false(hash_hex_valid(longer)); /* 65 digits */
}

/* ---------------------------------------------------------------------- */
/* hash_job                                                                */
/* ---------------------------------------------------------------------- */

static void put(sha256 *ctx, char tag, const char *s, size_t len)
{
    uint8_t head[9] = {(uint8_t)tag, 0, 0, 0, 0, 0, 0, 0, 0};
    head[7] = (uint8_t)(len >> 8);
    head[8] = (uint8_t)len;
    sha256_update(ctx, head, 9);
    sha256_update(ctx, s, len);
}

static void test_hash_job_encoding(void **state)
{
    (void)state;
    hash_shader shaders[] = {{"b.sl", "surface b() {}", 14}, {"a.sl", "displacement a() {}", 19}};
    hash_option options[] = {{"width", "64"}, {"arith", "affine"}};
    hash_job_input job = {"s.rib", "WorldBegin WorldEnd", 19, shaders, 2, options, 2};
    char got[HASH_HEX_SIZE];
    assert_int_equal(hash_job(&job, got), 0);

    sha256 ctx;
    sha256_init(&ctx);
    sha256_update(&ctx, "aafarm-job-v1", 13);
    put(&ctx, 'N', "s.rib", 5);
    put(&ctx, 'S', "WorldBegin WorldEnd", 19);
    put(&ctx, 'n', "a.sl", 4);
    put(&ctx, 't', "displacement a() {}", 19);
    put(&ctx, 'n', "b.sl", 4);
    put(&ctx, 't', "surface b() {}", 14);
    put(&ctx, 'k', "arith", 5);
    put(&ctx, 'v', "affine", 6);
    put(&ctx, 'k', "width", 5);
    put(&ctx, 'v', "64", 2);
    uint8_t d[SHA256_DIGEST_SIZE];
    char want[HASH_HEX_SIZE];
    sha256_final(&ctx, d);
    hash_hex(d, want);
    assert_string_equal(got, want);

    /* input order does not matter */
    hash_shader shaders2[] = {shaders[1], shaders[0]};
    hash_option options2[] = {options[1], options[0]};
    hash_job_input job2 = {"s.rib", "WorldBegin WorldEnd", 19, shaders2, 2, options2, 2};
    char again[HASH_HEX_SIZE];
    assert_int_equal(hash_job(&job2, again), 0);
    assert_string_equal(again, got);
}

/* Moving bytes across a field boundary changes the hash. */
static void test_hash_job_injective(void **state)
{
    (void)state;
    char h1[HASH_HEX_SIZE], h2[HASH_HEX_SIZE], h3[HASH_HEX_SIZE];
    hash_option o1[] = {{"ab", "c"}}, o2[] = {{"a", "bc"}};
    hash_job_input j1 = {"s", "x", 1, NULL, 0, o1, 1};
    hash_job_input j2 = {"s", "x", 1, NULL, 0, o2, 1};
    assert_int_equal(hash_job(&j1, h1), 0);
    assert_int_equal(hash_job(&j2, h2), 0);
    assert_string_not_equal(h1, h2);

    hash_job_input n1 = {"sx", "", 0, NULL, 0, NULL, 0};
    hash_job_input n2 = {"s", "x", 1, NULL, 0, NULL, 0};
    assert_int_equal(hash_job(&n1, h1), 0);
    assert_int_equal(hash_job(&n2, h2), 0);
    assert_string_not_equal(h1, h2);

    /* a shader and an option with the same strings are different things */
    hash_shader sh[] = {{"k", "v", 1}};
    hash_option op[] = {{"k", "v"}};
    hash_job_input s1 = {"s", "x", 1, sh, 1, NULL, 0};
    hash_job_input s2 = {"s", "x", 1, NULL, 0, op, 1};
    assert_int_equal(hash_job(&s1, h1), 0);
    assert_int_equal(hash_job(&s2, h2), 0);
    assert_int_equal(hash_job(&n2, h3), 0);
    assert_string_not_equal(h1, h2);
    assert_string_not_equal(h1, h3);
    assert_string_not_equal(h2, h3);
}

static void test_hash_job_refusals(void **state)
{
    (void)state;
    char h[HASH_HEX_SIZE] = "untouched";
    hash_shader dup[] = {{"a.sl", "x", 1}, {"a.sl", "y", 1}};
    hash_option dupo[] = {{"k", "1"}, {"k", "2"}};
    hash_option nullv[] = {{"k", NULL}};
    hash_shader nulln[] = {{NULL, "x", 1}};
    hash_job_input j = {"s", "x", 1, dup, 2, NULL, 0};
    assert_int_equal(hash_job(&j, h), -1);
    j = (hash_job_input){"s", "x", 1, NULL, 0, dupo, 2};
    assert_int_equal(hash_job(&j, h), -1);
    j = (hash_job_input){"s", "x", 1, NULL, 0, nullv, 1};
    assert_int_equal(hash_job(&j, h), -1);
    j = (hash_job_input){"s", "x", 1, nulln, 1, NULL, 0};
    assert_int_equal(hash_job(&j, h), -1);
    j = (hash_job_input){NULL, "x", 1, NULL, 0, NULL, 0};
    assert_int_equal(hash_job(&j, h), -1);
    j = (hash_job_input){"s", NULL, 1, NULL, 0, NULL, 0};
    assert_int_equal(hash_job(&j, h), -1);
    assert_int_equal(hash_job(NULL, h), -1);
    assert_string_equal(h, "untouched");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_vectors),
        cmocka_unit_test(test_million_a),
        cmocka_unit_test(test_every_split),
        cmocka_unit_test(test_padding_boundaries),
        cmocka_unit_test(test_hex),
        cmocka_unit_test(test_hash_job_encoding),
        cmocka_unit_test(test_hash_job_injective),
        cmocka_unit_test(test_hash_job_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

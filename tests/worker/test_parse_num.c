/*
 * test_parse_num.c: the command lines' number parser (common/util/parse_num):
 * the syntax aafarm-master, aafarm-worker and aafarm-maketx accept (whole
 * numbers as strtol reads them, byte counts with K/M/G and an optional B),
 * the bounds (both ends in, one past refused), garbage refused with *out
 * left alone, and the message the tools print, naming both bounds (issue
 * 27: --budget above 1e9 used to say only ">= 1000").
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "util/err.h"
#include "util/parse_num.h"

static void test_whole_numbers(void **state)
{
    (void)state;
    static const struct { const char *text; long lo, hi; bool ok; long want; } cases[] = {
        {"12", 1, 100, true, 12},
        {"1", 1, 100, true, 1},          /* both bounds are in */
        {"100", 1, 100, true, 100},
        {"0", 1, 100, false, 0},         /* one past either is not */
        {"101", 1, 100, false, 0},
        {" 7", 0, 10, true, 7},          /* strtol's leading blanks and sign */
        {"+7", 0, 10, true, 7},
        {"-3", -5, 5, true, -3},
        {"-3", 0, 5, false, 0},
        {"7 ", 0, 10, false, 0},         /* nothing after the digits */
        {"7x", 0, 10, false, 0},
        {"1.5", 0, 10, false, 0},
        {"0x10", 0, 100, false, 0},      /* decimal only */
        {"", 0, 10, false, 0},
        {" ", 0, 10, false, 0},
        {"-", 0, 10, false, 0},
        {"lots", 0, 10, false, 0},
        {"99999999999999999999999", 0, 1000000000L, false, 0},   /* past long */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        long v = -42;
        bool ok = parse_long_within(cases[i].text, cases[i].lo, cases[i].hi, &v);
        if (ok != cases[i].ok) fail_msg("'%s' in %ld..%ld: %s", cases[i].text, cases[i].lo,
                                        cases[i].hi, ok ? "accepted" : "refused");
        assert_int_equal(v, ok ? cases[i].want : -42);   /* untouched when refused */
    }
}

static void test_byte_counts(void **state)
{
    (void)state;
    static const struct { const char *text; bool ok; size_t want; } cases[] = {
        {"0", true, 0},
        {"123", true, 123},
        {"123B", true, 123},
        {"40K", true, 40 << 10},
        {"40k", true, 40 << 10},
        {"4M", true, 4 << 20},
        {"4mb", true, 4 << 20},
        {"4MB", true, 4 << 20},
        {"2G", true, (size_t)2 << 30},
        {"2gB", true, (size_t)2 << 30},
        {"1.5K", true, 1536},
        {"1e3", true, 1000},
        {"", false, 0},
        {"K", false, 0},
        {"B", false, 0},
        {"lots", false, 0},
        {"-1", false, 0},
        {"4X", false, 0},
        {"4KK", false, 0},
        {"4 M", false, 0},
        {"4M ", false, 0},
        {"inf", false, 0},
        {"nan", false, 0},
        {"1e30G", false, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        size_t v = 42;
        bool ok = parse_byte_count(cases[i].text, &v);
        if (ok != cases[i].ok)
            fail_msg("'%s': %s", cases[i].text, ok ? "accepted" : "refused");
        assert_true(v == (ok ? cases[i].want : 42));
    }
}

static void test_option_messages_name_both_bounds(void **state)
{
    (void)state;
    char err[ERR_LEN] = "";
    long n = 0;
    assert_true(parse_option_long("--budget", "a number", "5000", 1000, 1000000000L, &n, err,
                                  sizeof err));
    assert_int_equal(n, 5000);
    assert_false(parse_option_long("--budget", "a number", "2000000000", 1000, 1000000000L, &n,
                                   err, sizeof err));
    assert_string_equal(err, "--budget wants a number 1000..1000000000, got '2000000000'");
    assert_false(parse_option_long("--budget", "a number", "999", 1000, 1000000000L, &n, err,
                                   sizeof err));
    assert_string_equal(err, "--budget wants a number 1000..1000000000, got '999'");
    assert_false(parse_option_long("--liveness", NULL, "x", 1, 1000, &n, err, sizeof err));
    assert_string_equal(err, "--liveness wants 1..1000, got 'x'");
    assert_false(parse_option_long("--tile-delay", "milliseconds", "-1", 0, 600000, &n, err,
                                   sizeof err));
    assert_string_equal(err, "--tile-delay wants milliseconds 0..600000, got '-1'");
    assert_int_equal(n, 5000);
    /* no buffer: the answer alone */
    assert_false(parse_option_long("--tile", "a size", "0", 1, 1024, &n, NULL, 0));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_whole_numbers),
        cmocka_unit_test(test_byte_counts),
        cmocka_unit_test(test_option_messages_name_both_bounds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

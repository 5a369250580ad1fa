/*
 * test_scene_numbers.c: the RIB lexer's numbers (rib_lexer.c reads most
 * of them without strtod, by the exact fast path): every number it reads
 * is the double strtod gives, bit for bit, over hand-picked edges (the
 * 15-digit and 10^22 borders, signed zeros, leading zeros, long
 * fractions) and 300,000 random numbers of the forms exporters write.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/rib_lexer.h"

/* The lexer's value of the one number in s, against strtod's. */
static void check_one(const char *s)
{
    rib_lexer *lx = rib_lexer_new("n.rib", s, strlen(s));
    rib_token t = rib_lexer_next(lx);
    if (t.kind != RIB_TOK_NUMBER)
        fail_msg("'%s' is not read as a number", s);
    double want = strtod(s, NULL);
    if (memcmp(&t.number, &want, sizeof want) != 0)
        fail_msg("'%s': the lexer reads %.17g, strtod %.17g", s, t.number, want);
    rib_lexer_destroy(&lx);
}

static void test_edges(void **state)
{
    (void)state;
    static const char *const cases[] = {
        "0", "-0", "+0", "0.0", "-0.0", ".5", "-.5", "5.", "007", "0.40", "1.00",
        "123456789012345", "1234567890123456", "12345678901234567890", "9007199254740993",
        "0.000000000000000000001", "0.1234567890123456789", "1e22", "1e23", "1e-22", "1e-23",
        "123456789012345e7", "123456789012345e8", "1.5e-7", "4.35", "0.3", "2.675",
        "-33", "157", "260", "1E5", "1e+5", "1e-0", "0e999", "1e308", "4.9e-324",
        "99999999999999.9", "0.999999999999999", "3.141592653589793",
        "00000000000000000000001.5", "1.000000000000000000001",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        check_one(cases[i]);
}

static void test_random(void **state)
{
    (void)state;
    srand(23);
    char s[128];
    for (int k = 0; k < 300000; k++) {
        int n = 0;
        if (rand() % 3 == 0) s[n++] = rand() % 2 ? '-' : '+';
        int whole = rand() % 12, frac = rand() % 2 ? rand() % 20 : 0;
        if (whole == 0 && frac == 0) whole = 1;
        for (int i = 0; i < whole; i++) s[n++] = (char)('0' + rand() % 10);
        if (frac > 0 || rand() % 4 == 0) {
            s[n++] = '.';
            for (int i = 0; i < frac; i++) s[n++] = (char)('0' + (rand() % 3 ? rand() % 10 : 0));
        }
        if (rand() % 4 == 0)
            n += snprintf(s + n, sizeof s - (size_t)n, "e%d", rand() % 61 - 30);
        s[n] = '\0';
        check_one(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_random),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_scene_numbers.c: the RIB lexer's numbers (rib_lexer.c reads most
 * of them without strtod, by the exact fast path): every number it reads
 * is the double strtod gives, bit for bit, over hand-picked edges (the
 * 15-digit and 10^22 borders, signed zeros, leading zeros, long
 * fractions) and 300,000 random numbers of the forms exporters write;
 * and (rib_lexer.c reads a number's syntax and value in one pass) which
 * words are numbers at all: 200,000 random words of digits, signs, points,
 * exponents and letters, each followed by a random delimiter, against the
 * RIB number syntax as a POSIX regular expression: a word it matches is
 * one number token (strtod's value, or "out of range" where strtod
 * overflows), any other one bad token naming the whole word, and the
 * delimiter after it is the next token; the same through the tokenless
 * read of long arrays (rib_lexer_next_number), which must take only the
 * numbers it reads right.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <regex.h>
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

/* word (its bytes are no delimiter) then delim (a delimiter or ""): the
 * lexer's first token against the oracle, then the token after it. */
static void check_word(const regex_t *syntax, const char *word, const char *delim, bool bulk)
{
    char text[160];
    snprintf(text, sizeof text, "%s%s", word, delim);
    rib_lexer *lx = rib_lexer_new("n.rib", text, strlen(text));
    bool number = regexec(syntax, word, 0, NULL, 0) == 0;
    double want = number ? strtod(word, NULL) : 0;
    rib_token t = {0};
    if (bulk && rib_lexer_next_number(lx, &t.number)) {
        /* the tokenless read (long arrays) takes only numbers it reads
         * right, and leaves every other word to rib_lexer_next */
        t.kind = RIB_TOK_NUMBER;
        t.pos.line = t.pos.col = 1;
        if (!number || !isfinite(want))
            fail_msg("'%s' (before '%s') is read as a number by rib_lexer_next_number", word,
                     delim);
    } else {
        t = rib_lexer_next(lx);
    }
    char msg[256];
    if (number && isfinite(want)) {
        if (t.kind != RIB_TOK_NUMBER)
            fail_msg("'%s' (before '%s') is a number, the lexer says %s", word, delim,
                     t.kind == RIB_TOK_BAD ? t.error : "another kind");
        if (memcmp(&t.number, &want, sizeof want) != 0)
            fail_msg("'%s': the lexer reads %.17g, strtod %.17g", word, t.number, want);
    } else {
        if (number)
            snprintf(msg, sizeof msg, "number '%s' is out of range", word);
        else
            snprintf(msg, sizeof msg, "bad number '%s'", word);
        if (t.kind != RIB_TOK_BAD || strcmp(t.error, msg) != 0)
            fail_msg("'%s' (before '%s'): want \"%s\", the lexer says %s", word, delim, msg,
                     t.kind == RIB_TOK_BAD ? t.error : "a number");
    }
    if (t.pos.line != 1 || t.pos.col != 1)
        fail_msg("'%s': the token is at %d:%d, not 1:1", word, t.pos.line, t.pos.col);
    t = rib_lexer_next(lx);
    rib_token_kind after = delim[0] == '[' ? RIB_TOK_LBRACKET
                         : delim[0] == ']' ? RIB_TOK_RBRACKET
                         : delim[0] == '"' ? RIB_TOK_BAD      /* an unterminated string */
                                           : RIB_TOK_EOF;     /* "", space, comment */
    if (t.kind != after)
        fail_msg("'%s' then '%s': the next token is of kind %d, want %d", word, delim,
                 (int)t.kind, (int)after);
    rib_lexer_destroy(&lx);
}

static void test_words(void **state)
{
    (void)state;
    regex_t syntax;
    /* RI Specification C.1: [+-] digits [. digits] [e [+-] digits], digits
     * on at least one side of the point */
    int rc = regcomp(&syntax, "^[+-]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][+-]?[0-9]+)?$",
                     REG_EXTENDED | REG_NOSUB);
    assert_int_equal(rc, 0);
    static const char *const delims[] = {"", " ", "]", "[", "\"", "#c", "\n", "\t"};
    static const char *const fixed[] = {
        "1.2.3", "12abc", "1e", "1e+", "1e-", "+", "-", ".", "+.", "-.e5", ".e5", "1e5e",
        "1e5.", "1..2", "--1", "+-1", "1-", "1+2", "0x10", "1f", "1e999", "-1e999", "1e-999",
        "5.", ".5", "1E+05", "1e0005", "007.700e-02", "1ee5", "1e5x", "9q",
    };
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        for (size_t d = 0; d < sizeof delims / sizeof delims[0]; d++)
            for (int bulk = 0; bulk < 2; bulk++)
                check_word(&syntax, fixed[i], delims[d], bulk);
    /* a number starts with a digit, a sign or a point (other words are
     * names); the rest mostly number bytes, a few letters */
    static const char first[] = "0123456789+-.";
    static const char rest[] = "0123456789012345678901234567890123456789..+-eEeExq_";
    srand(2323);
    char w[32];
    for (int k = 0; k < 200000; k++) {
        int n = 1 + rand() % 12;
        w[0] = first[rand() % (int)(sizeof first - 1)];
        for (int i = 1; i < n; i++) w[i] = rest[rand() % (int)(sizeof rest - 1)];
        w[n] = '\0';
        check_word(&syntax, w, delims[rand() % (int)(sizeof delims / sizeof delims[0])], k % 2);
    }
    regfree(&syntax);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_random),
        cmocka_unit_test(test_words),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

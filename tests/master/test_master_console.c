/*
 * test_master_console.c: the master's aggregated warnings
 * (master/console.h, console_tally): the first batch is said at once,
 * later ones at most once per interval as one line with their count and
 * the first few tiles ("3 leases passed their deadlines in the last 10 s
 * (tiles 4, 9, 17) ..."); the rest of the tiles is counted, nothing is
 * lost at the end (force), and the line goes to stderr with the
 * program's prefix. The log tail of the live monitor keeps the last
 * CONSOLE_TAIL lines at INFO and ERROR, also under -q, oldest first.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "console.h"

static const char *detail = "without a result: back in the queue";

static void test_tally_counts_and_interval(void **state)
{
    (void)state;
    console *con = console_new(-1, false);   /* -q: the lines are not printed */
    console_tally t;
    console_tally_init(&t, "lease passed its deadline", "leases passed their deadlines", detail,
                       10000);
    char line[600];
    assert_false(console_tally_format(&t, 0, line, sizeof line));
    assert_false(console_tally_flush(&t, con, 0, false));   /* nothing counted */

    console_tally_add(&t, 4, NULL);   /* the first one: said at once */
    assert_true(console_tally_format(&t, 1000, line, sizeof line));
    assert_string_equal(line, "1 lease passed its deadline (tile 4) without a result: back in "
                              "the queue");
    assert_true(console_tally_flush(&t, con, 1000, false));

    console_tally_add(&t, 9, NULL);   /* within the interval: counted */
    assert_false(console_tally_flush(&t, con, 2000, false));
    console_tally_add(&t, 17, NULL);
    console_tally_add(&t, 21, NULL);
    assert_false(console_tally_flush(&t, con, 10999, false));
    assert_true(console_tally_format(&t, 11000, line, sizeof line));
    assert_string_equal(line, "3 leases passed their deadlines in the last 10 s (tiles 9, 17, "
                              "21) without a result: back in the queue");
    assert_true(console_tally_flush(&t, con, 11000, false));   /* one line for the three */
    assert_false(console_tally_format(&t, 11000, line, sizeof line));
    assert_false(console_tally_flush(&t, con, 30000, false));   /* said: nothing left */

    /* a batch long after: said at once, with the time since the last line */
    console_tally_add(&t, 2, NULL);
    assert_true(console_tally_format(&t, 41000, line, sizeof line));
    assert_string_equal(line, "1 lease passed its deadline in the last 30 s (tile 2) without a "
                              "result: back in the queue");
    assert_true(console_tally_flush(&t, con, 41000, false));
    console_destroy(&con);
}

static void test_tally_cuts_the_tile_list(void **state)
{
    (void)state;
    console *con = console_new(-1, false);
    console_tally t;
    console_tally_init(&t, "lease passed its deadline", "leases passed their deadlines", detail,
                       10000);
    console_tally_add(&t, 0, NULL);
    assert_true(console_tally_flush(&t, con, 0, false));
    for (int i = 0; i < 12; i++) console_tally_add(&t, 100 + i, NULL);
    char line[600];
    assert_true(console_tally_format(&t, 500, line, sizeof line));
    assert_string_equal(line, "12 leases passed their deadlines in the last 0.5 s (tiles 100, 101, "
                              "102, 103, 104 and 7 more) without a result: back in the queue");
    /* the end of the render: said even within the interval */
    assert_true(console_tally_flush(&t, con, 500, true));
    /* events without a tile, and a detail of the last event */
    console_tally_add(&t, -1, ": the first");
    console_tally_add(&t, -1, ": the last");
    assert_true(console_tally_format(&t, 20500, line, sizeof line));
    assert_string_equal(line, "2 leases passed their deadlines in the last 20 s: the last");
    console_destroy(&con);
}

/* The line reaches stderr once, with the program's prefix. */
static void test_tally_prints_one_line(void **state)
{
    (void)state;
    char path[] = "/tmp/test_master_console_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    fflush(stderr);
    int saved = dup(STDERR_FILENO);
    dup2(fd, STDERR_FILENO);
    console *con = console_new(0, false);
    console_tally t;
    console_tally_init(&t, "lease passed its deadline", "leases passed their deadlines", detail,
                       10000);
    for (int now = 0; now <= 10000; now += 100) {   /* one a tick for 10 s: two lines */
        console_tally_add(&t, now / 100, NULL);
        console_tally_flush(&t, con, now, false);
    }
    console_destroy(&con);
    fflush(stderr);
    dup2(saved, STDERR_FILENO);
    close(saved);
    char text[4096] = "";
    ssize_t n = pread(fd, text, sizeof text - 1, 0);
    close(fd);
    unlink(path);
    assert_true(n > 0);
    text[n] = '\0';
    assert_string_equal(text,
        "aafarm-master: 1 lease passed its deadline (tile 0) without a result: back in the queue\n"
        "aafarm-master: 100 leases passed their deadlines in the last 10 s (tiles 1, 2, 3, 4, 5 "
        "and 95 more) without a result: back in the queue\n");
}

static void test_tail_keeps_the_last_lines(void **state)
{
    (void)state;
    FILE *saved = stderr;
    stderr = fopen("/dev/null", "w");   /* -q: nothing printed, all kept */
    console *con = console_new(-1, false);
    assert_int_equal(console_tail_count(con), 0);
    assert_string_equal(console_tail_line(con, 0), "");
    for (int i = 0; i < CONSOLE_TAIL + 5; i++)
        console_log(con, i % 2 ? CONSOLE_ERROR : CONSOLE_INFO, "line %d", i);
    console_log(con, CONSOLE_DETAIL, "a detail is not kept");
    assert_int_equal(console_tail_count(con), CONSOLE_TAIL);
    assert_string_equal(console_tail_line(con, 0), "line 5");
    char last[32];
    snprintf(last, sizeof last, "line %d", CONSOLE_TAIL + 4);
    assert_string_equal(console_tail_line(con, CONSOLE_TAIL - 1), last);
    assert_string_equal(console_tail_line(con, CONSOLE_TAIL), "");
    console_destroy(&con);
    fclose(stderr);
    stderr = saved;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tally_counts_and_interval),
        cmocka_unit_test(test_tally_cuts_the_tile_list),
        cmocka_unit_test(test_tally_prints_one_line),
        cmocka_unit_test(test_tail_keeps_the_last_lines),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * death.h: death tests, the check that an assert (or an out-of-memory
 * abort) is live. death_run forks, runs fn(arg) in the child with its
 * stderr captured, and reports whether the child died of SIGABRT with
 * `expect` in what it printed. Every module with invariants has one death
 * test that trips an assert on purpose (docs/conventions.md), so a build
 * that compiled its asserts away fails the suite instead of passing it.
 *
 * Use it before any thread is started in the test process.
 */
#ifndef TESTS_DEATH_H
#define TESTS_DEATH_H

#include <stdbool.h>

/* True when fn(arg) aborted (SIGABRT) and its stderr holds expect (NULL:
 * any message). On false, why says what happened instead (exit status,
 * signal, what it printed). */
bool death_run(void (*fn)(void *), void *arg, const char *expect, char *why, int whylen);

/* cmocka form: fails the test with death_run's reason. */
#define assert_death(fn, arg, expect)                                        \
    do {                                                                     \
        char death_why_[2048];                                               \
        if (!death_run((fn), (arg), (expect), death_why_, sizeof death_why_)) \
            fail_msg("%s", death_why_);                                      \
    } while (0)

/* The other side of xalloc.h's try_*: fn(arg) runs in a forked child whose
 * address space is limited to what it already has plus `headroom` bytes,
 * so a large allocation really fails. fn returns 0 when it met that
 * failure as it should (an error message, not an abort). True when the
 * child exited 0; else why says how it ended. (ASan builds: the test sets
 * ASAN_OPTIONS=allocator_may_return_null=1 through __asan_default_options.) */
bool starved_run(int (*fn)(void *), void *arg, unsigned long headroom, char *why, int whylen);

#define assert_starved_ok(fn, arg, headroom)                                        \
    do {                                                                            \
        char starved_why_[512];                                                     \
        if (!starved_run((fn), (arg), (headroom), starved_why_, sizeof starved_why_)) \
            fail_msg("%s", starved_why_);                                           \
    } while (0)

#endif

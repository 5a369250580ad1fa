/*
 * tests/fuzz/fuzz_target.h: the one function every fuzz target defines,
 * libFuzzer's entry point. The same target file links either with
 * libFuzzer (-DAAFARM_FUZZ=ON, clang: the fuzzer) or with replay.c (the
 * normal build: CTest replays the seed corpus and the regression inputs).
 * A target returns 0 and aborts (assert-style, through fuzz_check) when an
 * invariant fails, so that both drivers report the input.
 */
#ifndef TESTS_FUZZ_TARGET_H
#define TESTS_FUZZ_TARGET_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* An invariant of the code under test; a failure is a finding. */
#define fuzz_check(cond)                                                          \
    do {                                                                          \
        if (!(cond)) {                                                            \
            fprintf(stderr, "%s:%d: fuzz invariant failed: %s\n", __FILE__,       \
                    __LINE__, #cond);                                             \
            abort();                                                              \
        }                                                                         \
    } while (0)

#endif

/*
 * test_rng.h: the tests' random numbers, a fixed-seed splitmix64 (Steele,
 * Lea & Flood 2014), so that a failing case comes back on every run. Each
 * test keeps its own state (a seed of its choosing); the sequences are
 * those the tests had when each carried its own copy.
 */
#ifndef TESTS_TEST_RNG_H
#define TESTS_TEST_RNG_H

#include <stdint.h>

/* the next 64 random bits of *state */
static inline uint64_t test_rng_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* uniform in [0, 1), 53 bits */
static inline double test_rng_unit(uint64_t *state)
{
    return (double)(test_rng_next(state) >> 11) * 0x1p-53;
}

/* 0 .. n-1 (n > 0; the modulo's bias is below 2^-32 for the n of tests) */
static inline int test_rng_int(uint64_t *state, int n)
{
    return (int)(test_rng_next(state) % (uint64_t)n);
}

#endif

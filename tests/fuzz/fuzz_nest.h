/*
 * tests/fuzz/fuzz_nest.h: a structure-aware mutator for the text targets
 * (rib, sl), for the fuzzer build only (AAFARM_FUZZER). Byte mutations
 * seldom build what breaks a recursive parser: a thousand nested blocks,
 * parentheses or else-if links, a chain of thousands of terms. One
 * mutation in four here instead repeats a slice of the input many times,
 * either alone (a long chain: "+ s" -> "+ s + s + s ...", or a long list of
 * statements) or paired with a later slice (an opener and its closer:
 * "{" ... "}" -> "{{{ ... }}}", "if (c) x; else" -> a chain of else-ifs,
 * "AttributeBegin" ... "AttributeEnd" -> deep blocks); the rest are
 * libFuzzer's own mutations. Include once, from the target's file.
 */
#ifndef TESTS_FUZZ_NEST_H
#define TESTS_FUZZ_NEST_H

#ifdef AAFARM_FUZZER
#include <stdbool.h>
#include <string.h>

size_t LLVMFuzzerMutate(uint8_t *data, size_t size, size_t max_size);

static unsigned nest_rand(unsigned *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return *s;
}

size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned seed);
size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned seed)
{
    unsigned s = seed | 1u;
    if (size < 2 || nest_rand(&s) % 4 != 0)
        return LLVMFuzzerMutate(data, size, max_size);
    /* the opener [a, b), and for a pair the closer [c, d), b <= c */
    size_t a = nest_rand(&s) % size;
    size_t b = a + 1 + nest_rand(&s) % (size - a < 24 ? size - a : 24);
    bool pair = nest_rand(&s) % 2 == 0 && b < size;
    size_t c = b, d = b;
    if (pair) {
        c = b + nest_rand(&s) % (size - b);
        d = c + 1 + nest_rand(&s) % (size - c < 24 ? size - c : 24);
    }
    size_t unit = (b - a) + (d - c);
    if (size + unit > max_size)
        return LLVMFuzzerMutate(data, size, max_size);
    size_t room = (max_size - size) / unit;
    size_t k = 1 + nest_rand(&s) % (room < 3000 ? room : 3000);
    uint8_t *out = malloc(size + k * unit);
    if (!out)
        return LLVMFuzzerMutate(data, size, max_size);
    size_t n = 0;
    memcpy(out + n, data, b);                       /* up to the opener's end */
    n += b;
    for (size_t i = 0; i < k; i++, n += b - a) memcpy(out + n, data + a, b - a);
    memcpy(out + n, data + b, d - b);               /* the middle and the closer */
    n += d - b;
    for (size_t i = 0; i < k && pair; i++, n += d - c) memcpy(out + n, data + c, d - c);
    memcpy(out + n, data + d, size - d);
    n += size - d;
    memcpy(data, out, n);
    free(out);
    return n;
}
#endif

#endif

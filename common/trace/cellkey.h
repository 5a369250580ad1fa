/*
 * cellkey.h: the key of a quadtree cell, {u0, u1, v0, v1} of one object, in
 * the direct-mapped per-thread caches that keep pure functions of object
 * and cell (prove.c's slope bounds, intersect.c's wall samples, moves and
 * cases, displace.c's planes): where an entry goes, whether it holds the
 * cell, and keying it to a cell or to none. An entry whose key has
 * r[0] >= r[1] (a zeroed one) holds none: cells have a width.
 */
#ifndef TRACE_CELLKEY_H
#define TRACE_CELLKEY_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

static inline uint64_t trace_cell_bits(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

/* the entry of a cache of 2^log2_entries entries for the cell */
static inline unsigned trace_cell_slot(const double r[4], int obj, unsigned log2_entries)
{
    uint64_t h = trace_cell_bits(r[0]) * 0x9e3779b97f4a7c15ull ^
                 trace_cell_bits(r[2]) * 0xbf58476d1ce4e5b9ull ^
                 trace_cell_bits(r[1] - r[0]) * 0x94d049bb133111ebull ^ (uint64_t)obj;
    h ^= h >> 29;
    return (unsigned)((h * 0x9e3779b97f4a7c15ull) >> (64 - log2_entries));
}

/* whether an entry keyed (key, key_obj) holds the cell r of object obj */
static inline bool trace_cell_is(const double key[4], int key_obj, const double r[4], int obj)
{
    return key_obj == obj && key[0] == r[0] && key[1] == r[1] && key[2] == r[2] &&
           key[3] == r[3];
}

/* the entry now holds the cell r of object obj */
static inline void trace_cell_keep(double key[4], int *key_obj, const double r[4], int obj)
{
    memcpy(key, r, 4 * sizeof key[0]);
    *key_obj = obj;
}

/* the entry holds no cell (a failed run: nothing to keep) */
static inline void trace_cell_forget(double key[4])
{
    key[0] = 1.0;
    key[1] = 0.0;
}

#endif

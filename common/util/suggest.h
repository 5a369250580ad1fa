/*
 * suggest.h: "did you mean WorldBegin?" -- the closest of a list of names,
 * within a distance that depends on the length of the name asked for.
 *
 * The distance is Damerau's (optimal string alignment): insertions,
 * deletions, substitutions and swaps of two neighbouring letters each count
 * one, and letters are compared without case, so "worldbegin" is at
 * distance 0 from "WorldBegin" (and is still suggested: the caller asked
 * because the exact name was not found). The most a suggestion may be away
 * is 1 for names of up to 4 letters, 2 up to 8, 3 beyond, so that short
 * names do not suggest unrelated ones. Used for RIB requests (common/scene)
 * and shader names (common/job). A library: it prints nothing.
 */
#ifndef UTIL_SUGGEST_H
#define UTIL_SUGGEST_H

#include <stddef.h>

/* The edit distance between a and b, case-insensitive (see above). */
int suggest_distance(const char *a, const char *b);

/* The largest distance accepted for a name of `len` letters: 1, 2 or 3. */
int suggest_limit(size_t len);

/* The name of names[0..n) closest to `name`, within suggest_limit of its
 * length; the first one on a tie; NULL when none is close enough. NULL
 * entries of names are skipped. */
const char *suggest_closest(const char *name, const char *const *names, int n);

#endif

/*
 * parse_num.h: the numbers of the command lines, parsed once for
 * aafarm-master, aafarm-worker and aafarm-maketx (counts, sizes in pixels,
 * milliseconds, seconds, byte counts with a K/M/G suffix).
 *
 * Syntax (what the three tools accepted before they shared this file):
 *   - a whole number: strtol's decimal form, the whole text (leading
 *     blanks and a sign allowed, nothing after the digits), within lo..hi;
 *   - a byte count: strtod's form (fractions allowed: 1.5M), >= 0,
 *     then K, M or G (powers of 1024, either case), then an optional B:
 *     "400K", "4M", "2gb", "123". A value that is not finite or does not
 *     fit a size_t is refused.
 *
 * The parse_* functions only say yes or no; parse_option_long also writes
 * the message the tools print, "OPT wants [NOUN ]LO..HI, got 'TEXT'", which
 * names both bounds. A library function: it prints nothing (util/err.h).
 */
#ifndef UTIL_PARSE_NUM_H
#define UTIL_PARSE_NUM_H

#include <stdbool.h>
#include <stddef.h>

/* True and *out = the number when text is a whole number in lo..hi. */
bool parse_long_within(const char *text, long lo, long hi, long *out);

/* True and *out = the bytes when text is a byte count ("4M", "40K", "0"). */
bool parse_byte_count(const char *text, size_t *out);

/* parse_long_within for an option: on failure err holds
 * "OPT wants NOUN LO..HI, got 'TEXT'" (NOUN NULL: "OPT wants LO..HI, ...")
 * and the result is false. */
bool parse_option_long(const char *opt, const char *noun, const char *text, long lo, long hi,
                       long *out, char *err, size_t errsz);

#endif

/*
 * format.h: the format strings of the shading language's format() and
 * printf() (RI Spec 3.2 §15.6), walked once for the checker (conversions
 * against argument types) and once for the code generator (the pieces it
 * emits).
 */
#ifndef SL_FORMAT_H
#define SL_FORMAT_H

#include <stddef.h>

/* Walks a format string (format, printf): fn gets each conversion's spec
 * ("%5.2f", its length and conversion letter) with the literal text before
 * it, and once more the trailing literal (spec NULL, conv 0); "%%" comes as
 * a literal ending in one '%' (spec NULL, conv '%'). Returns the number of
 * conversions, -1 for a malformed one. */
int sl_format_walk(const char *fmt, void (*fn)(void *, const char *spec, size_t len, char conv,
                                              const char *lit, size_t litlen), void *arg);

#endif

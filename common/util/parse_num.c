/*
 * parse_num.c: the numbers of the command lines (parse_num.h).
 */
#include "util/parse_num.h"

#include <stdint.h>
#include <stdlib.h>

#include "util/err.h"

bool parse_long_within(const char *text, long lo, long hi, long *out)
{
    char *end;
    long v = strtol(text, &end, 10);   /* out of long's range: LONG_MIN/MAX, refused below */
    if (end == text || *end || v < lo || v > hi) return false;
    *out = v;
    return true;
}

bool parse_byte_count(const char *text, size_t *out)
{
    char *end;
    double v = strtod(text, &end);
    if (end == text || !(v >= 0)) return false;
    double mul = 1;
    switch (*end) {
    case 'K': case 'k': mul = 1024.0; end++; break;
    case 'M': case 'm': mul = 1024.0 * 1024; end++; break;
    case 'G': case 'g': mul = 1024.0 * 1024 * 1024; end++; break;
    default: break;
    }
    if (*end == 'B' || *end == 'b') end++;
    if (*end) return false;
    double bytes = v * mul;
    if (!(bytes < (double)SIZE_MAX)) return false;   /* inf, or past size_t */
    *out = (size_t)bytes;
    return true;
}

bool parse_option_long(const char *opt, const char *noun, const char *text, long lo, long hi,
                       long *out, char *err, size_t errsz)
{
    if (parse_long_within(text, lo, hi, out)) return true;
    return err_set(err, errsz, "%s wants %s%s%ld..%ld, got '%s'", opt, noun ? noun : "",
                   noun ? " " : "", lo, hi, text);
}

/*
 * err.c: err_set and its two companions (see err.h for the convention).
 */
#include "util/err.h"

#include <stdio.h>
#include <string.h>

bool err_vset(char *err, size_t errsz, const char *fmt, va_list ap)
{
    if (err && errsz > 0)
        vsnprintf(err, errsz, fmt, ap);
    return false;
}

bool err_set(char *err, size_t errsz, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    err_vset(err, errsz, fmt, ap);
    va_end(ap);
    return false;
}

bool err_prefix(char *err, size_t errsz, const char *fmt, ...)
{
    if (!err || errsz == 0)
        return false;
    char prefix[ERR_LEN], old[ERR_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    snprintf(old, sizeof old, "%s", err);
    snprintf(err, errsz, "%s: %s", prefix, old);
    return false;
}

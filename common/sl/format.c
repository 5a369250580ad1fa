/*
 * format.c: sl_format_walk, the parser of format strings (see format.h).
 */
#include "sl/format.h"

#include <string.h>

/* The conversions of a format string (RI Spec 3.2 §15.6): "%%", or "%"
 * flags [-+ 0], width, .precision and one of f e g d i (a float), p v n
 * (a point, vector or normal), c (a color), m (a matrix), s (a string).
 * Calls fn for each; returns the number of conversions, or -1 (reported)
 * for a malformed one. Shared with the code generator. */
int sl_format_walk(const char *fmt, void (*fn)(void *, const char *spec, size_t len, char conv,
                                              const char *lit, size_t litlen), void *arg)
{
    int count = 0;
    const char *lit = fmt;
    for (const char *p = fmt; *p; p++) {
        if (*p != '%')
            continue;
        if (p[1] == '%') {              /* the literal up to and with one '%' */
            if (fn)
                fn(arg, NULL, 0, '%', lit, (size_t)(p + 1 - lit));
            lit = ++p + 1;
            continue;
        }
        const char *q = p + 1;
        while (*q && strchr("-+ 0", *q))
            q++;
        while (*q >= '0' && *q <= '9')
            q++;
        if (*q == '.')
            for (q++; *q >= '0' && *q <= '9'; q++)
                ;
        if (!*q || !strchr("fegdipvncms", *q) || q - p > 20)
            return -1;
        if (fn)
            fn(arg, p, (size_t)(q - p), *q, lit, (size_t)(p - lit));
        count++;
        p = q;
        lit = q + 1;
    }
    if (fn && *lit)
        fn(arg, NULL, 0, 0, lit, strlen(lit));
    return count;
}

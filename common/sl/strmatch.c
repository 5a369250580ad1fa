/*
 * strmatch.c: the regular expressions of the shading language's match()
 * (RI Spec 3.2 §15.6 "String Functions": match(pattern, subject) is 1 when
 * the regular expression matches anywhere in the subject).
 *
 * The subset: literal characters, `.`, `[abc]`, `[a-z]`, `[^...]`, the
 * postfix `*`, `+`, `?`, the anchors `^` (at the start) and `$` (at the
 * end), and `\c` for a literal c. A backtracking matcher in the manner of
 * Kernighan and Pike's, bounded: it gives up (no match) after
 * SL_MATCH_MAX_STEPS steps, so a hostile pattern cannot hang a worker; it
 * never allocates.
 */
#include "sl/strmatch.h"

#include <stdbool.h>
#include <string.h>

typedef struct matcher {
    long steps;
} matcher;

/* Length of the atom at p (a character, an escape, `.` or a class); 0 at
 * the end; -1 when malformed. */
static int atom_len(const char *p)
{
    if (!*p)
        return 0;
    if (*p == '\\')
        return p[1] ? 2 : -1;
    if (*p == '[') {
        int i = 1;
        if (p[i] == '^')
            i++;
        if (p[i] == ']')            /* a leading ] is literal */
            i++;
        while (p[i] && p[i] != ']')
            i++;
        return p[i] == ']' ? i + 1 : -1;
    }
    if (*p == '*' || *p == '+' || *p == '?')
        return -1;                  /* a repetition of nothing */
    return 1;
}

/* Does the atom at p (length n) match character c? */
static bool atom_matches(const char *p, int n, char c)
{
    if (*p == '\\')
        return p[1] == c;
    if (*p == '.')
        return true;
    if (*p != '[')
        return *p == c;
    int i = 1;
    bool negate = p[i] == '^';
    if (negate)
        i++;
    bool in = false;
    for (; i < n - 1; i++) {
        if (p[i + 1] == '-' && i + 2 < n - 1) {
            in |= c >= p[i] && c <= p[i + 2];
            i += 2;
        } else {
            in |= p[i] == c;
        }
    }
    return in != negate;
}

static bool match_here(matcher *m, const char *p, const char *s)
{
    if (++m->steps > SL_MATCH_MAX_STEPS)
        return false;
    if (!*p)
        return true;
    if (p[0] == '$' && !p[1])
        return !*s;
    int n = atom_len(p);
    if (n <= 0)
        return false;
    char rep = p[n];
    if (rep == '*' || rep == '+' || rep == '?') {
        const char *rest = p + n + 1;
        int min = rep == '+' ? 1 : 0, max = rep == '?' ? 1 : -1;
        int count = 0;
        while (s[count] && (max < 0 || count < max) && atom_matches(p, n, s[count]))
            count++;
        for (int k = count; k >= min; k--)      /* longest first */
            if (match_here(m, rest, s + k))
                return true;
        return false;
    }
    return *s && atom_matches(p, n, *s) && match_here(m, p + n, s + 1);
}

int sl_match_check(const char *pattern)
{
    const char *p = pattern;
    if (*p == '^')
        p++;
    while (*p) {
        if (p[0] == '$' && !p[1])
            break;
        int n = atom_len(p);
        if (n < 0)
            return (int)(p - pattern) + 1;
        p += n;
        if (*p == '*' || *p == '+' || *p == '?')
            p++;
    }
    return 0;
}

int sl_match(const char *pattern, const char *subject)
{
    if (sl_match_check(pattern) != 0)
        return 0;
    matcher m = { 0 };
    if (*pattern == '^')
        return match_here(&m, pattern + 1, subject);
    const char *s = subject;
    do {
        if (match_here(&m, pattern, s))
            return 1;
    } while (*s++ && m.steps <= SL_MATCH_MAX_STEPS);
    return 0;
}

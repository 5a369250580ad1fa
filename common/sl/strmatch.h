/*
 * strmatch.h: the regular expressions of match() (strmatch.c): literal
 * characters, `.`, classes `[a-z]` `[^...]`, `*` `+` `?`, anchors `^` `$`,
 * escapes `\c`; bounded work, no allocation.
 */
#ifndef SL_STRMATCH_H
#define SL_STRMATCH_H

enum { SL_MATCH_MAX_STEPS = 100000 };

/* 1 when pattern matches anywhere in subject (or, anchored, where the
 * anchors say), else 0 (also for a malformed pattern or one that needs
 * more than SL_MATCH_MAX_STEPS steps). */
int sl_match(const char *pattern, const char *subject);

/* 0 for a well-formed pattern, else the 1-based offset of the bad atom. */
int sl_match_check(const char *pattern);

#endif

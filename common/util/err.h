/*
 * err.h: aafarm's one error convention (docs/conventions.md).
 *
 * A function that can fail takes `char *err, size_t errsz` as its last two
 * parameters and, on failure, writes one line into err (what went wrong,
 * where: file:line:col when there is a place, and what to do) with err_set.
 * err may be NULL or errsz 0: the message is then dropped. Callers that keep
 * a message declare `char err[ERR_LEN]`; structs that keep one (a render
 * thread's, the VM's) use the same length. Libraries never print: they
 * return the message and the program that called them decides where it goes.
 *
 * Modelled on Redis's anetSetError: one helper, one buffer size.
 */
#ifndef UTIL_ERR_H
#define UTIL_ERR_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>

/* The length of every error buffer: a message with its place and advice,
 * or a short prefix in front of another ERR_LEN message. */
#define ERR_LEN 1024

/* Formats the message into err (when err is not NULL and errsz > 0) and
 * returns false, so a bool function can `return err_set(err, errsz, ...)`. */
bool err_set(char *err, size_t errsz, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* err_set with a va_list, for helpers that add their own context. */
bool err_vset(char *err, size_t errsz, const char *fmt, va_list ap)
    __attribute__((format(printf, 3, 0)));

/* Puts "prefix: " in front of the message already in err (the caller's
 * context around a callee's message). Returns false like err_set. */
bool err_prefix(char *err, size_t errsz, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#endif

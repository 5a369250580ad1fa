/*
 * rib_reader.h: cuts the token stream into requests (rib_request): a
 * request name followed by its arguments, up to the next name.
 *
 * RIB has no statement terminator: a request's arguments are everything
 * up to the next bare word (RI Specification 3.2, Appendix C.1). An
 * argument is a number, a string, or an array of numbers or of strings in
 * brackets. Reading the arguments of unknown requests the same way is what
 * lets the parser skip them.
 *
 * Errors inside a request (a bad token, an unclosed '[', a stray ']', an
 * array mixing numbers and strings) are reported naming the request, and
 * mark it `broken`: the parser then skips it, so that one typo gives one
 * message. Tokens where a request name should be are reported once per run.
 */
#ifndef SCENE_RIB_READER_H
#define SCENE_RIB_READER_H

#include <stdbool.h>
#include <stddef.h>

#include "sl/diag.h"

typedef enum rib_arg_kind {
    RIB_ARG_NUMBER,      /* nums[first] */
    RIB_ARG_STRING,      /* strs[first] */
    RIB_ARG_NUMBERS,     /* [ ... ]: nums[first .. first+count) */
    RIB_ARG_STRINGS,     /* [ "..." ]: strs[first .. first+count) */
} rib_arg_kind;

typedef struct rib_arg {
    rib_arg_kind kind;
    sl_pos pos;
    int first, count;
} rib_arg;

typedef struct rib_request {
    char *name;
    sl_pos pos;
    rib_arg *args;
    int nargs;
    double *nums;
    int nnums;
    char **strs;
    int nstrs;
    bool broken;         /* an error was reported inside it */
    int args_cap, nums_cap, strs_cap;
} rib_request;

typedef struct rib_reader rib_reader;

/* Reads text[0..len) (not copied); positions carry `file` (not copied). */
rib_reader *rib_reader_new(const char *file, const char *text, size_t len, sl_diag *diag);
void rib_reader_destroy(rib_reader **self_p);

/* The next request, or NULL at the end of the text. The request stays
 * valid until the next call. */
rib_request *rib_reader_next(rib_reader *self);

/* The position just past the last token (for "never closed" messages). */
sl_pos rib_reader_end_pos(const rib_reader *self);

/* Argument helpers. */
bool rib_arg_is_numeric(const rib_arg *arg);
bool rib_arg_is_string(const rib_arg *arg);
/* The numbers of a numeric argument (count in *n). */
const double *rib_arg_numbers(const rib_request *req, const rib_arg *arg, int *n);
/* The first string of a string argument (NULL when it has none). */
const char *rib_arg_string(const rib_request *req, const rib_arg *arg);
/* "a number", "a string", "an array of numbers", ... for messages. */
const char *rib_arg_describe(const rib_arg *arg);

#endif

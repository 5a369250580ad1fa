/*
 * rib_reader.c: requests out of tokens (see rib_reader.h).
 *
 * One token of lookahead: a request ends where the next name starts, so
 * the reader always holds the token after the current request.
 *
 * A request's name and strings live in buffers the reader keeps from one
 * request to the next (a request costs no allocation once the buffers are
 * as long as the longest seen): a scene of a million instances is some
 * ten million requests.
 */
#include "scene/rib_reader.h"
#include "scene/rib_lexer.h"
#include "sl/strbuf.h"
#include "util/xalloc.h"

#include <stdlib.h>
#include <string.h>

struct rib_reader {
    rib_lexer *lexer;
    rib_token tok;          /* lookahead */
    sl_diag *diag;
    rib_request req;
    size_t name_cap;        /* of req.name */
    size_t *str_caps;       /* of req.strs[i], for the nstrs_made slots made */
    int nstrs_made;
};

rib_reader *rib_reader_new(const char *file, const char *text, size_t len, sl_diag *diag)
{
    rib_reader *self = xrealloc(NULL, sizeof *self);
    memset(self, 0, sizeof *self);
    self->lexer = rib_lexer_new(file, text, len);
    self->diag = diag;
    self->tok = rib_lexer_next(self->lexer);
    return self;
}

/* Empties the request; its buffers stay for the next one. */
static void request_clear(rib_request *req)
{
    req->nargs = req->nnums = req->nstrs = 0;
    req->broken = false;
}

/* *buf (of capacity *cap) made to hold s[0..len) and a '\0'. */
static void copy_into(char **buf, size_t *cap, const char *s, size_t len)
{
    if (len + 1 > *cap) {
        *cap = len + 1 > 2 * *cap ? len + 1 : 2 * *cap;
        free(*buf);
        *buf = xmalloc(*cap);
    }
    memcpy(*buf, s, len);
    (*buf)[len] = '\0';
}

void rib_reader_destroy(rib_reader **self_p)
{
    if (!self_p || !*self_p)
        return;
    rib_reader *self = *self_p;
    request_clear(&self->req);
    free(self->req.name);
    for (int i = 0; i < self->nstrs_made; i++)
        free(self->req.strs[i]);
    free(self->str_caps);
    free(self->req.args);
    free(self->req.nums);
    free(self->req.strs);
    rib_lexer_destroy(&self->lexer);
    free(self);
    *self_p = NULL;
}

sl_pos rib_reader_end_pos(const rib_reader *self)
{
    return self->tok.pos;
}

static void advance(rib_reader *self)
{
    self->tok = rib_lexer_next(self->lexer);
}

/* ---------------------------------------------------------------------- */
/* growing the request                                                     */
/* ---------------------------------------------------------------------- */

static void push_number(rib_request *req, double v)
{
    if (req->nnums == req->nums_cap) {
        req->nums_cap = req->nums_cap ? 2 * req->nums_cap : 64;
        req->nums = xrealloc(req->nums, (size_t)req->nums_cap * sizeof *req->nums);
    }
    req->nums[req->nnums++] = v;
}

static void push_string(rib_reader *self, const char *s, size_t len)
{
    rib_request *req = &self->req;
    if (req->nstrs == req->strs_cap) {
        req->strs_cap = req->strs_cap ? 2 * req->strs_cap : 16;
        req->strs = xrealloc(req->strs, (size_t)req->strs_cap * sizeof *req->strs);
        self->str_caps = xrealloc(self->str_caps, (size_t)req->strs_cap * sizeof *self->str_caps);
    }
    if (req->nstrs == self->nstrs_made) {
        req->strs[self->nstrs_made] = NULL;
        self->str_caps[self->nstrs_made++] = 0;
    }
    copy_into(&req->strs[req->nstrs], &self->str_caps[req->nstrs], s, len);
    req->nstrs++;
}

static rib_arg *push_arg(rib_request *req, rib_arg_kind kind, sl_pos pos)
{
    if (req->nargs == req->args_cap) {
        req->args_cap = req->args_cap ? 2 * req->args_cap : 16;
        req->args = xrealloc(req->args, (size_t)req->args_cap * sizeof *req->args);
    }
    rib_arg *arg = &req->args[req->nargs++];
    arg->kind = kind;
    arg->pos = pos;
    arg->first = kind == RIB_ARG_STRING || kind == RIB_ARG_STRINGS ? req->nstrs : req->nnums;
    arg->count = 0;
    return arg;
}

/* Reports an error inside the current request and marks it broken. */
static void request_error(rib_reader *self, sl_pos pos, const char *what)
{
    sl_diag_error(self->diag, pos, "%s: %s", self->req.name, what);
    self->req.broken = true;
}

/* ---------------------------------------------------------------------- */
/* arguments                                                               */
/* ---------------------------------------------------------------------- */

/* One element of an array: appends it unless it mixes kinds. */
static void read_array_element(rib_reader *self, rib_arg *arg, bool *mixed_reported)
{
    bool is_number = self->tok.kind == RIB_TOK_NUMBER;
    if (arg->count == 0)
        arg->kind = is_number ? RIB_ARG_NUMBERS : RIB_ARG_STRINGS;
    if (is_number != (arg->kind == RIB_ARG_NUMBERS)) {
        if (!*mixed_reported)
            request_error(self, self->tok.pos, "an array cannot mix numbers and strings");
        *mixed_reported = true;
        return;
    }
    if (arg->count == 0)
        arg->first = is_number ? self->req.nnums : self->req.nstrs;
    if (is_number)
        push_number(&self->req, self->tok.number);
    else
        push_string(self, self->tok.text, self->tok.len);
    arg->count++;
}

static void read_array(rib_reader *self)
{
    rib_arg *arg = push_arg(&self->req, RIB_ARG_NUMBERS, self->tok.pos);
    size_t index = (size_t)(self->req.nargs - 1);
    sl_pos open = self->tok.pos;
    bool mixed = false, nested = false;
    advance(self);
    for (;;) {
        arg = &self->req.args[index];
        switch (self->tok.kind) {
        case RIB_TOK_NUMBER:
            read_array_element(self, arg, &mixed);
            if (arg->kind == RIB_ARG_NUMBERS) {
                /* the numbers after it without tokens (a mesh's arrays
                 * are millions): up to the first that is not a plain one */
                double v;
                while (rib_lexer_next_number(self->lexer, &v)) {
                    push_number(&self->req, v);
                    arg->count++;
                }
            }
            break;
        case RIB_TOK_STRING:
            read_array_element(self, arg, &mixed);
            break;
        case RIB_TOK_RBRACKET:
            advance(self);
            return;
        case RIB_TOK_LBRACKET:
            if (!nested)
                request_error(self, self->tok.pos, "arrays cannot be nested ('[' inside '[')");
            nested = true;
            break;
        case RIB_TOK_BAD:
            request_error(self, self->tok.pos, self->tok.error);
            break;
        case RIB_TOK_NAME:
        case RIB_TOK_EOF:
            request_error(self, open, "'[' is never closed (missing ']')");
            return;
        }
        advance(self);
    }
}

static void read_arguments(rib_reader *self)
{
    for (;;) {
        switch (self->tok.kind) {
        case RIB_TOK_NAME:
        case RIB_TOK_EOF:
            return;
        case RIB_TOK_NUMBER:
            push_arg(&self->req, RIB_ARG_NUMBER, self->tok.pos)->count = 1;
            push_number(&self->req, self->tok.number);
            break;
        case RIB_TOK_STRING: {
            rib_arg *arg = push_arg(&self->req, RIB_ARG_STRING, self->tok.pos);
            arg->count = 1;
            push_string(self, self->tok.text, self->tok.len);
            break;
        }
        case RIB_TOK_LBRACKET:
            read_array(self);
            continue;
        case RIB_TOK_RBRACKET:
            request_error(self, self->tok.pos, "']' without a matching '['");
            break;
        case RIB_TOK_BAD:
            request_error(self, self->tok.pos, self->tok.error);
            break;
        }
        advance(self);
    }
}

/* ---------------------------------------------------------------------- */
/* requests                                                                */
/* ---------------------------------------------------------------------- */

static const char *token_description(const rib_token *t)
{
    switch (t->kind) {
    case RIB_TOK_NUMBER:   return "a number";
    case RIB_TOK_STRING:   return "a string";
    case RIB_TOK_LBRACKET: return "'['";
    case RIB_TOK_RBRACKET: return "']'";
    default:               return "something else";
    }
}

/* Skips tokens up to the next name, reporting the run once. */
static void skip_to_name(rib_reader *self)
{
    bool reported = false;
    while (self->tok.kind != RIB_TOK_NAME && self->tok.kind != RIB_TOK_EOF) {
        if (!reported && self->tok.kind == RIB_TOK_BAD)
            sl_diag_error(self->diag, self->tok.pos, "%s", self->tok.error);
        else if (!reported)
            sl_diag_error(self->diag, self->tok.pos,
                          "expected a request name, got %s", token_description(&self->tok));
        reported = true;
        advance(self);
    }
}

rib_request *rib_reader_next(rib_reader *self)
{
    request_clear(&self->req);
    skip_to_name(self);
    if (self->tok.kind == RIB_TOK_EOF)
        return NULL;
    copy_into(&self->req.name, &self->name_cap, self->tok.text, self->tok.len);
    self->req.pos = self->tok.pos;
    advance(self);
    read_arguments(self);
    return &self->req;
}

/* ---------------------------------------------------------------------- */
/* argument helpers                                                        */
/* ---------------------------------------------------------------------- */

bool rib_arg_is_numeric(const rib_arg *arg)
{
    return arg->kind == RIB_ARG_NUMBER || arg->kind == RIB_ARG_NUMBERS;
}

bool rib_arg_is_string(const rib_arg *arg)
{
    return arg->kind == RIB_ARG_STRING || arg->kind == RIB_ARG_STRINGS;
}

const double *rib_arg_numbers(const rib_request *req, const rib_arg *arg, int *n)
{
    *n = rib_arg_is_numeric(arg) ? arg->count : 0;
    return *n ? req->nums + arg->first : NULL;
}

const char *rib_arg_string(const rib_request *req, const rib_arg *arg)
{
    if (!rib_arg_is_string(arg) || arg->count == 0)
        return NULL;
    return req->strs[arg->first];
}

const char *rib_arg_describe(const rib_arg *arg)
{
    switch (arg->kind) {
    case RIB_ARG_NUMBER:  return "a number";
    case RIB_ARG_STRING:  return "a string";
    case RIB_ARG_NUMBERS: return arg->count ? "an array of numbers" : "an empty array";
    case RIB_ARG_STRINGS: return "an array of strings";
    }
    return "an argument";
}

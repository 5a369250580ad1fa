/*
 * rib_inline_archive.c: inline archives (PRMan's RIB, RI Specification
 * 3.2's archive record extended as exporters write it):
 *
 *   ArchiveBegin "name" [params] ... ArchiveEnd
 *
 * The requests between are recorded, not run; `ReadArchive "name"` later
 * replays them in the graphics state current at the ReadArchive, as if
 * they stood there (what ReadArchive of a file does, rib_archive.c). A name
 * defined inline takes precedence over a file of that name. Defining a
 * name again replaces it for the ReadArchive requests that follow.
 *
 * Nesting: an ArchiveBegin inside a recording is recorded with its
 * ArchiveEnd, so the inner archive is defined when the outer one is read.
 * A replay counts as one archive level (SCENE_ARCHIVE_MAX_DEPTH in all,
 * with file archives); an archive that reads itself, directly or through
 * others, is an error. Each replayed request keeps its own place in the
 * file that defined it, so messages point inside the ArchiveBegin block,
 * followed by the chain of ReadArchive requests that read it. A block
 * must close in the file that opened it; one left open is an error.
 */
#include "scene/rib_parser.h"
#include "util/xalloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct inline_archive {
    char *name;                    /* NULL: a malformed ArchiveBegin (never found) */
    sl_pos pos;                    /* the ArchiveBegin */
    rib_request *reqs;             /* deep copies */
    int nreqs, cap;
    bool reading;                  /* being replayed (a cycle when read again) */
} inline_archive;

struct rib_inline_archives {
    inline_archive **defs;         /* in order of definition; owned */
    int ndefs;
    inline_archive *recording;     /* the open ArchiveBegin, or NULL */
    int depth;                     /* ArchiveBegin nesting inside the recording */
    int chain_depth;               /* p->narchive_chain at its ArchiveBegin */
};

static char *dup_string(const char *s)
{
    return xstrndup(s, strlen(s));
}

static void copy_request(rib_request *dst, const rib_request *src)
{
    memset(dst, 0, sizeof *dst);
    dst->name = dup_string(src->name);
    dst->pos = src->pos;
    dst->broken = src->broken;
    dst->nargs = dst->args_cap = src->nargs;
    dst->nnums = dst->nums_cap = src->nnums;
    dst->nstrs = dst->strs_cap = src->nstrs;
    if (src->nargs > 0) {
        dst->args = xreallocarray(NULL, (size_t)src->nargs, sizeof *dst->args);
        memcpy(dst->args, src->args, (size_t)src->nargs * sizeof *dst->args);
    }
    if (src->nnums > 0) {
        dst->nums = xreallocarray(NULL, (size_t)src->nnums, sizeof *dst->nums);
        memcpy(dst->nums, src->nums, (size_t)src->nnums * sizeof *dst->nums);
    }
    if (src->nstrs > 0) {
        dst->strs = xreallocarray(NULL, (size_t)src->nstrs, sizeof *dst->strs);
        for (int i = 0; i < src->nstrs; i++)
            dst->strs[i] = dup_string(src->strs[i]);
    }
}

static void request_clear(rib_request *r)
{
    free(r->name);
    free(r->args);
    free(r->nums);
    for (int i = 0; i < r->nstrs; i++)
        free(r->strs[i]);
    free(r->strs);
    memset(r, 0, sizeof *r);
}

static void archive_destroy(inline_archive **self_p)
{
    inline_archive *a = *self_p;
    if (!a)
        return;
    for (int i = 0; i < a->nreqs; i++)
        request_clear(&a->reqs[i]);
    free(a->reqs);
    free(a->name);
    free(a);
    *self_p = NULL;
}

static struct rib_inline_archives *state(rib_parser *p)
{
    if (!p->inline_archives)
        p->inline_archives = xcalloc(1, sizeof *p->inline_archives);
    return p->inline_archives;
}

static void record(inline_archive *a, const rib_request *req)
{
    if (a->nreqs == a->cap) {
        a->cap = a->cap ? 2 * a->cap : 16;
        a->reqs = xreallocarray(a->reqs, (size_t)a->cap, sizeof *a->reqs);
    }
    copy_request(&a->reqs[a->nreqs++], req);
}

/* The latest definition of `name`, or NULL. */
static inline_archive *find(const struct rib_inline_archives *s, const char *name)
{
    for (int i = s ? s->ndefs - 1 : -1; i >= 0; i--)
        if (s->defs[i]->name && strcmp(s->defs[i]->name, name) == 0)
            return s->defs[i];
    return NULL;
}

/* The open block left the file it was opened in: an error, and the
 * recording is dropped (the requests after it run as usual). */
static void left_open(rib_parser *p, struct rib_inline_archives *s)
{
    inline_archive *a = s->recording;
    sl_diag_error(p->diag, a->pos, "ArchiveBegin: this block is never closed in its file "
                  "(missing ArchiveEnd)");
    s->recording = NULL;
    archive_destroy(&a);
}

void rib_archive_begin(rib_parser *p, const rib_request *req)
{
    struct rib_inline_archives *s = state(p);
    char *name = NULL;
    if (!req->broken) {
        const char *n = rib_read_string(p, req, 0, "the archive name");
        rib_params params;          /* a parameter list may follow */
        if (n && !n[0])
            rib_error(p, req, req->args[0].pos, "the archive name is empty");
        else if (n && rib_params_read(p, req, 1, RIB_PARAMS_LOOSE, &params)) {
            rib_params_clear(&params);
            name = dup_string(n);
        }
    }
    inline_archive *a = xcalloc(1, sizeof *a);
    a->name = name;                 /* NULL: recorded all the same, never found */
    a->pos = req->pos;
    s->recording = a;
    s->depth = 0;
    s->chain_depth = p->narchive_chain;
}

void rib_archive_end(rib_parser *p, const rib_request *req)
{
    rib_error(p, req, req->pos, "there is no open ArchiveBegin to close");
}

/* Replays archive a for the ReadArchive req. */
static void replay(rib_parser *p, const rib_request *req, inline_archive *a)
{
    if (a->reading) {
        rib_error(p, req, req->args[0].pos, "archive \"%s\" (defined at %s:%d:%d) reads "
                  "itself: it is already being read", a->name, a->pos.file, a->pos.line,
                  a->pos.col);
        return;
    }
    if (p->narchive_chain >= SCENE_ARCHIVE_MAX_DEPTH) {
        rib_error(p, req, req->args[0].pos, "archives nested more than %d deep (is there a "
                  "cycle?)", SCENE_ARCHIVE_MAX_DEPTH);
        return;
    }
    p->archive_chain[p->narchive_chain].file = a->name;   /* lives as long as the parser */
    p->archive_chain[p->narchive_chain].read_at = req->pos;
    p->narchive_chain++;
    a->reading = true;
    for (int i = 0; i < a->nreqs && rib_parser_step(p, &a->reqs[i]); i++)
        ;
    a->reading = false;
    p->narchive_chain--;
}

bool rib_inline_archive_filter(rib_parser *p, const rib_request *req)
{
    struct rib_inline_archives *s = p->inline_archives;
    if (s && s->recording && p->narchive_chain < s->chain_depth)
        left_open(p, s);
    if (s && s->recording) {
        inline_archive *a = s->recording;
        if (strcmp(req->name, "ArchiveEnd") == 0 && s->depth == 0) {
            if (!req->broken && req->nargs > 0)
                rib_no_more_args(p, req, 0);
            s->defs = xreallocarray(s->defs, (size_t)s->ndefs + 1, sizeof *s->defs);
            s->defs[s->ndefs++] = a;
            s->recording = NULL;
            return true;
        }
        if (strcmp(req->name, "ArchiveBegin") == 0)
            s->depth++;
        else if (strcmp(req->name, "ArchiveEnd") == 0)
            s->depth--;
        record(a, req);
        return true;
    }
    if (strcmp(req->name, "ReadArchive") != 0 || req->broken || req->nargs < 1 ||
        req->args[0].kind != RIB_ARG_STRING)
        return false;
    inline_archive *a = find(s, rib_arg_string(req, &req->args[0]));
    if (!a)
        return false;               /* a file (rib_archive.c) */
    replay(p, req, a);
    return true;
}

void rib_inline_archive_finish(rib_parser *p)
{
    struct rib_inline_archives *s = p->inline_archives;
    if (s && s->recording)
        left_open(p, s);
}

void rib_inline_archives_destroy(rib_parser *p)
{
    struct rib_inline_archives *s = p->inline_archives;
    if (!s)
        return;
    for (int i = 0; i < s->ndefs; i++)
        archive_destroy(&s->defs[i]);
    free(s->defs);
    archive_destroy(&s->recording);
    free(s);
    p->inline_archives = NULL;
}

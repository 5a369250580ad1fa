/*
 * rib_archive.c: ReadArchive (RI Specification 3.2 §5.3 "ReadArchive"):
 * the requests of another RIB file, plain or gzip-compressed, read in place
 * as if written where the ReadArchive stands (same graphics state).
 *
 * Where an archive is found: an absolute name as is; otherwise first the
 * folder of the file that reads it, then each folder of Option
 * "searchpath" "archive" ["dir:&"] (relative folders are relative to the
 * main RIB's folder, like the shader path). The texts come from a source
 * set (sl/source.h) under their normalized names, filled on demand by its
 * loader: from disk through scene_archive_read (gunzipping on the way) on
 * the master and standalone; on a worker from the job's files in the
 * host's store (common/job/job_archive.c), never from the master's disk.
 * An archive is at most SCENE_ARCHIVE_MAX_BYTES uncompressed.
 *
 * Archives may read archives up to SCENE_ARCHIVE_MAX_DEPTH deep; a file
 * that reads itself, directly or through others, is an error. Every
 * message reported inside an archive names the chain that read it
 * (rib_error / rib_warning append it, see rib_parser.c).
 */
#include "scene/rib_parser.h"
#include "sl/source.h"
#include "sl/strbuf.h"
#include "util/xalloc.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

/* max as words for a message: "1 GiB", "4 MiB" or a count of bytes */
static void size_words(size_t max, char *out, size_t outsz)
{
    if (max >= ((size_t)1 << 30) && max % ((size_t)1 << 30) == 0)
        snprintf(out, outsz, "%zu GiB", max >> 30);
    else if (max >= ((size_t)1 << 20) && max % ((size_t)1 << 20) == 0)
        snprintf(out, outsz, "%zu MiB", max >> 20);
    else
        snprintf(out, outsz, "%zu bytes", max);
}

int scene_archive_read(sl_source_set *set, const char *name, const char *path,
                       sl_diag *diag)
{
    gzFile f = gzopen(path, "rb");
    if (!f) {
        if (errno == ENOENT || errno == ENOTDIR)
            return 1;
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "cannot open archive '%s': %s", name,
                          errno ? strerror(errno) : "out of memory");
        return -1;
    }
    gzbuffer(f, 1u << 18);
    /* the buffer grows by doubling up to one byte past the limit, so that a
     * file over it is seen without reading it all */
    size_t max = sl_source_set_max_size(set), cap = 1 << 16, n = 0;
    if (cap > max + 1)
        cap = max + 1;
    char *buf = xrealloc(NULL, cap);
    for (;;) {
        if (n == cap) {
            cap = cap > (max + 1) / 2 ? max + 1 : 2 * cap;
            buf = xrealloc(buf, cap);
        }
        unsigned want = cap - n > (1u << 30) ? 1u << 30 : (unsigned)(cap - n);
        int got = gzread(f, buf + n, want);
        if (got < 0) {
            int zerr;
            const char *msg = gzerror(f, &zerr);
            if (diag)
                sl_diag_error(diag, (sl_pos){0}, "cannot read archive '%s': %s (a damaged "
                              "or truncated gzip file?)", name, msg);
            free(buf);
            gzclose(f);
            return -1;
        }
        n += (size_t)got;
        if (n > max) {
            char words[32];
            size_words(max, words, sizeof words);
            if (diag)
                sl_diag_error(diag, (sl_pos){0}, "archive '%s' is larger than %s uncompressed "
                              "(the limit is %zu bytes per archive): split it into several "
                              "archives", name, words, max);
            free(buf);
            gzclose(f);
            return -1;
        }
        if (got == 0)
            break;
    }
    /* a stream cut short reads without error: gzclose tells */
    if (gzclose(f) != Z_OK) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "cannot read archive '%s': the gzip data ends "
                          "early (a truncated or damaged file?)", name);
        free(buf);
        return -1;
    }
    buf = xrealloc(buf, n + 1);   /* held once, at its size */
    buf[n] = '\0';
    int rc = sl_source_set_adopt(set, name, buf, n);
    if (rc < 0 && diag)
        sl_diag_error(diag, (sl_pos){0}, "cannot keep archive '%s': %s", name,
                      errno == EEXIST ? "a different file has that name" : strerror(errno));
    return rc == 0 ? 0 : -1;
}

/* Reads `name` from disk into the set, gunzipping when it is
 * gzip-compressed (zlib reads plain files transparently). */
int scene_archive_load_from_disk(sl_source_set *set, const char *name, sl_diag *diag,
                                 void *arg)
{
    (void)arg;
    return scene_archive_read(set, name, name, diag);
}

sl_source_set *scene_archive_set_new(void)
{
    sl_source_set *set = sl_source_set_new();
    sl_source_set_set_max_size(set, SCENE_ARCHIVE_MAX_BYTES);
    sl_source_set_set_loader(set, scene_archive_load_from_disk, NULL);
    return set;
}

/* "dir/name" normalized; dir "." or "" gives the name alone. */
static char *join(const char *dir, const char *name)
{
    if (name[0] == '/' || !dir[0] || strcmp(dir, ".") == 0)
        return sl_source_normalize(name);
    size_t n = strlen(dir) + strlen(name) + 2;
    char *joined = xrealloc(NULL, n);
    snprintf(joined, n, "%s/%s", dir, name);
    char *norm = sl_source_normalize(joined);
    free(joined);
    return norm;
}

static char *folder_of(const char *file)
{
    const char *slash = strrchr(file, '/');
    if (!slash)
        return xstrndup(".", 1);
    if (slash == file)
        return xstrndup("/", 1);
    return xstrndup(file, (size_t)(slash - file));
}

/* The archive's source, trying the candidates in order; NULL when none
 * exists (`tried` then lists the folders, for the message). */
static const sl_source *find_archive(rib_parser *p, const char *name, const char *includer,
                                     char *tried, size_t tried_size, bool *failed)
{
    int errors = sl_diag_error_count(p->diag);
    tried[0] = '\0';
    char *main_folder = folder_of(p->file);
    char *own_folder = folder_of(includer);
    int ndirs = name[0] == '/' ? 1 : 1 + p->narchive_path;
    const sl_source *src = NULL;
    for (int i = 0; i < ndirs && !src; i++) {
        char *dir;
        if (i == 0)
            dir = xstrndup(own_folder, strlen(own_folder));
        else
            dir = join(main_folder, p->archive_path[i - 1]);
        char *cand = join(dir, name);
        if (p->archives)
            src = sl_source_set_get(p->archives, cand, p->diag);
        if (!src && name[0] != '/') {
            size_t used = strlen(tried);
            snprintf(tried + used, tried_size - used, "%s%s", used ? ", " : "", dir);
        }
        free(cand);
        free(dir);
    }
    free(main_folder);
    free(own_folder);
    *failed = sl_diag_error_count(p->diag) > errors;
    return src;
}

/* The scene's copy of an archive name (positions outlive the parser). */
static const char *archive_name(scene *s, const char *name)
{
    for (int i = 0; i < s->narchives; i++)
        if (strcmp(s->archives[i], name) == 0)
            return s->archives[i];
    s->archives = xrealloc(s->archives, (size_t)(s->narchives + 1) * sizeof *s->archives);
    s->archives[s->narchives] = xstrndup(name, strlen(name));
    return s->archives[s->narchives++];
}

void rib_read_archive(rib_parser *p, const rib_request *req)
{
    const char *name = rib_read_string(p, req, 0, "the archive name");
    if (!name)
        return;
    rib_params params;      /* RI Spec 3.2: a parameter list may follow */
    if (!rib_params_read(p, req, 1, RIB_PARAMS_LOOSE, &params))
        return;
    rib_params_clear(&params);
    if (!name[0]) {
        rib_error(p, req, req->args[0].pos, "the archive name is empty");
        return;
    }
    char tried[1024];
    bool failed;
    const sl_source *src = find_archive(p, name, req->pos.file, tried, sizeof tried, &failed);
    if (!src) {
        if (failed)
            rib_error(p, req, req->args[0].pos, "archive \"%s\" cannot be read (see the "
                      "message above)", name);
        else if (name[0] == '/')
            rib_error(p, req, req->args[0].pos, "archive \"%s\" not found", name);
        else
            rib_error(p, req, req->args[0].pos, "archive \"%s\" not found: looked in %s; add "
                      "its folder with Option \"searchpath\" \"archive\" [\"dir:&\"]", name,
                      tried);
        return;
    }
    /* the file itself or any file of the chain: a cycle */
    bool cycle = strcmp(src->name, p->file) == 0;
    for (int i = 0; i < p->narchive_chain && !cycle; i++)
        cycle = strcmp(p->archive_chain[i].file, src->name) == 0;
    if (cycle) {
        rib_error(p, req, req->args[0].pos, "archive \"%s\" (%s) reads itself: it is already "
                  "being read", name, src->name);
        return;
    }
    if (p->narchive_chain >= SCENE_ARCHIVE_MAX_DEPTH) {
        rib_error(p, req, req->args[0].pos, "archives nested more than %d deep (is there a "
                  "cycle?)", SCENE_ARCHIVE_MAX_DEPTH);
        return;
    }
    const char *file = archive_name(p->scene, src->name);
    /* for caret lines in messages: a copy, so only of archives of a
     * shader source's size (a message in a bigger one has no caret) */
    if (p->diag_sources && src->len <= SL_SOURCE_DEFAULT_MAX_SIZE)
        sl_source_set_add(p->diag_sources, file, src->text, src->len);
    p->archive_chain[p->narchive_chain].file = file;
    p->archive_chain[p->narchive_chain].read_at = req->pos;
    p->narchive_chain++;
    rib_reader *saved = p->reader;
    p->reader = rib_reader_new(file, src->text, src->len, p->diag);
    rib_parser_run(p);
    rib_reader_destroy(&p->reader);
    p->reader = saved;
    p->narchive_chain--;
}

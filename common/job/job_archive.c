/*
 * job_archive.c: the archives a job's scene reads (ReadArchive) as files
 * of the job, like textures (see job.h, "Archives"; docs/farm.md, "Job
 * files"): content-addressed, shipped once per host through the worker's
 * store, never inside the Job message.
 *
 * Two loaders for the scene parser's archive set (sl/source.h):
 *
 *   job_archive_load_from_disk   job_load on the master / standalone: the
 *       archive found on disk is hashed as it lies there (a gzip file
 *       compressed: what travels), read (gunzipped) into the set, and
 *       added to the job as file "archive:<name>" with its path and stat
 *       stamp; a file that changes while it is read is an error.
 *   job_archive_load             every later parse (the master's check,
 *       standalone's render, a worker's job): the text of the job's file
 *       "archive:<name>" read from its local path (the master's disk, the
 *       host's store); a name the job has no file for does not exist, so
 *       the parser tries its next candidate folder exactly as the master's
 *       disk did, and a worker never reads the master's folders.
 *
 * The file names enter the job hash with the files' SHA-256 (job_finish),
 * so a changed archive makes a new job (resume and journal identity).
 * The set is the parse's own: the texts are freed when the parse ends.
 */
#include "job/job_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "scene/scene.h"

/* "archive:<name>", malloc'd */
static char *file_name(const char *name)
{
    size_t n = strlen(JOB_ARCHIVE_PREFIX) + strlen(name) + 1;
    char *key = xmalloc(n);
    snprintf(key, n, "%s%s", JOB_ARCHIVE_PREFIX, name);
    return key;
}

int job_archive_load_from_disk(sl_source_set *set, const char *name, sl_diag *diag, void *arg)
{
    job *self = arg;
    struct stat st;
    if (stat(name, &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) return 1;
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "cannot open archive '%s': %s", name,
                          strerror(errno));
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "archive '%s' is not a regular file", name);
        return -1;
    }
    if (self->nfiles >= JOB_MAX_FILES) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "archive '%s': a job reads at most %d files "
                          "(textures and archives)", name, JOB_MAX_FILES);
        return -1;
    }
    char hex[HASH_HEX_SIZE], err[ERR_LEN];
    uint64_t size = 0;
    struct stat stamp;
    if (!job_hash_file(name, hex, &size, &stamp, err, sizeof err)) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "cannot read archive '%s': %s", name, err);
        return -1;
    }
    int rc = scene_archive_read(set, name, name, diag);
    if (rc != 0) {
        if (rc > 0 && diag)
            sl_diag_error(diag, (sl_pos){0}, "archive '%s' was removed while it was read", name);
        return -1;
    }
    char *key = file_name(name);
    job_file probe = {.size = size, .stamped = true, .dev = (uint64_t)stamp.st_dev,
                      .ino = (uint64_t)stamp.st_ino,
                      .mtime_ns = (int64_t)stamp.st_mtim.tv_sec * 1000000000 +
                                  stamp.st_mtim.tv_nsec};
    bool ok = true;
    if (job_file_moved(&probe, name)) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "archive '%s' changed while it was read; load "
                          "the scene again when it is written", name);
        ok = false;
    } else if (!job_file_find(self, key) &&
               !job_add_disk_file(self, key, name, hex, size, &stamp, err, sizeof err)) {
        if (diag) sl_diag_error(diag, (sl_pos){0}, "archive '%s': %s", name, err);
        ok = false;
    }
    free(key);
    return ok ? 0 : -1;
}

int job_archive_load(sl_source_set *set, const char *name, sl_diag *diag, void *arg)
{
    const job *jb = arg;
    char *key = file_name(name);
    const job_file *f = job_file_find(jb, key);
    free(key);
    if (!f) return 1;
    if (!f->path) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "archive '%s' (%.12s...) is not present on this "
                          "host", name, f->sha256);
        return -1;
    }
    /* on the master's disk: the bytes hashed into the job, or an error */
    if (f->stamped && job_file_moved(f, f->path)) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "archive '%s' changed on disk after the job was "
                          "loaded; load the scene again", name);
        return -1;
    }
    int rc = scene_archive_read(set, name, f->path, diag);
    if (rc > 0) {
        if (diag)
            sl_diag_error(diag, (sl_pos){0}, "archive '%s': its copy '%s' is gone", name,
                          f->path);
        return -1;
    }
    return rc;
}

sl_source_set *job_archive_set_new(const job *jb)
{
    sl_source_set *set = sl_source_set_new();
    sl_source_set_set_max_size(set, SCENE_ARCHIVE_MAX_BYTES);
    sl_source_set_set_loader(set, job_archive_load, (void *)jb);
    return set;
}

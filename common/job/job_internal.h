/*
 * job_internal.h: what the files of common/job share and nobody else
 * needs: hashing a file on the master's disk with its stat stamp
 * (job_files.c), and the archives a job reads as job files
 * (job_archive.c, see job.h "Archives").
 */
#ifndef JOB_JOB_INTERNAL_H
#define JOB_JOB_INTERNAL_H

#include <sys/stat.h>

#include "job/job.h"

/* The most files a job names (textures and archives together). */
enum { JOB_MAX_FILES = 4096 };

/* Hashes the file at path (SHA-256 as hex, its size) and fills *stamp
 * with what fstat said before; a file written meanwhile is an error.
 * False with the reason in err. */
bool job_hash_file(const char *path, char hex[HASH_HEX_SIZE], uint64_t *size,
                   struct stat *stamp, char *err, size_t errsz);

/* Adds file `name` found on disk at `path`, hashed with stamp st (see
 * job_file.stamped). False (err) on a duplicate name or a bad hash. */
bool job_add_disk_file(job *self, const char *name, const char *path, const char *hex,
                       uint64_t size, const struct stat *st, char *err, size_t errsz);

/* Did the file at path change since `f` was stamped? (true also when it
 * cannot be stat'ed any more.) */
bool job_file_moved(const job_file *f, const char *path);

/* job_archive.c: the loaders of the parser's archive set (arg: the job)
 * and a set for a parse of a loaded or received job (at most
 * SCENE_ARCHIVE_MAX_BYTES per archive, job_archive_load). */
int job_archive_load_from_disk(sl_source_set *set, const char *name, sl_diag *diag, void *arg);
int job_archive_load(sl_source_set *set, const char *name, sl_diag *diag, void *arg);
sl_source_set *job_archive_set_new(const job *jb);

#endif

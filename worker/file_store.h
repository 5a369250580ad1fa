/*
 * file_store.h: the worker's on-disk store of job files (textures), keyed
 * by content (docs/textures.md, "The wire and the cache").
 *
 * One store serves every worker process of a host (--file-cache DIR,
 * default $XDG_CACHE_HOME/aafarm/files or /var/tmp/aafarm-$UID/files):
 *
 *   DIR/objects/<sha256>        a whole file, its hash checked before it
 *                               got there (written to a temporary name,
 *                               then renamed: never seen half-written)
 *   DIR/partial/<sha256>        a transfer under way: the bytes so far ...
 *   DIR/partial/<sha256>.have   ... and which chunks of them are written
 *   DIR/partial/<sha256>.lock   flock'd by the one process fetching it
 *   DIR/verified/<sha256>       inode, size and mtime of the object as
 *                               this host last checked or used it
 *
 * Processes coordinate through the file system only:
 *   - one fetcher per file: a transfer holds an exclusive flock on its
 *     .lock file; another process that needs the file waits (polls) until
 *     the object appears or the lock is free (the fetcher died: it then
 *     takes over and resumes from the chunks already written);
 *   - "in use": a process that holds a job keeps each of the job's
 *     objects open with a shared flock (file_store_acquire). Nobody ever
 *     waits on that lock: eviction only tries it (LOCK_NB) and skips files
 *     in use. No lock is held across renders that anyone waits for.
 *   - LRU: acquiring a file sets its mtime to a second before now (see
 *     touch_and_stamp); eviction removes the
 *     oldest files not in use until the store fits its byte budget.
 *   - a file is re-hashed the first time a process acquires it, unless it
 *     is as its stamp in verified/ says (inode, size, mtime: any write or
 *     replacement changes them); a corrupt one is deleted and fetched
 *     again.
 */
#ifndef WORKER_FILE_STORE_H
#define WORKER_FILE_STORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct file_store file_store;

/* The default folder: $XDG_CACHE_HOME/aafarm/files, or
 * /var/tmp/aafarm-$UID/files. */
void file_store_default_dir(char *buf, size_t size);

/* Opens (creating the folders) the store at dir with a byte budget (0:
 * unlimited). NULL and the reason in err when the folder cannot be used. */
file_store *file_store_open(const char *dir, uint64_t budget, char *err, size_t errsz);
void file_store_close(file_store **self_p);
const char *file_store_dir(const file_store *self);
/* How this process checked the objects it acquired: hashed, or trusted
 * by their stamps. */
void file_store_checks(const file_store *self, unsigned long *hashed, unsigned long *stamped);

/* The file with this hash and size, if whole in the store: returns an
 * open descriptor holding the shared "in use" lock (release with
 * file_store_release) and its path in path[0..path_size); -1 when absent
 * (a corrupt copy is removed first). */
int file_store_acquire(file_store *self, const char *sha256, uint64_t size, char *path,
                       size_t path_size);
void file_store_release(int fd);

/* Removes the oldest files not in use until the objects fit the budget.
 * Returns the number removed. */
int file_store_evict(file_store *self);

/* Bytes of the whole files in the store now. */
uint64_t file_store_bytes(const file_store *self);

/* ---- one transfer into the store ---- */

typedef struct file_transfer file_transfer;

typedef enum file_begin {
    FILE_BEGIN_STARTED,     /* *out is this process's transfer */
    FILE_BEGIN_PRESENT,     /* another process finished it meanwhile: acquire it */
    FILE_BEGIN_BUSY,        /* another process is fetching it: try again later */
    FILE_BEGIN_ERROR        /* the store cannot be written (err says why) */
} file_begin;

/* Starts, or resumes from the chunks written before (by this or a dead
 * process), the transfer of a file in chunks of `chunk` bytes. */
file_begin file_store_begin(file_store *self, const char *sha256, uint64_t size,
                            uint32_t chunk, file_transfer **out, char *err, size_t errsz);

/* The next chunk neither written nor asked for (marks it asked); false
 * when there is none. */
bool file_transfer_next(file_transfer *self, uint64_t *offset, uint32_t *length);

/* Forgets that the chunk at offset was asked for (the request could not
 * be sent). */
void file_transfer_unask(file_transfer *self, uint64_t offset);

/* Writes a received chunk. Returns its byte count when it was expected,
 * 0 when it is not one this transfer lacks (a duplicate, a stale answer),
 * -1 on a write error (err). */
long file_transfer_put(file_transfer *self, uint64_t offset, const void *data, size_t len,
                       char *err, size_t errsz);

/* Every chunk written? */
bool file_transfer_complete(const file_transfer *self);

/* Bytes still missing, and chunks asked for but not received. */
uint64_t file_transfer_missing(const file_transfer *self);

/* Forgets the chunks asked for but not received (after a reconnect: they
 * are asked again). */
void file_transfer_rewind(file_transfer *self);

/* A complete transfer: checks the hash, renames the file into the store
 * and ends the transfer (*self_p = NULL). 0 on success; -1 when the bytes
 * do not hash to the name (everything is discarded, err says so) or the
 * rename fails. */
int file_transfer_finish(file_transfer **self_p, char *err, size_t errsz);

/* Stops without finishing: the chunks written stay for a later resume,
 * the lock is released. */
void file_transfer_abandon(file_transfer **self_p);

const char *file_transfer_sha256(const file_transfer *self);

#endif

/*
 * file_server.h: the master's side of the job files (docs/textures.md,
 * "The wire and the cache"): reads the chunks workers ask for (NeedFile)
 * from the master's disk, for the FileChunk answers.
 *
 * job_load hashed each file; the copy served must still be that content.
 * Before every chunk the open file's device, inode, size and modification
 * time are compared with what job_load saw when it hashed it (and with
 * the last re-hash here): any difference, and the file is hashed again. A
 * file whose content no longer matches the job's hash fails the render
 * with a message naming it: the job must be loaded again (it then gets a
 * new hash, so no worker keeps a stale copy). Hashing runs on the master's
 * loop, so it happens only then, not for every render of a large file.
 *
 * Out of memory: the chunk buffer has the size a worker asked for (at most
 * PROTO_MAX_FILE_CHUNK, 16 MiB), so it is allocated with try_malloc
 * (util/xalloc.h) and a failure is refused with FILE_READ_NO_MEMORY and a
 * message instead of aborting the master: the render then ends as on a
 * full disk, its journal kept for --resume (test_file_server drives it).
 */
#ifndef MASTER_FILE_SERVER_H
#define MASTER_FILE_SERVER_H

#include <stddef.h>
#include <stdint.h>

#include "job/job.h"

typedef struct file_server file_server;

file_server *file_server_new(const job *jb);
void file_server_destroy(file_server **self_p);

typedef enum file_read {
    FILE_READ_OK,
    FILE_READ_UNKNOWN,   /* no file of the job has that hash (a peer's mistake) */
    FILE_READ_RANGE,     /* the range lies outside the file (a peer's mistake) */
    FILE_READ_CHANGED,   /* the file on disk is not the job's any more, or cannot be
                            read: the render fails (err says which and why) */
    FILE_READ_NO_MEMORY  /* no memory for the chunk: the render fails (err says so) */
} file_read;

/* Reads bytes [offset, offset + length) of the job's file with this hash
 * into *data (valid until the next call). *file is the job's entry. */
file_read file_server_read(file_server *self, const char *sha256, uint64_t offset,
                           uint32_t length, const uint8_t **data, const job_file **file,
                           char *err, size_t errsz);

#endif

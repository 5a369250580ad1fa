/*
 * bundle.h: a job as a job queue's submission carries it (docs/farm.md,
 * "A job queue"): everything the master needs to render it without the
 * submitter's disk. aafarm-submit loads the scene as the one-shot master
 * does (frame_sequence_load: the same checks, the same files collected)
 * and sends, as the body of POST /api/jobs:
 *
 *     AAFARM-JOB 1\n
 *     priority N\n
 *     pool NAME\n                   (only with --pool: the workers it goes to)
 *     scene NAME\n                  (for the list; the submitter's path)
 *     frame NUMBER OUTPUT\n         (one per frame, in order; OUTPUT absolute)
 *     \n
 *     then records, each a type byte, its length (8 bytes, little endian)
 *     and its bytes:
 *       'J'  one frame's Job, packed (proto_job_pack), in frame order
 *       'F'  a file of the jobs: its SHA-256 (64 hex digits), then its bytes
 *
 * The master decodes and checks it (job_bundle_decode: every Job checked
 * as one from the wire, every file's hash recomputed), keeps the bytes in
 * its database, and rebuilds each frame's job from them (job_bundle_job:
 * the job hashed again, as a worker does).
 */
#ifndef MASTER_BUNDLE_H
#define MASTER_BUNDLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image/format.h"
#include "job/frames.h"
#include "job/job.h"
#include "message.h"

enum { BUNDLE_MAX_FRAMES = 100000 };

typedef struct bundle_file {
    char sha256[HASH_HEX_SIZE];
    const uint8_t *data;           /* inside the decoded bytes */
    uint64_t size;
} bundle_file;

typedef struct job_bundle {
    int priority;
    char pool[PROTO_POOL_MAX + 1]; /* "" none: any worker */
    char *scene;
    int nframes;
    int *frame_numbers;
    char **outputs;
    proto_saved_job **jobs;
    bundle_file *files;
    int nfiles;
} job_bundle;

/* The submission of the frames of seq (its outputs made absolute against
 * the current folder), xmalloc'd, its size in *len; NULL with the reason
 * (a file of the job that cannot be read). */
uint8_t *job_bundle_encode(const frame_sequence *seq, const char *scene, int priority,
                           const char *pool, size_t *len, char *err, size_t errsz);

/* Decodes and checks data[0..len) (which must outlive b: the files point
 * into it). False with the reason; b is then cleared. */
bool job_bundle_decode(job_bundle *b, const uint8_t *data, size_t len, char *err, size_t errsz);
void job_bundle_clear(job_bundle *b);

/* Frame i's job rebuilt from its message (hashed again: a different hash
 * is refused), its files without local paths; its image format in *fmt. */
job *job_bundle_job(const job_bundle *b, int i, image_format *fmt, char *err, size_t errsz);

#endif

/*
 * job_proto.h: a Job message back into a job (the inverse of
 * master/job_message.c): what a worker does with the Job the master ships,
 * and what the master's job service does with a job a submitter sent
 * (master/bundle.c). Library `job_proto` (proto/CMakeLists.txt): it joins
 * the wire types of proto/ and the renderer's job, so that `proto` itself
 * keeps depending on nothing of the renderer.
 */
#ifndef PROTO_JOB_PROTO_H
#define PROTO_JOB_PROTO_H

#include <stddef.h>

#include "job/job.h"
#include "message.h"

/* The job made from the message's scene, sources, shaders, files and
 * render options, finished (job_finish) and hashed again: NULL with the
 * reason in err when a part is refused, or when its content does not hash
 * to the message's job_hash (the sender runs another aafarm version). The
 * image size and frame number are the caller's to take from m. */
job *job_from_proto(const proto_job *m, char *err, size_t errsz);

#endif

/*
 * job_message.h: a loaded job as the Job message the master ships to
 * workers (docs/protocol.md, "Job"): the RIB text, every shader source
 * under its name, the shader bindings and the render options. The
 * message borrows the job's strings (no copies); it lives as long as the
 * job and the job_message.
 */
#ifndef MASTER_JOB_MESSAGE_H
#define MASTER_JOB_MESSAGE_H

#include <stddef.h>

#include "image/format.h"
#include "job/job.h"
#include "message.h"

typedef struct job_message job_message;

job_message *job_message_new(const job *jb, const image_format *fmt);
void job_message_destroy(job_message **self_p);

/* The Job, ready to put in a proto_msg. */
const proto_job *job_message_job(const job_message *self);

/* Bytes of the packed Envelope carrying it (what one worker receives). */
size_t job_message_packed_size(const job_message *self);

#endif

/*
 * version.h: the protocol version of the farm and the rule that checks it.
 *
 * Master and worker must speak the same version; they compare in the
 * first exchange (Hello -> Welcome or Reject, docs/protocol.md
 * "Versions"). There is no negotiation: a mismatch is a clear error on
 * both sides that names the two versions and what to do.
 */
#ifndef PROTO_VERSION_H
#define PROTO_VERSION_H

#include <stddef.h>
#include <stdint.h>

/* Bump whenever aafarm.proto changes in a way an older peer would
 * misread (docs/protocol.md says which changes those are). */
#define AAFARM_PROTOCOL_VERSION 3   /* 2: job files (NeedFile, FileChunk, FilesReady); 3: archives are job files (archive:<path>), no longer sources */

/* Compares the master's and the worker's protocol versions. Returns 0 when
 * they are equal; otherwise -1 and, when err is not NULL, writes (at most
 * errsz bytes, NUL included) e.g.
 *     "master speaks protocol 1, worker 2: upgrade the older side"
 * A version 0 means the peer sent none (a Hello without a version). */
int proto_version_check(uint32_t master, uint32_t worker, char *err, size_t errsz);

#endif

/*
 * hash.h: SHA-256 (FIPS 180-4) with an incremental interface, and the
 * content hash that names a render job on the farm.
 *
 * A job is identified by the hash of everything that determines its image
 * (DESIGN.md §2, "the image is a pure function of (scene, shaders,
 * options)"): a worker that already holds a job with the same hash is not
 * sent it again. hash_job() defines the one canonical byte encoding of a
 * job (below) so that the master and every worker compute the same name
 * from the same content whatever order the shaders and options came in.
 *
 * Canonical encoding hashed by hash_job() (docs/protocol.md, "Job hash"):
 *
 *     "aafarm-job-v1"                       the domain string, no NUL
 *     record('N', scene name)
 *     record('S', scene text)
 *     for each shader, sorted by name (bytewise):
 *         record('n', name)  record('t', text)
 *     for each option, sorted by key (bytewise):
 *         record('k', key)   record('v', value)
 *
 * where record(tag, bytes) is the tag byte, the byte count as 8 bytes
 * big-endian, then the bytes. The length prefixes make the encoding
 * injective: no two different jobs share an encoding.
 *
 * The SHA-256 context is a plain value (no allocation): initialise it
 * with sha256_init(), feed it with sha256_update(), read it with
 * sha256_final().
 */
#ifndef UTIL_HASH_H
#define UTIL_HASH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SHA256_DIGEST_SIZE 32
#define SHA256_BLOCK_SIZE 64
/* 64 lowercase hex digits and the terminating NUL */
#define HASH_HEX_SIZE 65

typedef struct sha256 {
    uint32_t state[8];               /* H0..H7 of FIPS 180-4 §6.2 */
    uint64_t length;                 /* message bytes so far */
    uint8_t block[SHA256_BLOCK_SIZE]; /* the partial block */
    size_t used;                     /* bytes in block */
} sha256;

/* Starts a new message (initial hash value, FIPS 180-4 §5.3.3). */
void sha256_init(sha256 *self);

/* Appends len bytes of the message; any split of a message into updates
 * gives the same digest. */
void sha256_update(sha256 *self, const void *data, size_t len);

/* Pads, finishes and writes the digest; self must be re-initialised
 * before it is used again. */
void sha256_final(sha256 *self, uint8_t digest[SHA256_DIGEST_SIZE]);

/* One-shot digest of data[0..len). */
void sha256_digest(const void *data, size_t len, uint8_t digest[SHA256_DIGEST_SIZE]);

/* digest as 64 lowercase hex digits plus NUL. */
void hash_hex(const uint8_t digest[SHA256_DIGEST_SIZE], char hex[HASH_HEX_SIZE]);

/* True when s is exactly 64 lowercase hex digits (a hash_hex output). */
bool hash_hex_valid(const char *s);

/* SHA-256 of everything readable from the open file fd (read with pread
 * from offset 0, in 1 MiB pieces), as hex; *len (may be NULL) gets the
 * bytes read. False on a read error. */
bool hash_fd(int fd, char hex[HASH_HEX_SIZE], uint64_t *len);

/* ---- the job hash ---- */

typedef struct hash_shader {
    const char *name;   /* NUL-terminated; unique within a job */
    const char *text;   /* text[0..len) */
    size_t len;
} hash_shader;

typedef struct hash_option {
    const char *key;    /* NUL-terminated; unique within a job */
    const char *value;  /* NUL-terminated */
} hash_option;

typedef struct hash_job_input {
    const char *scene_name;
    const char *scene_text;  /* scene_text[0..scene_len) */
    size_t scene_len;
    const hash_shader *shaders;
    size_t shader_count;
    const hash_option *options;
    size_t option_count;
} hash_job_input;

/* Writes the job's hash as 64 hex digits and returns 0; returns -1 (hex
 * untouched) when a name, text or key is NULL, when two shaders share a
 * name or two options share a key, or when memory runs out. */
int hash_job(const hash_job_input *job, char hex[HASH_HEX_SIZE]);

#endif

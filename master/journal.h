/*
 * journal.h: the master's journal of accepted tiles, "OUT.exr.journal"
 * beside the output, which lets `aafarm-master ... --resume` render only
 * the tiles a dead or interrupted master did not take (docs/farm.md,
 * "Journal and resume").
 *
 * File layout (every integer little-endian):
 *
 *   header   "AAFJRNL1"            8 bytes, magic and format version
 *            width, height, tile size, layers, tile count   5 x u32
 *            job hash                64 bytes, lowercase hex (util/hash.h)
 *            CRC-32 of the 92 bytes above                   u32
 *   record   "TILE"                  4 bytes
 *            tile index (row-major)  u32
 *            chunk length            u32 (at most JOURNAL_MAX_CHUNK)
 *            CRC-32 of index, length and chunk              u32
 *            the tile's compressed EXR chunk, exactly the bytes the output
 *            file holds for it (image/writer.h)
 *
 * A record is written with one write() to a file opened O_APPEND, after
 * the tile was validated. A process killed at any moment leaves whole
 * records plus at most one torn one at the end; a torn or corrupt record
 * (short, bad magic, index out of range, bad CRC) ends the journal: it and
 * everything after it are dropped (the file is truncated there) and those
 * tiles are rendered again.
 *
 * fsync policy: the journal is fdatasync'ed at most once per
 * JOURNAL_SYNC_MS while tiles arrive, and at journal_sync(). Killing the
 * master (even kill -9) loses nothing it journaled, since the data is in
 * the kernel's page cache; a power cut or kernel crash loses at most the
 * tiles of the last second, which the CRC check drops and --resume renders
 * again.
 *
 * The journal is locked (flock) while a master uses it, so two masters
 * cannot render into the same output. Pure file I/O: no sockets, no
 * OpenEXR; unit-tested in tests/master/test_farm_journal.c.
 */
#ifndef MASTER_JOURNAL_H
#define MASTER_JOURNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "util/err.h"
enum {
    JOURNAL_MAX_CHUNK = 64 << 20,   /* the largest tile frame the wire accepts */
    JOURNAL_SYNC_MS = 1000
};

/* What a journal belongs to: the job and its image grid. */
typedef struct journal_id {
    char job_hash[65];
    uint32_t width, height, tile_size, layers, tiles;
} journal_id;

/* What a resume found. */
typedef struct journal_replay {
    int tiles;                 /* intact records replayed (duplicates skipped) */
    uint64_t dropped_bytes;    /* torn or corrupt tail cut off */
    char dropped_why[ERR_LEN]; /* why the tail was cut, "" when nothing was */
} journal_replay;

typedef struct journal journal;

/* "OUT.exr.journal" for output path "OUT.exr" (malloc'd). */
char *journal_path_for(const char *output);

/* Starts an empty journal for a fresh render (replacing an old one:
 * *replaced says whether one with records was there). NULL with err. */
journal *journal_create(const char *path, const journal_id *id, bool *replaced,
                        char *err, size_t errsz);

/* Called for each intact record, in file order, once per tile; returning
 * false stops the resume with err filled in. */
typedef bool (*journal_tile_fn)(void *arg, int tile, const void *chunk, size_t len,
                                char *err, size_t errsz);

/* Opens an existing journal for --resume: checks that it belongs to `id`
 * (else NULL, err says which job it belongs to), replays its intact
 * records through fn, truncates a torn or corrupt tail and leaves the
 * journal ready for appending. *missing is set (and NULL returned, err
 * empty) when there is no journal at path, or one shorter than its header
 * (a master killed while creating it: it holds no tile). */
journal *journal_resume(const char *path, const journal_id *id, journal_tile_fn fn, void *arg,
                        journal_replay *info, bool *missing, char *err, size_t errsz);

/* Appends one tile's chunk; fdatasync when JOURNAL_SYNC_MS passed since
 * the last one (now_ms: any monotonic clock). On failure the journal is
 * cut back to its last whole record where possible. */
bool journal_append(journal *self, int tile, const void *chunk, size_t len, int64_t now_ms,
                    char *err, size_t errsz);

/* fdatasync now. */
bool journal_sync(journal *self, char *err, size_t errsz);

const char *journal_file(const journal *self);

/* Closes the journal and keeps the file (for a later --resume). */
void journal_close(journal **self_p);

/* The render is complete: closes and deletes the journal. */
void journal_remove(journal **self_p);

/* CRC-32 (IEEE 802.3, as zlib's crc32), continuing from crc (0 to start). */
uint32_t journal_crc32(uint32_t crc, const void *bytes, size_t len);

#endif

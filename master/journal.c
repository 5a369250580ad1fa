/*
 * journal.c: the journal of accepted tiles (see journal.h for the layout,
 * the fsync policy and what a resume drops).
 */
#include "journal.h"
#include "util/err.h"
#include "util/fdio.h"
#include "util/xalloc.h"

#include <assert.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

enum { HEADER_BYTES = 8 + 5 * 4 + 64 + 4, RECORD_BYTES = 16 };

static const char magic[8] = {'A', 'A', 'F', 'J', 'R', 'N', 'L', '1'};
static const char record_magic[4] = {'T', 'I', 'L', 'E'};

struct journal {
    char *path;
    int fd;
    uint64_t size;          /* end of the last whole record (>= the header) */
    uint32_t tiles;         /* the grid's tile count: every record's index is below it */
    int64_t synced_ms;      /* last fdatasync (-1: never) */
    bool dirty;             /* written since the last fdatasync */
};

/* ---- CRC-32 ---- */

uint32_t journal_crc32(uint32_t crc, const void *bytes, size_t len)
{
    static uint32_t table[256];
    static bool ready;
    if (!ready) {   /* idempotent: racing threads compute the same table */
        for (uint32_t i = 0; i < 256; i++) {
            uint32_t c = i;
            for (int k = 0; k < 8; k++) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            table[i] = c;
        }
        ready = true;
    }
    const uint8_t *p = bytes;
    crc = ~crc;
    for (size_t i = 0; i < len; i++) crc = table[(crc ^ p[i]) & 0xFF] ^ (crc >> 8);
    return ~crc;
}

/* ---- encoding ---- */

static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void encode_header(uint8_t h[HEADER_BYTES], const journal_id *id)
{
    memcpy(h, magic, 8);
    put_u32(h + 8, id->width);
    put_u32(h + 12, id->height);
    put_u32(h + 16, id->tile_size);
    put_u32(h + 20, id->layers);
    put_u32(h + 24, id->tiles);
    memset(h + 28, '0', 64);
    memcpy(h + 28, id->job_hash, strnlen(id->job_hash, 64));
    put_u32(h + 92, journal_crc32(0, h, 92));
}

static uint32_t record_crc(const uint8_t rec[RECORD_BYTES], const void *chunk, size_t len)
{
    return journal_crc32(journal_crc32(0, rec + 4, 8), chunk, len);
}

/* ---- files ---- */

char *journal_path_for(const char *output)
{
    size_t n = strlen(output) + sizeof ".journal";
    char *p = xmalloc(n);
    snprintf(p, n, "%s.journal", output);
    return p;
}

const char *journal_file(const journal *self)
{
    return self->path;
}

static const char *space_hint(int e)
{
    return e == ENOSPC || e == EDQUOT ? " (free some space on that file system, then run "
                                        "again with --resume)" : "";
}

/* Opens (creating) and locks the file; -1 with err. */
static int open_locked(const char *path, bool create, char *err, size_t errsz)
{
    int fd = open(path, O_RDWR | O_APPEND | O_CLOEXEC | (create ? O_CREAT : 0), 0644);
    if (fd < 0) {
        if (errno != ENOENT || create)
            err_set(err, errsz, "cannot open the journal %s: %s", path, strerror(errno));
        return -1;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        int e = errno;
        err_set(err, errsz, "the journal %s is locked: %s", path,
                e == EWOULDBLOCK ? "another master is rendering into the same output"
                                  : strerror(e));
        close(fd);
        return -1;
    }
    return fd;
}

static journal *wrap(const char *path, int fd, uint64_t size, uint32_t tiles)
{
    assert(fd >= 0 && size >= HEADER_BYTES);   /* open, and the header whole */
    journal *self = xcalloc(1, sizeof *self);
    self->path = xstrdup(path);
    self->fd = fd;
    self->size = size;
    self->tiles = tiles;
    self->synced_ms = -1;
    return self;
}

journal *journal_create(const char *path, const journal_id *id, bool *replaced, char *err,
                        size_t errsz)
{
    *replaced = false;
    int fd = open_locked(path, true, err, errsz);
    if (fd < 0) return NULL;
    struct stat st;
    if (fstat(fd, &st) == 0 && st.st_size > HEADER_BYTES) *replaced = true;
    uint8_t h[HEADER_BYTES];
    encode_header(h, id);
    if (ftruncate(fd, 0) != 0 || !fd_write_all(fd, h, sizeof h) || fdatasync(fd) != 0) {
        int e = errno;
        err_set(err, errsz, "cannot write the journal %s: %s%s", path, strerror(e),
                space_hint(e));
        close(fd);
        unlink(path);
        return NULL;
    }
    return wrap(path, fd, HEADER_BYTES, id->tiles);
}

static bool check_header(const char *path, int fd, const journal_id *id, char *err,
                         size_t errsz)
{
    uint8_t h[HEADER_BYTES], want[HEADER_BYTES];
    if (!fd_pread_all(fd, h, sizeof h, 0, NULL) || memcmp(h, magic, 8) != 0 ||
        get_u32(h + 92) != journal_crc32(0, h, 92)) {
        err_set(err, errsz, "cannot resume: %s is not an aafarm journal or its header is "
                "damaged (remove it and render without --resume)", path);
        return false;
    }
    encode_header(want, id);
    if (memcmp(h + 28, want + 28, 64) != 0) {
        err_set(err, errsz, "cannot resume: %s belongs to job %.12s, this render is job %.12s "
                "(the scene, a shader or an option changed; remove the journal or render "
                "without --resume)", path, (const char *)h + 28, id->job_hash);
        return false;
    }
    if (memcmp(h, want, 28) != 0) {
        err_set(err, errsz, "cannot resume: %s is for a %ux%u image in tiles of %u, this "
                "render is %ux%u in tiles of %u", path, get_u32(h + 8), get_u32(h + 12),
                get_u32(h + 16), id->width, id->height, id->tile_size);
        return false;
    }
    return true;
}

/* Reads the record at off: its chunk into *buf (grown as needed). False
 * with err saying how when it is torn or corrupt. */
static bool read_record(int fd, uint64_t off, uint64_t file_size, const journal_id *id,
                        uint8_t **buf, size_t *cap, int *tile, size_t *len, char *err,
                        size_t errsz)
{
    uint8_t rec[RECORD_BYTES];
    if (file_size - off < RECORD_BYTES || !fd_pread_all(fd, rec, sizeof rec, off, NULL)) {
        err_set(err, errsz, "a torn record header");
        return false;
    }
    uint32_t index = get_u32(rec + 4), n = get_u32(rec + 8);
    if (memcmp(rec, record_magic, 4) != 0 || index >= id->tiles || n == 0 ||
        n > JOURNAL_MAX_CHUNK) {
        err_set(err, errsz, "a corrupt record header");
        return false;
    }
    if (file_size - off - RECORD_BYTES < n) {
        err_set(err, errsz, "a torn record (tile %u)", index);
        return false;
    }
    if (n > *cap) {
        uint8_t *p = xrealloc(*buf, n);
        *buf = p;
        *cap = n;
    }
    if (!fd_pread_all(fd, *buf, n, off + RECORD_BYTES, NULL) ||
        record_crc(rec, *buf, n) != get_u32(rec + 12)) {
        err_set(err, errsz, "a record with a bad checksum (tile %u)", index);
        return false;
    }
    *tile = (int)index;
    *len = n;
    return true;
}

journal *journal_resume(const char *path, const journal_id *id, journal_tile_fn fn, void *arg,
                        journal_replay *info, bool *missing, char *err, size_t errsz)
{
    memset(info, 0, sizeof *info);
    *missing = false;
    err[0] = '\0';
    int fd = open_locked(path, false, err, errsz);
    if (fd < 0) {
        *missing = err[0] == '\0';
        return NULL;
    }
    struct stat st;
    if (fstat(fd, &st) == 0 && st.st_size < HEADER_BYTES) {
        close(fd);           /* killed while creating it: no tile was journaled */
        *missing = true;
        return NULL;
    }
    if (fstat(fd, &st) != 0 || !check_header(path, fd, id, err, errsz)) {
        close(fd);
        return NULL;
    }
    uint64_t file_size = (uint64_t)st.st_size, off = HEADER_BYTES;
    uint8_t *seen = xcalloc(id->tiles ? id->tiles : 1, 1), *buf = NULL;
    size_t cap = 0;
    bool ok = true;
    while (ok && off < file_size) {
        int tile;
        size_t len;
        if (!read_record(fd, off, file_size, id, &buf, &cap, &tile, &len, info->dropped_why,
                         sizeof info->dropped_why))
            break;
        assert(tile >= 0 && (uint32_t)tile < id->tiles);   /* read_record checked it */
        if (!seen[tile]) {
            seen[tile] = 1;
            info->tiles++;
            ok = fn(arg, tile, buf, len, err, errsz);
        }
        off += RECORD_BYTES + len;
    }
    free(buf);
    free(seen);
    /* the replay stopped at a record boundary inside the file, each tile
     * counted once */
    assert(off <= file_size && info->tiles >= 0 && (uint32_t)info->tiles <= id->tiles);
    if (!ok) {
        close(fd);
        return NULL;
    }
    info->dropped_bytes = file_size - off;
    if (off < file_size && ftruncate(fd, (off_t)off) != 0) {
        err_set(err, errsz, "cannot cut the damaged end off the journal %s: %s", path,
                strerror(errno));
        close(fd);
        return NULL;
    }
    return wrap(path, fd, off, id->tiles);
}

bool journal_sync(journal *self, char *err, size_t errsz)
{
    if (!self->dirty) return true;
    if (fdatasync(self->fd) != 0) {
        int e = errno;
        err_set(err, errsz, "cannot write the journal %s: %s%s", self->path, strerror(e),
                space_hint(e));
        return false;
    }
    self->dirty = false;
    return true;
}

bool journal_append(journal *self, int tile, const void *chunk, size_t len, int64_t now_ms,
                    char *err, size_t errsz)
{
    if (tile < 0 || len == 0 || len > JOURNAL_MAX_CHUNK) {
        err_set(err, errsz, "journal: tile %d with a %zu-byte chunk cannot be journaled", tile,
                len);
        return false;
    }
    /* the master journals only tiles of its own grid: a record its resume
     * would call corrupt (and drop with everything after it) is a bug */
    assert((uint32_t)tile < self->tiles);
    assert(self->size >= HEADER_BYTES);
    uint8_t rec[RECORD_BYTES];
    memcpy(rec, record_magic, 4);
    put_u32(rec + 4, (uint32_t)tile);
    put_u32(rec + 8, (uint32_t)len);
    put_u32(rec + 12, record_crc(rec, chunk, len));
    struct iovec iov[2] = {{rec, sizeof rec}, {(void *)chunk, len}};
    size_t want = sizeof rec + len;
    ssize_t n;
    do {
        n = writev(self->fd, iov, 2);
    } while (n < 0 && errno == EINTR);
    if (n != (ssize_t)want) {
        int e = n < 0 ? errno : ENOSPC;   /* a short write: the file system is full */
        err_set(err, errsz, "cannot write the journal %s: %s%s", self->path, strerror(e),
                space_hint(e));
        if (n > 0) (void)!ftruncate(self->fd, (off_t)self->size);   /* no torn tail */
        return false;
    }
    self->size += want;
    self->dirty = true;
    if (self->synced_ms < 0 || now_ms - self->synced_ms >= JOURNAL_SYNC_MS) {
        self->synced_ms = now_ms;
        return journal_sync(self, err, errsz);
    }
    return true;
}

static void destroy(journal **self_p, bool remove)
{
    journal *self = *self_p;
    if (!self) return;
    if (remove) unlink(self->path);
    else if (self->dirty) (void)fdatasync(self->fd);
    close(self->fd);
    free(self->path);
    free(self);
    *self_p = NULL;
}

void journal_close(journal **self_p)
{
    destroy(self_p, false);
}

void journal_remove(journal **self_p)
{
    destroy(self_p, true);
}

/*
 * file_server.c: chunks of the job's files from the master's disk, with
 * the content checked against the job's hash (see file_server.h).
 */
#define _GNU_SOURCE
#include "file_server.h"
#include "util/err.h"
#include "util/fdio.h"
#include "util/xalloc.h"

#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct served {
    int fd;                        /* -1 until first asked for */
    struct stat verified;          /* size and mtime when last hashed (st_ino 0: never) */
} served;

struct file_server {
    const job *jb;
    served *files;
    uint8_t *buf;
    size_t buf_size;
};

file_server *file_server_new(const job *jb)
{
    file_server *self = xcalloc(1, sizeof *self);
    self->jb = jb;
    self->files = xcalloc((size_t)jb->nfiles + 1, sizeof *self->files);
    for (int i = 0; i < jb->nfiles; i++) self->files[i].fd = -1;
    return self;
}

void file_server_destroy(file_server **self_p)
{
    file_server *self = *self_p;
    if (!self) return;
    for (int i = 0; i < self->jb->nfiles; i++)
        if (self->files[i].fd >= 0) close(self->files[i].fd);
    free(self->files);
    free(self->buf);
    free(self);
    *self_p = NULL;
}

static bool same_stat(const struct stat *a, const struct stat *b)
{
    return a->st_size == b->st_size && a->st_mtim.tv_sec == b->st_mtim.tv_sec &&
           a->st_mtim.tv_nsec == b->st_mtim.tv_nsec && a->st_ino == b->st_ino;
}

/* What job_load saw when it hashed the file. */
static bool as_loaded(const struct stat *st, const job_file *f)
{
    return f->stamped && (uint64_t)st->st_dev == f->dev && (uint64_t)st->st_ino == f->ino &&
           (uint64_t)st->st_size == f->size &&
           (int64_t)st->st_mtim.tv_sec * 1000000000 + st->st_mtim.tv_nsec == f->mtime_ns;
}

/* Opens the file (first time) and re-hashes it when it may have changed:
 * unless stat says it is the very file job_load hashed (same device,
 * inode, size and modification time) or the one hashed here last. The
 * hash runs on the master's loop, so it is done only when needed. */
static bool check(served *s, const job_file *f, char *err, size_t errsz)
{
    if (s->fd < 0) {
        s->fd = open(f->path, O_RDONLY | O_CLOEXEC);
        if (s->fd < 0) {
            err_set(err, errsz, "file '%s' ('%s' on the master's disk) cannot be opened any "
                    "more: %s; restore it and render again", f->name, f->path, strerror(errno));
            return false;
        }
        memset(&s->verified, 0, sizeof s->verified);
    }
    struct stat st;
    if (fstat(s->fd, &st) != 0) {
        err_set(err, errsz, "file '%s': %s", f->name, strerror(errno));
        return false;
    }
    if (as_loaded(&st, f) || (s->verified.st_ino != 0 && same_stat(&st, &s->verified)))
        return true;
    char hex[HASH_HEX_SIZE];
    uint64_t len = 0;
    if (!hash_fd(s->fd, hex, &len)) {
        err_set(err, errsz, "file '%s' ('%s') cannot be read: %s", f->name, f->path,
                strerror(errno));
        return false;
    }
    if (len != f->size || strcmp(hex, f->sha256) != 0) {
        err_set(err, errsz, "file '%s' ('%s') changed on the master's disk since the job was "
                "loaded (%llu bytes, SHA-256 %.12s... then; %llu bytes, %.12s... now): render "
                "again to ship the new version", f->name, f->path,
                (unsigned long long)f->size, f->sha256, (unsigned long long)len, hex);
        return false;
    }
    s->verified = st;
    return true;
}

file_read file_server_read(file_server *self, const char *sha, uint64_t offset, uint32_t length,
                           const uint8_t **data, const job_file **file, char *err, size_t errsz)
{
    int i = 0;
    while (i < self->jb->nfiles && strcmp(self->jb->files[i].sha256, sha) != 0) i++;
    if (i == self->jb->nfiles) return FILE_READ_UNKNOWN;
    const job_file *f = &self->jb->files[i];
    *file = f;
    if (offset >= f->size || length > f->size - offset) return FILE_READ_RANGE;
    served *s = &self->files[i];
    if (!check(s, f, err, errsz)) return FILE_READ_CHANGED;
    if (self->buf_size < length) {
        uint8_t *buf = try_malloc(length);   /* a size the worker chose: refused, not fatal */
        if (!buf) {
            err_set(err, errsz, "file '%s': no memory for a chunk of %u bytes (the master is "
                    "out of memory)", f->name, length);
            return FILE_READ_NO_MEMORY;
        }
        free(self->buf);
        self->buf = buf;
        self->buf_size = length;
    }
    size_t got = 0;
    if (!fd_pread_all(s->fd, self->buf, length, offset, &got)) {
        err_set(err, errsz, "file '%s' ('%s') cannot be read at byte %llu: %s", f->name,
                f->path, (unsigned long long)(offset + got),
                errno == 0 ? "it is shorter than when the job was loaded" : strerror(errno));
        return FILE_READ_CHANGED;
    }
    *data = self->buf;
    return FILE_READ_OK;
}

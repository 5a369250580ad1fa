/*
 * outfile.c: temporary file + fsync + rename (see outfile.h).
 *
 * After the rename the containing directory is fsync'ed too, so that the
 * new name survives a crash (best effort: some file systems refuse to
 * fsync a directory, which is not an error for us).
 */
#include "image/outfile.h"
#include "util/err.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "util/xalloc.h"

struct image_outfile {
    char *path;        /* final name */
    char *temp_path;   /* path.tmp-<pid> */
    int fd;
};

static char *temp_name(const char *path)
{
    size_t n = strlen(path) + 32;
    char *s = xmalloc(n);
    snprintf(s, n, "%s.tmp-%ld", path, (long) getpid());
    return s;
}

image_outfile *image_outfile_new(const char *path, char *err, size_t errsz)
{
    if (!path || !*path) {
        err_set(err, errsz, "no output file name given");
        return NULL;
    }
    image_outfile *self = xcalloc(1, sizeof *self);
    self->fd = -1;
    self->path = xstrdup(path);
    self->temp_path = temp_name(path);
    self->fd = open(self->temp_path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC,
                    0666);
    if (self->fd < 0) {
        err_set(err, errsz, "cannot create %s: %s (check that the directory "
                "exists and is writable%s)", self->temp_path,
                strerror(errno), errno == EEXIST ? "; remove the stale "
                "temporary file" : "");
        image_outfile_destroy(&self);
    }
    return self;
}

void image_outfile_destroy(image_outfile **self_p)
{
    if (!self_p || !*self_p)
        return;
    image_outfile *self = *self_p;
    if (self->fd >= 0) {
        close(self->fd);
        unlink(self->temp_path);
    }
    free(self->path);
    free(self->temp_path);
    free(self);
    *self_p = NULL;
}

int image_outfile_fd(const image_outfile *self)
{
    return self->fd;
}

const char *image_outfile_path(const image_outfile *self)
{
    return self->path;
}

const char *image_outfile_temp_path(const image_outfile *self)
{
    return self->temp_path;
}

static void sync_directory(const char *path)
{
    char *dir = xstrdup(path);
    char *slash = strrchr(dir, '/');
    const char *name = dir;
    if (!slash)
        name = ".";
    else if (slash == dir)
        slash[1] = '\0';
    else
        *slash = '\0';
    int fd = open(name, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        (void) fsync(fd);
        close(fd);
    }
    free(dir);
}

bool image_outfile_commit(image_outfile **self_p, char *err, size_t errsz)
{
    image_outfile *self = *self_p;
    int sync_rc = fsync(self->fd);
    int sync_errno = errno;
    int close_rc = close(self->fd);
    self->fd = -1;
    bool ok = sync_rc == 0 && close_rc == 0;
    if (!ok)
        err_set(err, errsz, "cannot write %s: %s (disk full?)",
                self->temp_path, strerror(sync_rc ? sync_errno : errno));
    if (ok && rename(self->temp_path, self->path) != 0) {
        err_set(err, errsz, "cannot rename %s to %s: %s", self->temp_path,
                self->path, strerror(errno));
        ok = false;
    }
    if (ok)
        sync_directory(self->path);
    else
        unlink(self->temp_path);
    image_outfile_destroy(self_p);
    return ok;
}

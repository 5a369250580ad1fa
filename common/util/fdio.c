/*
 * fdio.c: full reads and writes on a file descriptor (see fdio.h).
 */
#include "util/fdio.h"

#include <errno.h>
#include <sys/types.h>
#include <unistd.h>

/* The write loop of both: at the file position (at NULL) or at *at. */
static bool write_loop(int fd, const void *buf, size_t len, const uint64_t *at)
{
    const char *p = buf;
    uint64_t off = at ? *at : 0;
    while (len > 0) {
        ssize_t n = at ? pwrite(fd, p, len, (off_t)off) : write(fd, p, len);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = EIO;
            return false;
        }
        p += n;
        len -= (size_t)n;
        off += (uint64_t)n;
    }
    return true;
}

bool fd_write_all(int fd, const void *buf, size_t len)
{
    return write_loop(fd, buf, len, NULL);
}

bool fd_pwrite_all(int fd, const void *buf, size_t len, uint64_t off)
{
    return write_loop(fd, buf, len, &off);
}

bool fd_pread_all(int fd, void *buf, size_t len, uint64_t off, size_t *got)
{
    char *p = buf;
    size_t done = 0;
    bool ok = true;
    while (done < len) {
        ssize_t n = pread(fd, p + done, len - done, (off_t)(off + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = 0;
            ok = false;
            break;
        }
        done += (size_t)n;
    }
    if (got) *got = done;
    return ok;
}

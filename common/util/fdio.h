/*
 * fdio.h: full reads and writes on a file descriptor. read(2), write(2),
 * pread(2) and pwrite(2) may move fewer bytes than asked (a signal, a
 * pipe, a file system's whim); these loop until all bytes have moved,
 * retrying EINTR. Written once for the master's journal, its file server
 * and the worker's file store.
 */
#ifndef UTIL_FDIO_H
#define UTIL_FDIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Writes buf[0..len) at the file position. False with errno set (EIO when
 * the system wrote nothing and said no error). */
bool fd_write_all(int fd, const void *buf, size_t len);

/* Writes buf[0..len) at offset off. False with errno set (EIO as above). */
bool fd_pwrite_all(int fd, const void *buf, size_t len, uint64_t off);

/* Reads len bytes at offset off into buf. False on an error (errno set)
 * or when the file ends first (errno 0). *got (when not NULL) receives
 * the bytes read either way. */
bool fd_pread_all(int fd, void *buf, size_t len, uint64_t off, size_t *got);

#endif

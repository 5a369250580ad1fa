/*
 * file_store.c: the content-addressed store of job files shared by the
 * worker processes of a host (see file_store.h for the layout and the
 * rules between processes).
 */
#define _GNU_SOURCE
#include "file_store.h"

#include <assert.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "util/hash.h"
#include "util/err.h"
#include "util/fdio.h"
#include "util/xalloc.h"

struct file_store {
    char dir[PATH_MAX];
    uint64_t budget;
    char (*verified)[HASH_HEX_SIZE];   /* hashes this process has checked */
    size_t nverified, cap;
    unsigned long hashed, stamp_trusted;   /* acquire's checks: by hash, by stamp */
};

struct file_transfer {
    file_store *store;
    char sha256[HASH_HEX_SIZE];
    uint64_t size;
    uint32_t chunk;
    size_t nchunks;
    unsigned char *have;           /* written (mirrors the .have file) */
    unsigned char *asked;          /* asked for, not received */
    int lock_fd, data_fd, map_fd;
};

enum { MAP_HEADER = 16 };          /* chunk size, file size: 8 bytes each, big-endian */

void file_store_default_dir(char *buf, size_t size)
{
    const char *xdg = getenv("XDG_CACHE_HOME");
    if (xdg && xdg[0] == '/') snprintf(buf, size, "%s/aafarm/files", xdg);
    else snprintf(buf, size, "/var/tmp/aafarm-%u/files", (unsigned)getuid());
}

static int sub_path(const file_store *s, char *buf, size_t size, const char *sub,
                    const char *name, const char *suffix)
{
    int n = snprintf(buf, size, "%s/%s/%s%s", s->dir, sub, name, suffix);
    return n < 0 || (size_t)n >= size ? -1 : 0;
}

/* mkdir -p of dir (0700 for the folders it creates). */
static int make_dirs(const char *dir)
{
    char tmp[PATH_MAX];
    if (snprintf(tmp, sizeof tmp, "%s", dir) >= (int)sizeof tmp) {
        errno = ENAMETOOLONG;
        return -1;
    }
    for (char *p = tmp + 1; *p; p++) {
        if (*p != '/') continue;
        *p = '\0';
        if (mkdir(tmp, 0700) != 0 && errno != EEXIST) return -1;
        *p = '/';
    }
    if (mkdir(tmp, 0700) != 0 && errno != EEXIST) return -1;
    return 0;
}

file_store *file_store_open(const char *dir, uint64_t budget, char *err, size_t errsz)
{
    char sub[PATH_MAX + 16];
    const char *subs[] = {"objects", "partial", "verified"};
    for (int i = 0; i < 3; i++) {
        snprintf(sub, sizeof sub, "%s/%s", dir, subs[i]);
        if (make_dirs(sub) != 0 || access(sub, W_OK | X_OK) != 0) {
            err_set(err, errsz, "cannot use the file cache folder '%s': %s (give another with "
                    "--file-cache DIR)", sub, strerror(errno));
            return NULL;
        }
    }
    /* a store another user owns or may write could feed us any bytes under
     * a hash we trust once checked: refuse it */
    struct stat st;
    if (stat(dir, &st) != 0 || st.st_uid != getuid() || (st.st_mode & 022)) {
        err_set(err, errsz, "the file cache folder '%s' is not this user's own (owner %u, mode "
                "%03o): give another with --file-cache DIR", dir, (unsigned)st.st_uid,
                (unsigned)(st.st_mode & 0777));
        return NULL;
    }
    file_store *self = xcalloc(1, sizeof *self);
    snprintf(self->dir, sizeof self->dir, "%s", dir);
    self->budget = budget;
    return self;
}

void file_store_close(file_store **self_p)
{
    file_store *self = *self_p;
    if (!self) return;
    free(self->verified);
    free(self);
    *self_p = NULL;
}

const char *file_store_dir(const file_store *self) { return self->dir; }

void file_store_checks(const file_store *self, unsigned long *hashed, unsigned long *stamped)
{
    *hashed = self->hashed;
    *stamped = self->stamp_trusted;
}

static bool is_verified(const file_store *s, const char *sha)
{
    for (size_t i = 0; i < s->nverified; i++)
        if (strcmp(s->verified[i], sha) == 0) return true;
    return false;
}

static void mark_verified(file_store *s, const char *sha)
{
    if (is_verified(s, sha)) return;
    if (s->nverified == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 16;
        s->verified = xrealloc(s->verified, s->cap * sizeof *s->verified);
    }
    snprintf(s->verified[s->nverified++], HASH_HEX_SIZE, "%s", sha);
}

/*
 * Stamps: verified/<sha> holds "inode size mtime-s mtime-ns" of the object
 * as it was after this host last checked or used it (acquire touches the
 * object for the LRU, then writes the stamp). A process that finds the
 * object as stamped trusts it without hashing it again (a 4 GiB map costs
 * ~12 s to hash); any write to the object changes its mtime, and a
 * replaced object its inode, so a changed object is hashed (and, if
 * corrupt, removed) as before. Stamps are written to a temporary name and
 * renamed; a missing, stale or unreadable stamp only costs a hash.
 */
static bool stamp_matches(const file_store *s, const char *sha, const struct stat *st)
{
    char path[PATH_MAX + 100];
    if (sub_path(s, path, sizeof path, "verified", sha, "") != 0) return false;
    FILE *f = fopen(path, "r");
    if (!f) return false;
    unsigned long long ino, size;
    long long sec, nsec;
    bool ok = fscanf(f, "%llu %llu %lld %lld", &ino, &size, &sec, &nsec) == 4 &&
              ino == (unsigned long long)st->st_ino && size == (unsigned long long)st->st_size &&
              sec == (long long)st->st_mtim.tv_sec && nsec == (long long)st->st_mtim.tv_nsec;
    fclose(f);
    return ok;
}

static void stamp_write(const file_store *s, const char *sha, int fd)
{
    struct stat st;
    char path[PATH_MAX + 100], tmp[PATH_MAX + 120];
    if (fstat(fd, &st) != 0 || sub_path(s, path, sizeof path, "verified", sha, "") != 0 ||
        snprintf(tmp, sizeof tmp, "%s.%d.tmp", path, (int)getpid()) >= (int)sizeof tmp)
        return;
    FILE *f = fopen(tmp, "w");
    if (!f) return;
    bool ok = fprintf(f, "%llu %llu %lld %lld\n", (unsigned long long)st.st_ino,
                      (unsigned long long)st.st_size, (long long)st.st_mtim.tv_sec,
                      (long long)st.st_mtim.tv_nsec) > 0;
    ok = fclose(f) == 0 && ok;
    if (!ok || rename(tmp, path) != 0) unlink(tmp);
}

/* Marks the object most recently used and stamps it. The mtime is set one
 * second in the past: file times come from a coarse clock (a few ms), so a
 * write right after a touch to "now" could leave the mtime unchanged and
 * the stamp would still match; a write after this touch moves it forward.
 * (Eviction only compares these times with each other.) */
static void touch_and_stamp(const file_store *s, const char *sha, int fd)
{
    struct timespec ts[2];
    clock_gettime(CLOCK_REALTIME, &ts[0]);
    ts[0].tv_sec -= 1;
    ts[1] = ts[0];
    futimens(fd, ts);
    stamp_write(s, sha, fd);
}

static void stamp_remove(const file_store *s, const char *sha)
{
    char path[PATH_MAX + 100];
    if (sub_path(s, path, sizeof path, "verified", sha, "") == 0) unlink(path);
}

int file_store_acquire(file_store *self, const char *sha, uint64_t size, char *path,
                       size_t path_size)
{
    if (sub_path(self, path, path_size, "objects", sha, "") != 0) return -1;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return -1;
    while (flock(fd, LOCK_SH) != 0 && errno == EINTR) {}
    struct stat a, b;
    if (fstat(fd, &a) != 0 || stat(path, &b) != 0 || a.st_ino != b.st_ino || a.st_dev != b.st_dev) {
        close(fd);                 /* evicted between open and lock */
        return -1;
    }
    bool good = (uint64_t)a.st_size == size;
    if (good && !is_verified(self, sha)) {
        if (stamp_matches(self, sha, &a)) {
            self->stamp_trusted++;     /* as this host last saw it */
        } else {
            char hex[HASH_HEX_SIZE];
            good = hash_fd(fd, hex, NULL) && strcmp(hex, sha) == 0;
            self->hashed++;
        }
        if (good) mark_verified(self, sha);
    }
    if (!good) {
        unlink(path);              /* corrupt: fetched again */
        stamp_remove(self, sha);
        close(fd);
        return -1;
    }
    touch_and_stamp(self, sha, fd);   /* most recently used; the stamp for the next process */
    return fd;
}

void file_store_release(int fd)
{
    if (fd >= 0) close(fd);        /* drops the shared lock */
}

typedef struct entry {
    char name[HASH_HEX_SIZE];
    uint64_t size;
    struct timespec mtime;
} entry;

static int by_age(const void *a, const void *b)
{
    const entry *x = a, *y = b;
    if (x->mtime.tv_sec != y->mtime.tv_sec) return x->mtime.tv_sec < y->mtime.tv_sec ? -1 : 1;
    if (x->mtime.tv_nsec != y->mtime.tv_nsec) return x->mtime.tv_nsec < y->mtime.tv_nsec ? -1 : 1;
    return strcmp(x->name, y->name);
}

/* The whole files in the store (malloc'd array), their total in *total. */
static entry *list_objects(const file_store *s, size_t *n, uint64_t *total)
{
    char dir[PATH_MAX + 16];
    snprintf(dir, sizeof dir, "%s/objects", s->dir);
    *n = 0;
    *total = 0;
    DIR *d = opendir(dir);
    if (!d) return NULL;
    entry *v = NULL;
    size_t cap = 0;
    struct dirent *de;
    while ((de = readdir(d))) {
        if (!hash_hex_valid(de->d_name)) continue;
        struct stat st;
        if (fstatat(dirfd(d), de->d_name, &st, 0) != 0 || !S_ISREG(st.st_mode)) continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 32;
            v = xrealloc(v, cap * sizeof *v);
        }
        memcpy(v[*n].name, de->d_name, HASH_HEX_SIZE);   /* 64 hex digits and the NUL */
        v[*n].size = (uint64_t)st.st_size;
        v[*n].mtime = st.st_mtim;
        *total += (uint64_t)st.st_size;
        (*n)++;
    }
    closedir(d);
    return v;
}

uint64_t file_store_bytes(const file_store *self)
{
    size_t n;
    uint64_t total;
    free(list_objects(self, &n, &total));
    return total;
}

int file_store_evict(file_store *self)
{
    if (self->budget == 0) return 0;
    size_t n;
    uint64_t total;
    entry *v = list_objects(self, &n, &total);
    int removed = 0;
    if (total > self->budget) {
        qsort(v, n, sizeof *v, by_age);
        for (size_t i = 0; i < n && total > self->budget; i++) {
            char path[PATH_MAX + 100];
            if (sub_path(self, path, sizeof path, "objects", v[i].name, "") != 0) continue;
            int fd = open(path, O_RDONLY | O_CLOEXEC);
            if (fd < 0) continue;
            struct stat a, b;
            /* in use (a shared lock held) or replaced meanwhile: keep it */
            if (flock(fd, LOCK_EX | LOCK_NB) == 0 && fstat(fd, &a) == 0 && stat(path, &b) == 0 &&
                a.st_ino == b.st_ino && unlink(path) == 0) {
                stamp_remove(self, v[i].name);
                assert(v[i].size <= total);   /* the total is the sum of the sizes listed */
                total -= v[i].size;
                removed++;
            }
            close(fd);
        }
    }
    free(v);
    return removed;
}

/* ---- transfers ---- */

static bool object_exists(const file_store *s, const char *sha)
{
    char path[PATH_MAX + 100];
    return sub_path(s, path, sizeof path, "objects", sha, "") == 0 && access(path, F_OK) == 0;
}

static void put_be64(unsigned char *p, uint64_t v)
{
    for (int i = 7; i >= 0; i--, v >>= 8) p[i] = (unsigned char)(v & 0xff);
}

static uint64_t get_be64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) v = v << 8 | p[i];
    return v;
}

static void transfer_free(file_transfer *t)
{
    if (t->data_fd >= 0) close(t->data_fd);
    if (t->map_fd >= 0) close(t->map_fd);
    if (t->lock_fd >= 0) close(t->lock_fd);   /* releases the lock */
    free(t->have);
    free(t->asked);
    free(t);
}

/* Reads the chunk map of an earlier attempt, or starts a fresh one. */
static bool load_map(file_transfer *t)
{
    unsigned char head[MAP_HEADER] = {0};
    struct stat st;
    /* an earlier attempt's chunk size wins (another process may have been
     * started with another --file-chunk): its chunks are what is written */
    if (fstat(t->map_fd, &st) == 0 && pread(t->map_fd, head, MAP_HEADER, 0) == MAP_HEADER &&
        get_be64(head + 8) == t->size && get_be64(head) >= 1 && get_be64(head) <= UINT32_MAX) {
        uint32_t chunk = (uint32_t)get_be64(head);
        size_t n = (size_t)((t->size + chunk - 1) / chunk);
        if ((uint64_t)st.st_size == MAP_HEADER + n && n != t->nchunks) {
            unsigned char *have = xrealloc(t->have, n + 1), *asked = xrealloc(t->asked, n + 1);
            t->have = have;
            t->asked = asked;
            memset(t->asked, 0, n + 1);
        }
        if ((uint64_t)st.st_size == MAP_HEADER + n) {
            t->chunk = chunk;
            t->nchunks = n;
        }
    }
    bool resume = fstat(t->map_fd, &st) == 0 &&
                  (uint64_t)st.st_size == MAP_HEADER + t->nchunks &&
                  get_be64(head) == t->chunk && get_be64(head + 8) == t->size &&
                  (t->nchunks == 0 ||
                   pread(t->map_fd, t->have, t->nchunks, MAP_HEADER) == (ssize_t)t->nchunks);
    /* the map, read or fresh, covers the file in whole chunks */
    assert(t->chunk >= 1 && t->nchunks == (size_t)((t->size + t->chunk - 1) / t->chunk));
    if (resume) {
        for (size_t i = 0; i < t->nchunks; i++) t->have[i] = t->have[i] == 1;
        return true;
    }
    memset(t->have, 0, t->nchunks);
    put_be64(head, t->chunk);
    put_be64(head + 8, t->size);
    return ftruncate(t->map_fd, 0) == 0 && ftruncate(t->data_fd, 0) == 0 &&
           ftruncate(t->data_fd, (off_t)t->size) == 0 &&
           fd_pwrite_all(t->map_fd, head, MAP_HEADER, 0) &&
           (t->nchunks == 0 || fd_pwrite_all(t->map_fd, t->have, t->nchunks, MAP_HEADER));
}

file_begin file_store_begin(file_store *self, const char *sha, uint64_t size, uint32_t chunk,
                            file_transfer **out, char *err, size_t errsz)
{
    *out = NULL;
    if (object_exists(self, sha)) return FILE_BEGIN_PRESENT;
    char lock[PATH_MAX + 100], data[PATH_MAX + 100], map[PATH_MAX + 100];
    if (sub_path(self, lock, sizeof lock, "partial", sha, ".lock") != 0 ||
        sub_path(self, data, sizeof data, "partial", sha, "") != 0 ||
        sub_path(self, map, sizeof map, "partial", sha, ".have") != 0) {
        err_set(err, errsz, "the file cache folder's name is too long");
        return FILE_BEGIN_ERROR;
    }
    file_transfer *t = xcalloc(1, sizeof *t);
    t->store = self;
    t->data_fd = t->map_fd = -1;
    snprintf(t->sha256, sizeof t->sha256, "%s", sha);
    t->size = size;
    t->chunk = chunk ? chunk : 1;
    t->nchunks = (size_t)((size + t->chunk - 1) / t->chunk);
    assert((uint64_t)t->nchunks * t->chunk >= size);
    t->have = xcalloc(t->nchunks + 1, 1);
    t->asked = xcalloc(t->nchunks + 1, 1);
    t->lock_fd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (t->lock_fd < 0) {
        err_set(err, errsz, "cannot create '%s': %s", lock, strerror(errno));
        transfer_free(t);
        return FILE_BEGIN_ERROR;
    }
    if (flock(t->lock_fd, LOCK_EX | LOCK_NB) != 0) {
        transfer_free(t);
        return FILE_BEGIN_BUSY;    /* another process of this host fetches it */
    }
    if (object_exists(self, sha)) {   /* finished while we took the lock */
        transfer_free(t);
        return FILE_BEGIN_PRESENT;
    }
    t->data_fd = open(data, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    t->map_fd = open(map, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (t->data_fd < 0 || t->map_fd < 0 || !load_map(t)) {
        err_set(err, errsz, "cannot write the file cache's '%s': %s", data, strerror(errno));
        transfer_free(t);
        return FILE_BEGIN_ERROR;
    }
    *out = t;
    return FILE_BEGIN_STARTED;
}

bool file_transfer_next(file_transfer *t, uint64_t *offset, uint32_t *length)
{
    for (size_t i = 0; i < t->nchunks; i++) {
        if (t->have[i] || t->asked[i]) continue;
        t->asked[i] = 1;
        *offset = (uint64_t)i * t->chunk;
        uint64_t left = t->size - *offset;
        *length = left < t->chunk ? (uint32_t)left : t->chunk;
        return true;
    }
    return false;
}

void file_transfer_unask(file_transfer *t, uint64_t offset)
{
    if (offset % t->chunk == 0 && offset < t->size) t->asked[offset / t->chunk] = 0;
}

long file_transfer_put(file_transfer *t, uint64_t offset, const void *data, size_t len,
                       char *err, size_t errsz)
{
    if (offset % t->chunk != 0 || offset >= t->size) return 0;
    size_t i = (size_t)(offset / t->chunk);
    uint64_t left = t->size - offset;
    if (len != (left < t->chunk ? left : t->chunk) || t->have[i]) return 0;
    static const unsigned char one = 1;
    /* the bytes first, then the map: a crash in between costs one chunk */
    assert(i < t->nchunks);   /* offset < size: a chunk of the map */
    if (!fd_pwrite_all(t->data_fd, data, len, offset) ||
        !fd_pwrite_all(t->map_fd, &one, 1, MAP_HEADER + (uint64_t)i)) {
        err_set(err, errsz, "cannot write to the file cache %s: %s (free space there, or give "
                "another folder with --file-cache DIR)", t->store->dir,
                strerror(errno ? errno : EIO));
        return -1;
    }
    t->have[i] = 1;
    t->asked[i] = 0;
    return (long)len;
}

bool file_transfer_complete(const file_transfer *t)
{
    for (size_t i = 0; i < t->nchunks; i++)
        if (!t->have[i]) return false;
    return true;
}

uint64_t file_transfer_missing(const file_transfer *t)
{
    uint64_t n = 0;
    for (size_t i = 0; i < t->nchunks; i++)
        if (!t->have[i]) {
            uint64_t left = t->size - (uint64_t)i * t->chunk;
            n += left < t->chunk ? left : t->chunk;
        }
    return n;
}

void file_transfer_rewind(file_transfer *t)
{
    memset(t->asked, 0, t->nchunks);
}

const char *file_transfer_sha256(const file_transfer *t) { return t->sha256; }

int file_transfer_finish(file_transfer **self_p, char *err, size_t errsz)
{
    file_transfer *t = *self_p;
    assert(file_transfer_complete(t));   /* finished only with every chunk written */
    *self_p = NULL;
    char data[PATH_MAX + 100], map[PATH_MAX + 100], lock[PATH_MAX + 100], obj[PATH_MAX + 100];
    sub_path(t->store, data, sizeof data, "partial", t->sha256, "");
    sub_path(t->store, map, sizeof map, "partial", t->sha256, ".have");
    sub_path(t->store, lock, sizeof lock, "partial", t->sha256, ".lock");
    sub_path(t->store, obj, sizeof obj, "objects", t->sha256, "");
    char hex[HASH_HEX_SIZE];
    uint64_t len = 0;
    int rc = 0;
    if (!hash_fd(t->data_fd, hex, &len) || len != t->size || strcmp(hex, t->sha256) != 0) {
        err_set(err, errsz, "the %llu bytes received hash to %.12s..., not %.12s...: "
                "discarded, to be fetched again", (unsigned long long)len, hex, t->sha256);
        unlink(data);
        rc = -1;
    } else if (rename(data, obj) != 0) {   /* atomic: whole or absent */
        err_set(err, errsz, "cannot move '%s' into the file cache: %s", data, strerror(errno));
        unlink(data);
        rc = -1;
    } else {
        mark_verified(t->store, t->sha256);
        touch_and_stamp(t->store, t->sha256, t->data_fd);   /* the same inode, now the object */
    }
    unlink(map);
    unlink(lock);                  /* a process that locks the old inode finds the object */
    transfer_free(t);
    return rc;
}

void file_transfer_abandon(file_transfer **self_p)
{
    if (!*self_p) return;
    transfer_free(*self_p);
    *self_p = NULL;
}

/*
 * job_files.c: the data files a job needs (textures, height maps), found
 * generically on the master's / standalone side (see job.h,
 * job_collect_files; docs/textures.md, "The wire and the cache").
 *
 * A shader names a file by a string: a constant in its code
 * (texture("height.exr", s, t)) or a string parameter set in the RIB
 * (Displacement "heightmap" "string texname" "rock.exr"). Every such
 * string that names an existing regular file on the scene's texture
 * search path (Option "searchpath" "texture", then the RIB's folder) is a
 * file of the job: its bytes are hashed (SHA-256, FIPS 180-4) here, once,
 * and the job carries the name, hash and size. Strings that name no file
 * ("rgb", "current") are not files; a false match costs one transfer of a
 * file the shader never reads, never a wrong pixel.
 */
#include "job/job.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "job/job_internal.h"
#include "job/job_scene.h"
#include "sl/bytecode.h"

enum { MAX_NAME = 4096 };

static int64_t mtime_ns(const struct stat *st)
{
    return (int64_t)st->st_mtim.tv_sec * 1000000000 + st->st_mtim.tv_nsec;
}

/* stat before and after: a file written meanwhile is an error */
bool job_hash_file(const char *path, char hex[HASH_HEX_SIZE], uint64_t *size,
                      struct stat *stamp, char *err, size_t errsz)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        return err_set(err, errsz, "%s", strerror(errno));
    }
    struct stat after;
    if (fstat(fileno(f), stamp) != 0) {
        err_set(err, errsz, "%s", strerror(errno));
        fclose(f);
        return false;
    }
    enum { CHUNK = 1 << 20 };
    unsigned char *buf = xmalloc(CHUNK);
    sha256 h;
    sha256_init(&h);
    uint64_t n = 0;
    size_t got;
    while ((got = fread(buf, 1, CHUNK, f)) > 0) {
        sha256_update(&h, buf, got);
        n += got;
    }
    bool bad = ferror(f) != 0;
    int e = errno;
    bool moved = fstat(fileno(f), &after) != 0 || mtime_ns(&after) != mtime_ns(stamp) ||
                 after.st_size != stamp->st_size || (uint64_t)after.st_size != n;
    free(buf);
    fclose(f);
    if (bad) {
        return err_set(err, errsz, "read error: %s", strerror(e));
    }
    if (moved) {
        err_set(err, errsz, "it changed while it was read; load the scene again when it "
                "is written");
        return false;
    }
    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_final(&h, digest);
    hash_hex(digest, hex);
    *size = n;
    return true;
}

bool job_add_disk_file(job *self, const char *name, const char *path, const char *hex,
                       uint64_t size, const struct stat *st, char *err, size_t errsz)
{
    if (!job_add_file(self, name, hex, size, err, errsz)) return false;
    job_file *f = &self->files[self->nfiles - 1];
    job_file_set_path(self, self->nfiles - 1, path);
    f->stamped = true;
    f->dev = (uint64_t)st->st_dev;
    f->ino = (uint64_t)st->st_ino;
    f->mtime_ns = mtime_ns(st);
    return true;
}

bool job_file_moved(const job_file *f, const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return true;
    return (uint64_t)st.st_dev != f->dev || (uint64_t)st.st_ino != f->ino ||
           mtime_ns(&st) != f->mtime_ns || (uint64_t)st.st_size != f->size;
}

/* The first "<dir>/<name>" on the texture path that is a regular file
 * (an absolute name: itself), malloc'd, or NULL. */
static char *find_on_path(const scene *sc, const char *name)
{
    struct stat st;
    if (name[0] == '/') {
        if (stat(name, &st) == 0 && S_ISREG(st.st_mode)) return xstrdup(name);
        return NULL;
    }
    for (int i = 0; i < sc->ntexture_path; i++) {
        const char *dir = sc->texture_path[i];
        size_t n = strlen(dir) + strlen(name) + 2;
        char *path = xmalloc(n);
        if (strcmp(dir, ".") == 0) snprintf(path, n, "%s", name);
        else snprintf(path, n, "%s%s%s", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", name);
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) return path;
        free(path);
    }
    return NULL;
}

bool job_texture_path_resolve(void *scene_, const char *name, char *path, size_t path_size,
                              char *err, size_t errsz)
{
    const scene *sc = scene_;
    char *found = find_on_path(sc, name);
    if (!found) {
        err_set(err, errsz, "no file '%s' on the texture search path (add its folder "
                "with Option \"searchpath\" \"texture\" [\"dir:&\"]; the RIB's folder is "
                "searched last)", name);
        return false;
    }
    bool fits = strlen(found) < path_size;
    if (fits)
        memcpy(path, found, strlen(found) + 1);
    else
        err_set(err, errsz, "the path of '%s' is longer than %zu bytes", name,
                path_size - 1);
    free(found);
    return fits;
}

/* One candidate string: a file of the job when it names one. */
static bool consider(job *self, const scene *sc, const char *name, sl_pos pos, sl_diag *diag)
{
    size_t len = strlen(name);
    if (len == 0 || len > MAX_NAME || job_file_find(self, name)) return true;
    for (size_t i = 0; i < len; i++)
        if ((unsigned char)name[i] < 0x20 || name[i] == 0x7f) return true;   /* not a file name */
    char *path = find_on_path(sc, name);
    if (!path) return true;
    if (self->nfiles >= JOB_MAX_FILES) {
        sl_diag_error(diag, pos, "file '%s': a job reads at most %d files", name, JOB_MAX_FILES);
        free(path);
        return false;
    }
    char hex[HASH_HEX_SIZE], err[ERR_LEN];
    uint64_t size = 0;
    struct stat st;
    if (!job_hash_file(path, hex, &size, &st, err, sizeof err)) {
        sl_diag_error(diag, pos, "file '%s' (found as '%s' on the texture search path) cannot be "
                      "read: %s; fix its permissions or remove it", name, path, err);
        free(path);
        return false;
    }
    bool ok = job_add_disk_file(self, name, path, hex, size, &st, err, sizeof err);
    if (!ok) sl_diag_error(diag, pos, "%s", err);
    free(path);
    return ok;
}

bool job_collect_files(job *self, const job_scene *js, sl_diag *diag)
{
    self->files_known = true;
    const scene *sc = js->scene;
    bool ok = true;
    for (int i = 0; i < self->nshaders && ok; i++) {
        const sl_program *p = js->programs[i];
        if (!p) continue;
        sl_pos pos = {self->shaders[i].file, 0, 0};
        for (int k = 0; k < p->nstrings && ok; k++)
            ok = consider(self, sc, p->strings[k], pos, diag);
    }
    for (int i = 0; i < sc->nshaders && ok; i++) {
        const scene_shader *sh = &sc->shaders[i];
        for (int k = 0; k < sh->nparams && ok; k++)
            if (sh->params[k].string)
                ok = consider(self, sc, sh->params[k].string, sh->params[k].pos, diag);
    }
    return ok;
}

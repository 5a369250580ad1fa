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

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "job/job_scene.h"
#include "sl/bytecode.h"

enum { MAX_JOB_FILES = 4096, MAX_NAME = 4096 };

/* Hashes the file at path; false (errno-based reason in why) on a read
 * error. */
static bool hash_file(const char *path, char hex[HASH_HEX_SIZE], uint64_t *size, char *why,
                      size_t why_size)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, why_size, "%s", strerror(errno));
        return false;
    }
    enum { CHUNK = 1 << 20 };
    unsigned char *buf = malloc(CHUNK);
    if (!buf) abort();
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
    free(buf);
    fclose(f);
    if (bad) {
        snprintf(why, why_size, "read error: %s", strerror(e));
        return false;
    }
    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_final(&h, digest);
    hash_hex(digest, hex);
    *size = n;
    return true;
}

/* The first "<dir>/<name>" on the texture path that is a regular file
 * (an absolute name: itself), malloc'd, or NULL. */
static char *find_on_path(const scene *sc, const char *name)
{
    struct stat st;
    if (name[0] == '/') {
        if (stat(name, &st) == 0 && S_ISREG(st.st_mode)) return strdup(name);
        return NULL;
    }
    for (int i = 0; i < sc->ntexture_path; i++) {
        const char *dir = sc->texture_path[i];
        size_t n = strlen(dir) + strlen(name) + 2;
        char *path = malloc(n);
        if (!path) abort();
        if (strcmp(dir, ".") == 0) snprintf(path, n, "%s", name);
        else snprintf(path, n, "%s%s%s", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", name);
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) return path;
        free(path);
    }
    return NULL;
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
    if (self->nfiles >= MAX_JOB_FILES) {
        sl_diag_error(diag, pos, "file '%s': a job reads at most %d files", name, MAX_JOB_FILES);
        free(path);
        return false;
    }
    char hex[HASH_HEX_SIZE], why[300];
    uint64_t size = 0;
    if (!hash_file(path, hex, &size, why, sizeof why)) {
        sl_diag_error(diag, pos, "file '%s' (found as '%s' on the texture search path) cannot be "
                      "read: %s; fix its permissions or remove it", name, path, why);
        free(path);
        return false;
    }
    bool ok = job_add_file(self, name, hex, size, why, sizeof why);
    if (ok) job_file_set_path(self, self->nfiles - 1, path);
    else sl_diag_error(diag, pos, "%s", why);
    free(path);
    return ok;
}

bool job_collect_files(job *self, const job_scene *js, sl_diag *diag)
{
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

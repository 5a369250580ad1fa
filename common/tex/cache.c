/*
 * cache.c: the per-process texture cache (tex.h): one copy of each
 * texture, opened by name through a resolver on first use and shared by
 * every thread; and the default resolver, a texture search path.
 *
 * Thread safety: a mutex guards the table; the first thread to ask for a
 * name resolves and reads the file while holding it (others asking then
 * wait rather than read the file twice). Textures are never freed before
 * the cache, so a pointer handed out stays valid: the shading VM keeps
 * them per run without the lock (sl_vm_set_textures).
 *
 * Memory: an aafarm-maketx file opens with its large levels in tiles
 * (tiles.c) in a pool with a byte budget, the process's unless
 * tex_cache_set_tiles says otherwise; the cache's own budget counts what
 * stays in memory for good (tex_bytes).
 */
#include "tex/tex_internal.h"
#include "util/err.h"
#include "util/xalloc.h"

#include <assert.h>
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct tex_entry {
    char *name;
    tex_texture *tex;
} tex_entry;

struct tex_cache {
    pthread_mutex_t lock;
    tex_entry *entries;
    int n, cap;
    size_t bytes, budget;
    tex_resolve_fn resolve;
    void *resolve_ctx;
    tex_tiles *tiles;        /* NULL: the process's pool */
};

tex_cache *tex_cache_new(size_t budget)
{
    tex_cache *self = xcalloc(1, sizeof *self);
    pthread_mutex_init(&self->lock, NULL);
    self->budget = budget;
    return self;
}

void tex_cache_destroy(tex_cache **self_p)
{
    tex_cache *self = *self_p;
    if (!self)
        return;
    for (int i = 0; i < self->n; i++) {
        free(self->entries[i].name);
        tex_destroy(&self->entries[i].tex);
    }
    free(self->entries);
    pthread_mutex_destroy(&self->lock);
    free(self);
    *self_p = NULL;
}

void tex_cache_set_resolver(tex_cache *self, tex_resolve_fn fn, void *ctx)
{
    pthread_mutex_lock(&self->lock);
    self->resolve = fn;
    self->resolve_ctx = ctx;
    pthread_mutex_unlock(&self->lock);
}

void tex_cache_set_tiles(tex_cache *self, tex_tiles *pool)
{
    pthread_mutex_lock(&self->lock);
    self->tiles = pool;
    pthread_mutex_unlock(&self->lock);
}

static tex_texture *find(const tex_cache *self, const char *name)
{
    for (int i = 0; i < self->n; i++)
        if (strcmp(self->entries[i].name, name) == 0)
            return self->entries[i].tex;
    return NULL;
}

static void add(tex_cache *self, const char *name, tex_texture *t)
{
    if (self->n == self->cap) {
        self->cap = self->cap ? 2 * self->cap : 8;
        self->entries = xreallocarray(self->entries, (size_t)self->cap, sizeof *self->entries);
    }
    assert(self->n < self->cap && !find(self, name));   /* one entry per name */
    self->entries[self->n].name = xstrdup(name);
    self->entries[self->n].tex = t;
    self->n++;
    self->bytes += tex_bytes(t);
}

const tex_texture *tex_cache_get(tex_cache *self, const char *name, char *err, size_t errsz)
{
    pthread_mutex_lock(&self->lock);
    tex_texture *t = find(self, name);
    if (t) {
        pthread_mutex_unlock(&self->lock);
        return t;
    }
    char path[4096], reason[ERR_LEN] = "";
    if (self->resolve) {
        if (!self->resolve(self->resolve_ctx, name, path, sizeof path, reason, sizeof reason)) {
            err_set(err, errsz, "texture '%s': %s", name, reason);
            pthread_mutex_unlock(&self->lock);
            return NULL;
        }
    } else {
        snprintf(path, sizeof path, "%s", name);
    }
    t = tex_open_in(path, self->tiles ? self->tiles : tex_tiles_process(), err, errsz);
    if (t && self->budget && self->bytes + tex_bytes(t) > self->budget) {
        err_set(err, errsz, "texture '%s': its pyramids take %zu bytes and the textures "
                "already open %zu, over the budget of %zu bytes; raise the texture memory "
                "budget or use smaller maps", name, tex_bytes(t), self->bytes, self->budget);
        tex_destroy(&t);
        t = NULL;
    }
    if (t)
        add(self, name, t);
    pthread_mutex_unlock(&self->lock);
    return t;
}

bool tex_cache_put(tex_cache *self, const char *name, tex_texture *t)
{
    pthread_mutex_lock(&self->lock);
    bool ok = !find(self, name);
    if (ok)
        add(self, name, t);
    pthread_mutex_unlock(&self->lock);
    if (!ok)
        tex_destroy(&t);
    return ok;
}

size_t tex_cache_bytes(const tex_cache *self)
{
    return self->bytes;
}

/* ---- the texture search path ---- */

static bool is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

bool tex_searchpath_resolve(void *ctx, const char *name, char *path, size_t path_size,
                            char *err, size_t errsz)
{
    const tex_searchpath *sp = ctx;
    const char *base = sp && sp->base[0] ? sp->base : ".";
    if (name[0] == '/') {
        snprintf(path, path_size, "%s", name);
        if (is_file(path))
            return true;
        return err_set(err, errsz, "no file %s", name);
    }
    const char *s = sp ? sp->path : "";
    for (;;) {               /* each folder of the path; "&" and "@" are the base */
        const char *colon = strchr(s, ':');
        size_t len = colon ? (size_t)(colon - s) : strlen(s);
        if (len > 0) {
            bool here = (len == 1 && (s[0] == '&' || s[0] == '@'));
            if (here)
                snprintf(path, path_size, "%s/%s", base, name);
            else if (s[0] == '/')
                snprintf(path, path_size, "%.*s/%s", (int)len, s, name);
            else
                snprintf(path, path_size, "%s/%.*s/%s", base, (int)len, s, name);
            if (is_file(path))
                return true;
        }
        if (!colon)
            break;
        s = colon + 1;
    }
    snprintf(path, path_size, "%s/%s", base, name);   /* the scene's folder last */
    if (is_file(path))
        return true;
    err_set(err, errsz, "not found in the scene's folder %s nor on the texture "
            "search path \"%s\"; add its folder with Option \"searchpath\" \"texture\" "
            "[\"dir:&\"]", base, sp ? sp->path : "");
    return false;
}

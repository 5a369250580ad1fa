/*
 * source.c: the in-memory source set and the #include resolver (see
 * source.h for the rules).
 *
 * The set is a plain array of heap-allocated entries searched linearly: a
 * shader job holds a handful of files, and every pointer handed out stays
 * valid until the set is destroyed (entries are never moved or replaced).
 */
#include "sl/source.h"
#include "util/xalloc.h"

#include <assert.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct sl_source_set {
    sl_source **items;
    size_t count, cap;
    size_t max_size;
    sl_source_loader loader;
    void *loader_arg;
};

/* ---------------------------------------------------------------------- */
/* names                                                                   */
/* ---------------------------------------------------------------------- */

char *sl_source_normalize(const char *name)
{
    size_t n = strlen(name);
    bool absolute = n > 0 && name[0] == '/';
    /* the result is never longer than the input, except "." and "/" */
    char *out = xmalloc(n + 2);
    size_t len = 0;
    size_t depth = 0;     /* components in out that a ".." may cancel */
    if (absolute)
        out[len++] = '/';
    size_t root = len;

    const char *p = name;
    while (*p) {
        while (*p == '/')
            p++;
        const char *start = p;
        while (*p && *p != '/')
            p++;
        size_t clen = (size_t)(p - start);
        if (clen == 0 || (clen == 1 && start[0] == '.'))
            continue;
        if (clen == 2 && start[0] == '.' && start[1] == '.') {
            if (depth > 0) {               /* drop the last component */
                while (len > root && out[len - 1] != '/')
                    len--;
                if (len > root)
                    len--;                 /* its separator */
                depth--;
                continue;
            }
            if (absolute)                  /* "/.." is "/" */
                continue;
        } else {
            depth++;
        }
        if (len > root)
            out[len++] = '/';
        memcpy(out + len, start, clen);
        len += clen;
    }
    if (len == 0)
        out[len++] = '.';
    out[len] = '\0';
    return out;
}

/* Directory part of a normalized name: "" when it has none. malloc'd. */
static char *dir_of(const char *name)
{
    const char *slash = strrchr(name, '/');
    size_t len = slash ? (size_t)(slash - name) : 0;
    if (slash == name)
        len = 1;                           /* "/x" lives in "/" */
    char *dir = xmalloc(len + 1);
    memcpy(dir, name, len);
    dir[len] = '\0';
    return dir;
}

/* dir + "/" + name, normalized. malloc'd. */
static char *join(const char *dir, const char *name)
{
    size_t dl = strlen(dir), nl = strlen(name);
    char *tmp = xmalloc(dl + nl + 2);
    memcpy(tmp, dir, dl);
    tmp[dl] = '/';
    memcpy(tmp + dl + 1, name, nl + 1);
    char *result = sl_source_normalize(dl ? tmp : name);
    free(tmp);
    return result;
}

/* ---------------------------------------------------------------------- */
/* the set                                                                 */
/* ---------------------------------------------------------------------- */

sl_source_set *sl_source_set_new(void)
{
    sl_source_set *self = xmalloc(sizeof *self);
    memset(self, 0, sizeof *self);
    self->max_size = SL_SOURCE_DEFAULT_MAX_SIZE;
    return self;
}

void sl_source_set_destroy(sl_source_set **self_p)
{
    if (!self_p || !*self_p)
        return;
    sl_source_set *self = *self_p;
    for (size_t i = 0; i < self->count; i++) {
        free((char *)self->items[i]->name);
        free((char *)self->items[i]->text);
        free(self->items[i]);
    }
    free(self->items);
    free(self);
    *self_p = NULL;
}

void sl_source_set_set_max_size(sl_source_set *self, size_t max_bytes)
{
    self->max_size = max_bytes;
}

size_t sl_source_set_max_size(const sl_source_set *self) { return self->max_size; }

static const sl_source *find_normalized(const sl_source_set *self, const char *name)
{
    for (size_t i = 0; i < self->count; i++)
        if (strcmp(self->items[i]->name, name) == 0)
            return self->items[i];
    return NULL;
}

const sl_source *sl_source_set_find(const sl_source_set *self, const char *name)
{
    char *norm = sl_source_normalize(name);
    const sl_source *src = find_normalized(self, norm);
    free(norm);
    return src;
}

/* Stores the entry; `text` (len + 1 bytes, NUL-terminated) becomes the set's. */
static int add_owned(sl_source_set *self, const char *name, char *text, size_t len)
{
    if (!name || !*name) {
        free(text);
        errno = EINVAL;
        return -1;
    }
    if (len > self->max_size) {
        free(text);
        errno = EFBIG;
        return -1;
    }
    char *norm = sl_source_normalize(name);
    const sl_source *old = find_normalized(self, norm);
    if (old) {
        free(norm);
        bool same = old->len == len && memcmp(old->text, text, len) == 0;
        free(text);
        if (same)
            return 0;
        errno = EEXIST;
        return -1;
    }
    sl_source *src = xmalloc(sizeof *src);
    src->name = norm;
    src->text = text;
    src->len = len;
    if (self->count == self->cap) {
        self->cap = self->cap ? 2 * self->cap : 8;
        self->items = xrealloc(self->items, self->cap * sizeof *self->items);
    }
    self->items[self->count++] = src;
    return 0;
}

int sl_source_set_add(sl_source_set *self, const char *name, const char *text, size_t len)
{
    if (!name || !*name) {
        errno = EINVAL;
        return -1;
    }
    if (len > self->max_size) {
        errno = EFBIG;
        return -1;
    }
    char *copy = xmalloc(len + 1);
    if (len)
        memcpy(copy, text, len);
    copy[len] = '\0';
    return add_owned(self, name, copy, len);
}

int sl_source_set_adopt(sl_source_set *self, const char *name, char *text, size_t len)
{
    assert(text && text[len] == '\0');   /* the caller's promise */
    return add_owned(self, name, text, len);
}

size_t sl_source_set_count(const sl_source_set *self) { return self->count; }

const sl_source *sl_source_set_at(const sl_source_set *self, size_t index)
{
    return index < self->count ? self->items[index] : NULL;
}

const char *sl_source_set_line(const sl_source_set *self, const char *name,
                               int line, size_t *len)
{
    const sl_source *src = find_normalized(self, name);
    if (!src || line < 1)
        return NULL;
    const char *p = src->text, *end = src->text + src->len;
    /* a line ends in LF, CR-LF or a lone CR (as sl_scanner_clean reads it) */
    for (int l = 1; l < line; l++) {
        while (p < end && *p != '\n' && *p != '\r')
            p++;
        if (p == end)
            return NULL;
        p += *p == '\r' && p + 1 < end && p[1] == '\n' ? 2 : 1;
    }
    const char *eol = p;
    while (eol < end && *eol != '\n' && *eol != '\r')
        eol++;
    *len = (size_t)(eol - p);
    return p;
}

/* ---------------------------------------------------------------------- */
/* loading from disk                                                       */
/* ---------------------------------------------------------------------- */

static sl_pos no_pos(void)
{
    sl_pos pos = { NULL, 0, 0 };
    return pos;
}

/* Reads a whole file, at most max bytes. Returns 0, 1 (does not exist),
 * -1 (reported). */
static int read_file(const char *path, size_t max, char **text, size_t *len,
                     sl_diag *diag, bool missing_is_error)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (!missing_is_error && (errno == ENOENT || errno == ENOTDIR))
            return 1;
        if (diag)
            sl_diag_error(diag, no_pos(), "cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    size_t cap = 4096, n = 0;
    char *buf = xmalloc(cap);
    for (;;) {
        if (n == cap) {
            cap *= 2;
            buf = xrealloc(buf, cap);
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n > max) {
            if (diag)
                sl_diag_error(diag, no_pos(), "'%s' is too large (more than %zu bytes)",
                              path, max);
            free(buf);
            fclose(f);
            return -1;
        }
        if (got == 0)
            break;
    }
    if (ferror(f)) {
        int err = errno;
        if (diag)
            sl_diag_error(diag, no_pos(), "cannot read '%s': %s", path, strerror(err));
        free(buf);
        fclose(f);
        return -1;
    }
    fclose(f);
    *text = buf;
    *len = n;
    return 0;
}

static int add_loaded(sl_source_set *self, const char *name, const char *path,
                      char *text, size_t len, sl_diag *diag)
{
    int rc = sl_source_set_add(self, name, text, len);
    if (rc < 0 && diag)
        sl_diag_error(diag, no_pos(), "cannot add '%s' as '%s': %s", path, name,
                      errno == EEXIST ? "a different source has that name"
                                      : strerror(errno));
    free(text);
    return rc;
}

int sl_source_set_load_file(sl_source_set *self, const char *path,
                            const char *name, sl_diag *diag)
{
    char *text;
    size_t len;
    if (read_file(path, self->max_size, &text, &len, diag, true) != 0)
        return -1;
    return add_loaded(self, name ? name : path, path, text, len, diag);
}

int sl_source_load_from_disk(sl_source_set *set, const char *name, sl_diag *diag, void *arg)
{
    (void)arg;
    char *text;
    size_t len;
    int rc = read_file(name, set->max_size, &text, &len, diag, false);
    if (rc != 0)
        return rc;
    return add_loaded(set, name, name, text, len, diag) == 0 ? 0 : -1;
}

void sl_source_set_set_loader(sl_source_set *self, sl_source_loader loader, void *arg)
{
    self->loader = loader;
    self->loader_arg = arg;
}

/* Looks a normalized name up, asking the loader when it is missing.
 * *failed is set when the loader reported an error. */
static const sl_source *get_normalized(sl_source_set *self, const char *name,
                                       sl_diag *diag, bool *failed)
{
    const sl_source *src = find_normalized(self, name);
    if (src || !self->loader)
        return src;
    int rc = self->loader(self, name, diag, self->loader_arg);
    if (rc < 0)
        *failed = true;
    return rc == 0 ? find_normalized(self, name) : NULL;
}

const sl_source *sl_source_set_get(sl_source_set *self, const char *name, sl_diag *diag)
{
    char *norm = sl_source_normalize(name);
    bool failed = false;
    const sl_source *src = get_normalized(self, norm, diag, &failed);
    free(norm);
    return src;
}

/* ---------------------------------------------------------------------- */
/* #include resolution                                                     */
/* ---------------------------------------------------------------------- */

static void list_add(char **list, size_t *len, const char *dir)
{
    const char *shown = *dir ? dir : ".";
    size_t add = strlen(shown) + (*len ? 2 : 0);
    *list = xrealloc(*list, *len + add + 1);
    if (*len) {
        memcpy(*list + *len, ", ", 2);
        *len += 2;
    }
    memcpy(*list + *len, shown, strlen(shown) + 1);
    *len += strlen(shown);
}

const sl_source *sl_source_set_resolve(sl_source_set *self, const char *name,
                                       const char *includer,
                                       const char *const *search_path, bool quoted,
                                       sl_diag *diag, char **searched)
{
    char *tried = NULL;
    size_t tried_len = 0;
    const sl_source *found = NULL;
    bool failed = false;

    if (searched)
        *searched = NULL;
    if (!name || !*name)
        return NULL;

    if (name[0] == '/') {
        char *norm = sl_source_normalize(name);
        found = get_normalized(self, norm, diag, &failed);
        free(norm);
        list_add(&tried, &tried_len, "/");
    } else {
        if (quoted) {
            char *dir = dir_of(includer ? includer : "");
            char *cand = join(dir, name);
            found = get_normalized(self, cand, diag, &failed);
            list_add(&tried, &tried_len, dir);
            free(cand);
            free(dir);
        }
        for (size_t i = 0; !found && !failed && search_path && search_path[i]; i++) {
            char *cand = join(search_path[i], name);
            found = get_normalized(self, cand, diag, &failed);
            list_add(&tried, &tried_len, search_path[i]);
            free(cand);
        }
    }
    if (!found && searched)
        *searched = tried ? tried : NULL;
    else
        free(tried);
    return found;
}

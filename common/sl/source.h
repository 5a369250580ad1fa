/*
 * source.h: the source set (sl_source_set), an in-memory map from source
 * names to source texts, and the #include resolver over it.
 *
 * Why in memory: a worker receives the shader sources of a job over the
 * network and has no access to the master's file system, so the
 * preprocessor never opens files itself; it resolves every #include against
 * this set. The master (or a CLI) fills the set from disk, either up front
 * (sl_source_set_load_file) or on demand through a loader callback
 * (sl_source_set_set_loader with sl_source_load_from_disk); after compiling,
 * the set holds exactly the files the shader needed and can be shipped with
 * the job (sl_source_set_count / sl_source_set_at). A worker sets no loader.
 *
 * Names are '/'-separated paths, normalized lexically when stored and when
 * looked up: "." components and empty components are dropped and "dir/.."
 * pairs cancel ("shaders/./lib/../wave.sl" is "shaders/wave.sl"); leading
 * ".." of a relative name stay; no symbolic links are followed. A name that
 * normalizes to nothing is ".".
 *
 * Resolution of `#include "x.h"` in file "shaders/wave.sl": first the
 * directory of the including file ("shaders/x.h"), then each directory of
 * the search path in order ("dir/x.h"); `#include <x.h>` skips the
 * including file's directory; an absolute name is tried as is. For each
 * candidate, the set is consulted, then the loader (if any).
 *
 * Limits: a source is at most sl_source_set_max_size() bytes (default
 * SL_SOURCE_DEFAULT_MAX_SIZE). Texts may contain any bytes, NUL included.
 */
#ifndef SL_SOURCE_H
#define SL_SOURCE_H

#include <stdbool.h>
#include <stddef.h>

#include "sl/diag.h"

enum { SL_SOURCE_DEFAULT_MAX_SIZE = 4 << 20 };   /* bytes per source */

typedef struct sl_source {
    const char *name;   /* normalized name */
    const char *text;   /* the bytes, followed by a NUL not counted in len */
    size_t len;
} sl_source;

typedef struct sl_source_set sl_source_set;

/* A loader: make `name` (a normalized candidate name) available in `set`,
 * typically by reading it from disk and calling sl_source_set_add.
 * Returns 0 when the source was added, 1 when it does not exist (the
 * resolver tries the next candidate), -1 on another failure, which the
 * loader has reported to diag (when diag is not NULL). */
typedef int (*sl_source_loader)(sl_source_set *set, const char *name,
                                sl_diag *diag, void *arg);

sl_source_set *sl_source_set_new(void);
void sl_source_set_destroy(sl_source_set **self_p);

void sl_source_set_set_max_size(sl_source_set *self, size_t max_bytes);
size_t sl_source_set_max_size(const sl_source_set *self);

/* Adds a copy of text[0..len) under the normalized name. Adding the same
 * text again under the same name is a no-op. Returns 0, or -1 with errno
 * EINVAL (empty name), EFBIG (larger than the maximum size) or EEXIST (the
 * name is taken by a different text). Pointers returned by the set stay
 * valid until it is destroyed. */
int sl_source_set_add(sl_source_set *self, const char *name, const char *text, size_t len);

/* As sl_source_set_add, but the set takes `text` itself (no copy: a big
 * archive is held once): malloc'd, at least len + 1 bytes, text[len] ==
 * '\0'. On failure, and when the same text is there already, it is freed. */
int sl_source_set_adopt(sl_source_set *self, const char *name, char *text, size_t len);

/* Reads the file at `path` into the set under `name` (NULL: the path
 * itself). Failures are reported to diag (if not NULL) as errors without
 * position, e.g. "cannot open 'x.sl': No such file or directory" or
 * "'big.sl' is too large (more than 4194304 bytes)". Returns 0 or -1. */
int sl_source_set_load_file(sl_source_set *self, const char *path,
                            const char *name, sl_diag *diag);

/* The loader consulted when a name is not in the set (NULL: none). */
void sl_source_set_set_loader(sl_source_set *self, sl_source_loader loader, void *arg);

/* A ready-made loader that reads `name` as a path relative to the current
 * directory (arg unused). Returns 1 when the file does not exist. */
int sl_source_load_from_disk(sl_source_set *set, const char *name, sl_diag *diag, void *arg);

/* The source with this (normalized) name: sl_source_set_find looks only in
 * the set, sl_source_set_get also asks the loader. NULL when absent. */
const sl_source *sl_source_set_find(const sl_source_set *self, const char *name);
const sl_source *sl_source_set_get(sl_source_set *self, const char *name, sl_diag *diag);

/* Iteration over the stored sources, in the order added. */
size_t sl_source_set_count(const sl_source_set *self);
const sl_source *sl_source_set_at(const sl_source_set *self, size_t index);

/* Text of line `line` (1-based) of source `name`, without its line end
 * ("\n" or "\r\n"); *len receives its length. NULL if there is no such
 * source or line. */
const char *sl_source_set_line(const sl_source_set *self, const char *name,
                               int line, size_t *len);

/* Resolves an #include (see above): `name` as written between the quotes
 * or brackets, `includer` the name of the including source, `quoted` true
 * for "x.h" and false for <x.h>, search_path a NULL-terminated list of
 * directories (may be NULL). Returns the source, or NULL; then, if
 * `searched` is not NULL, *searched receives a malloc'd, comma-separated
 * list of the directories tried, as written ("." for the top directory),
 * e.g. "shaders, lib, /usr/share/sl" (the caller frees it). */
const sl_source *sl_source_set_resolve(sl_source_set *self, const char *name,
                                       const char *includer,
                                       const char *const *search_path, bool quoted,
                                       sl_diag *diag, char **searched);

/* Lexical normalization of a name (see above); returns a malloc'd string. */
char *sl_source_normalize(const char *name);

#endif

/*
 * job.c: building, checking and hashing render jobs (see job.h).
 */
#include "job/job.h"
#include "util/err.h"
#include "util/parse_num.h"
#include "util/suggest.h"
#include "util/xalloc.h"

#include <assert.h>
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "job/job_internal.h"
#include "job/job_scene.h"
#include "scene/scene.h"
#include "sl/standard.h"

void job_options_default(job_options *opt)
{
    opt->arith = TRACE_ARITH_AFFINE;
    opt->tile_size = 32;
    opt->max_instructions = 1000000;
    opt->frame = 0;
}

bool job_options_parse_arg(job_options *self, const char *opt, const char *text, char *err,
                           size_t errsz)
{
    long n;
    if (strcmp(opt, "--arith") == 0) {
        if (trace_arith_parse(text, &self->arith)) return true;
        return err_set(err, errsz, "--arith wants 'affine' or 'interval', got '%s'", text);
    }
    if (strcmp(opt, "--tile") == 0) {
        if (!parse_option_long(opt, "a size", text, JOB_TILE_SIZE_MIN, JOB_TILE_SIZE_MAX, &n, err,
                               errsz))
            return false;
        self->tile_size = (int)n;
        return true;
    }
    assert(strcmp(opt, "--budget") == 0);
    if (!parse_option_long(opt, "a number", text, JOB_BUDGET_MIN, JOB_BUDGET_MAX, &n, err, errsz))
        return false;
    self->max_instructions = n;
    return true;
}

const char *trace_arith_name(trace_arith arith)
{
    return arith == TRACE_ARITH_INTERVAL ? "interval" : "affine";
}

bool trace_arith_parse(const char *text, trace_arith *out)
{
    if (strcmp(text, "affine") == 0) { *out = TRACE_ARITH_AFFINE; return true; }
    if (strcmp(text, "interval") == 0) { *out = TRACE_ARITH_INTERVAL; return true; }
    return false;
}

job *job_new(const char *scene_file, const char *scene_text, size_t scene_len,
             const job_options *options)
{
    job *self = xcalloc(1, sizeof *self);
    self->scene_file = xstrdup(scene_file);
    self->scene_text = xstrndup(scene_text, scene_len);
    self->scene_len = scene_len;
    self->sources = sl_source_set_new();
    if (options) self->options = *options;
    else job_options_default(&self->options);
    return self;
}

void job_destroy(job **self_p)
{
    job *self = *self_p;
    if (!self) return;
    free(self->scene_file);
    free(self->scene_text);
    sl_source_set_destroy(&self->sources);
    for (int i = 0; i < self->nshaders; i++) {
        free(self->shaders[i].name);
        free(self->shaders[i].file);
    }
    free(self->shaders);
    free(self->frame_numbers);
    free(self->display_name);
    for (int i = 0; i < self->nfiles; i++) {
        free(self->files[i].name);
        free(self->files[i].path);
    }
    free(self->files);
    free(self);
    *self_p = NULL;
}

bool job_add_source(job *self, const char *name, const char *text, size_t len,
                    char *err, size_t errsz)
{
    if (sl_source_set_add(self->sources, name, text, len) == 0) return true;
    if (errno == EFBIG)
        err_set(err, errsz, "shader source '%s' is larger than %zu bytes",
                name, sl_source_set_max_size(self->sources));
    else if (errno == EEXIST)
        err_set(err, errsz, "two different shader sources named '%s'", name);
    else
        err_set(err, errsz, "invalid shader source name '%s'", name);
    return false;
}

const char *job_shader_file(const job *self, const char *name)
{
    for (int i = 0; i < self->nshaders; i++)
        if (strcmp(self->shaders[i].name, name) == 0) return self->shaders[i].file;
    return NULL;
}

bool job_add_shader(job *self, const char *name, const char *file,
                    char *err, size_t errsz)
{
    if (!*name || !*file) {
        return err_set(err, errsz, "a shader entry with an empty name or file");
    }
    if (job_shader_file(self, name)) {
        return err_set(err, errsz, "shader '%s' listed twice", name);
    }
    self->shaders = xrealloc(self->shaders, sizeof(job_shader) * (size_t)(self->nshaders + 1));
    self->shaders[self->nshaders].name = xstrdup(name);
    self->shaders[self->nshaders].file = xstrdup(file);
    self->nshaders++;
    return true;
}

job_file *job_file_find(const job *self, const char *name)
{
    for (int i = 0; i < self->nfiles; i++)
        if (strcmp(self->files[i].name, name) == 0) return &self->files[i];
    return NULL;
}

bool job_add_file(job *self, const char *name, const char *hex, uint64_t size,
                  char *err, size_t errsz)
{
    if (!*name) {
        return err_set(err, errsz, "a file entry with an empty name");
    }
    if (!hash_hex_valid(hex)) {
        return err_set(err, errsz, "file '%s': its SHA-256 is not 64 lowercase hex digits",
                       name);
    }
    if (job_file_find(self, name)) {
        return err_set(err, errsz, "file '%s' listed twice", name);
    }
    self->files = xrealloc(self->files, sizeof(job_file) * (size_t)(self->nfiles + 1));
    job_file *f = &self->files[self->nfiles++];
    memset(f, 0, sizeof *f);
    f->name = xstrdup(name);
    snprintf(f->sha256, sizeof f->sha256, "%s", hex);
    f->size = size;
    return true;
}

void job_file_set_path(job *self, int i, const char *path)
{
    assert(i >= 0 && i < self->nfiles);
    free(self->files[i].path);
    self->files[i].path = path ? xstrdup(path) : NULL;
}

uint64_t job_files_bytes(const job *self)
{
    uint64_t n = 0;
    for (int i = 0; i < self->nfiles; i++) n += self->files[i].size;
    return n;
}

bool job_file_resolve(void *jb, const char *name, char *path, size_t path_size, char *err,
                      size_t errsz)
{
    const job *self = jb;
    const job_file *f = self ? job_file_find(self, name) : NULL;
    if (!f) {
        return err_set(err, errsz, "'%s' is not one of the job's files (none of that name "
                       "was found on the texture search path when the job was loaded: add its folder "
                       "with Option \"searchpath\" \"texture\" [\"dir:&\"])", name);
    }
    if (!f->path) {
        return err_set(err, errsz, "file '%s' (%.12s...) is not present on this host yet",
                       name, f->sha256);
    }
    if (strlen(f->path) >= path_size) {
        return err_set(err, errsz, "the path of file '%s' is longer than %zu bytes", name,
                       path_size - 1);
    }
    memcpy(path, f->path, strlen(f->path) + 1);
    return true;
}

bool job_finish(job *self, char *err, size_t errsz)
{
    for (int i = 0; i < self->nshaders; i++)
        if (!sl_source_set_find(self->sources, self->shaders[i].file)) {
            return err_set(err, errsz, "shader '%s': its source '%s' is missing from the job",
                           self->shaders[i].name, self->shaders[i].file);
        }
    if (self->options.frame < 0) {
        return err_set(err, errsz, "frame index %d is out of range", self->options.frame);
    }
    size_t nsrc = sl_source_set_count(self->sources);
    hash_shader *hs = xcalloc(nsrc + 1, sizeof *hs);
    int nopt = 3 + self->nshaders + self->nfiles + (self->options.frame != 0);
    hash_option *ho = xcalloc((size_t)nopt, sizeof *ho);
    /* a file enters the hash as option "file:<name>" = "<sha256>:<size>" */
    char **file_keys = xcalloc((size_t)self->nfiles + 1, sizeof *file_keys);
    char (*file_vals)[HASH_HEX_SIZE + 24] = xcalloc((size_t)self->nfiles + 1, sizeof *file_vals);
    char (*keys)[160] = xcalloc((size_t)nopt, sizeof *keys);
    char (*vals)[600] = xcalloc((size_t)nopt, sizeof *vals);
    for (size_t i = 0; i < nsrc; i++) {
        const sl_source *s = sl_source_set_at(self->sources, i);
        hs[i] = (hash_shader){s->name, s->text, s->len};
    }
    snprintf(keys[0], sizeof keys[0], "arith");
    snprintf(vals[0], sizeof vals[0], "%s", trace_arith_name(self->options.arith));
    snprintf(keys[1], sizeof keys[1], "tile_size");
    snprintf(vals[1], sizeof vals[1], "%d", self->options.tile_size);
    snprintf(keys[2], sizeof keys[2], "max_instructions");
    snprintf(vals[2], sizeof vals[2], "%ld", self->options.max_instructions);
    for (int i = 0; i < self->nshaders; i++) {
        snprintf(keys[3 + i], sizeof keys[0], "shader:%s", self->shaders[i].name);
        snprintf(vals[3 + i], sizeof vals[0], "%s", self->shaders[i].file);
    }
    for (int i = 0; i < 3 + self->nshaders; i++) ho[i] = (hash_option){keys[i], vals[i]};
    for (int i = 0; i < self->nfiles; i++) {
        size_t n = strlen(self->files[i].name) + 6;
        file_keys[i] = xmalloc(n);
        snprintf(file_keys[i], n, "file:%s", self->files[i].name);
        snprintf(file_vals[i], sizeof file_vals[i], "%s:%llu", self->files[i].sha256,
                 (unsigned long long)self->files[i].size);
        ho[3 + self->nshaders + i] = (hash_option){file_keys[i], file_vals[i]};
    }
    assert(3 + self->nshaders + self->nfiles + (self->options.frame != 0) == nopt);
    if (self->options.frame != 0) {   /* absent for frame 0: older hashes stay */
        snprintf(keys[nopt - 1], sizeof keys[0], "frame");
        snprintf(vals[nopt - 1], sizeof vals[0], "%d", self->options.frame);
        ho[nopt - 1] = (hash_option){keys[nopt - 1], vals[nopt - 1]};
    }
    hash_job_input in = {self->scene_file, self->scene_text, self->scene_len,
                         hs, nsrc, ho, (size_t)nopt};
    int rc = hash_job(&in, self->hash);
    for (int i = 0; i < self->nfiles; i++) free(file_keys[i]);
    free(file_keys);
    free(file_vals);
    free(hs);
    free(ho);
    free(keys);
    free(vals);
    if (rc != 0) {
        return err_set(err, errsz, "the job cannot be hashed (duplicate names)");
    }
    return true;
}

static char *read_file(const char *path, size_t *len, sl_diag *diag)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        sl_diag_error(diag, (sl_pos){0}, "cannot open scene '%s': %s", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = xmalloc(cap);
    size_t got;
    while ((got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            if (cap >= (size_t)64 << 20) {
                sl_diag_error(diag, (sl_pos){0}, "scene '%s' is larger than 64 MiB", path);
                free(buf);
                fclose(f);
                return NULL;
            }
            cap *= 2;
            buf = xrealloc(buf, cap);
        }
    }
    bool bad = ferror(f);
    fclose(f);
    if (bad) {
        sl_diag_error(diag, (sl_pos){0}, "cannot read scene '%s'", path);
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

char *job_read_scene(const char *rib_path, size_t *len, sl_diag *diag)
{
    return read_file(rib_path, len, diag);
}

/* The shader name closest to an unknown one (util/suggest.h), among the
 * NAME.sl files of the scene's shader search path and the standard
 * shaders; written to out ("" when none is near). */
static void closest_shader(const scene *sc, const char *name, char *out, size_t outsz)
{
    const char **names = NULL;
    int n = 0, cap = 0;
    for (int k = 0; k < sc->nsearch_path; k++) {
        DIR *dir = opendir(sc->search_path[k]);
        if (!dir) continue;
        for (struct dirent *e; (e = readdir(dir)) != NULL;) {
            size_t len = strlen(e->d_name);
            if (len <= 3 || strcmp(e->d_name + len - 3, ".sl") != 0) continue;
            if (n == cap) {
                cap = cap ? 2 * cap : 16;
                names = xreallocarray(names, (size_t)cap, sizeof *names);
            }
            names[n++] = xstrndup(e->d_name, len - 3);
        }
        closedir(dir);
    }
    int nfound = n;
    names = xreallocarray(names, (size_t)(n + sl_standard_nshaders), sizeof *names);
    for (int i = 0; i < sl_standard_nshaders; i++)
        names[n++] = sl_standard_shaders[i].name;
    const char *near = suggest_closest(name, names, n);
    snprintf(out, outsz, "%s", near ? near : "");
    for (int i = 0; i < nfound; i++)
        free((char *)names[i]);
    free(names);
}

job *job_load(const char *rib_path, const job_options *options, const atomic_int *cancel,
              sl_diag *diag)
{
    size_t len = 0;
    char *text = read_file(rib_path, &len, diag);
    if (!text) return NULL;
    /* the archives the scene reads become files of the job (hashed on
     * disk); their texts live only as long as this parse */
    job *self = job_new(rib_path, text, len, options);
    free(text);
    sl_source_set *archives = sl_source_set_new();
    sl_source_set_set_max_size(archives, SCENE_ARCHIVE_MAX_BYTES);
    sl_source_set_set_loader(archives, job_archive_load_from_disk, self);
    /* one parse, a check's (issue 23): the master keeps no mesh arrays
     * and no references, and checks those as it reads them */
    scene *sc = scene_check_frame(rib_path, self->scene_text, self->scene_len, archives,
                                  SCENE_MAX_OBJECTS, self->options.frame, job_scene_checker(),
                                  cancel, diag);
    sl_source_set_destroy(&archives);
    if (!sc) {
        job_destroy(&self);
        return NULL;
    }
    self->frame_number = sc->frame_number;
    self->nframes = sc->nframes;
    if (sc->nframes > 0) {
        self->frame_numbers = xmalloc(sizeof *self->frame_numbers * (size_t)sc->nframes);
        memcpy(self->frame_numbers, sc->frame_numbers,
               sizeof *self->frame_numbers * (size_t)sc->nframes);
    }
    if (sc->display_name) self->display_name = xstrdup(sc->display_name);
    char err[ERR_LEN];
    bool ok = true;
    for (int i = 0; i < sc->nshader_names; i++) {
        const char *name = sc->shader_names[i];
        char *path = scene_find_shader(sc, name, NULL, NULL);
        const sl_standard_shader *std = path ? NULL : sl_standard_find(name);
        if (std) {
            /* after the search path: the built-in text, shipped like a file */
            char file[64 + sizeof SL_STANDARD_DIR];
            snprintf(file, sizeof file, "%s/%s.sl", SL_STANDARD_DIR, std->name);
            if (!job_add_source(self, file, std->text, std->len, err, sizeof err) ||
                !job_add_shader(self, name, file, err, sizeof err)) {
                sl_diag_error(diag, (sl_pos){0}, "%s", err);
                ok = false;
            }
            continue;
        }
        if (!path) {
            /* point at the first call that names it */
            sl_pos pos = {0};
            for (int k = 0; k < sc->nshaders; k++)
                if (strcmp(sc->shaders[k].name, name) == 0) { pos = sc->shaders[k].pos; break; }
            char dirs[1024] = "";
            for (int k = 0; k < sc->nsearch_path; k++) {
                if (k) strncat(dirs, ", ", sizeof dirs - strlen(dirs) - 1);
                strncat(dirs, sc->search_path[k], sizeof dirs - strlen(dirs) - 1);
            }
            char near[256];
            closest_shader(sc, name, near, sizeof near);
            if (near[0])
                sl_diag_error(diag, pos, "shader '%s' not found (did you mean %s?): looked for "
                              "'%s.sl' in %s", name, near, name, dirs);
            else
                sl_diag_error(diag, pos, "shader '%s' not found: looked for '%s.sl' in %s; "
                              "add its folder with Option \"searchpath\" \"shader\" "
                              "[\"dir:&\"]", name, name, dirs);
            ok = false;
            continue;
        }
        if (sl_source_set_load_file(self->sources, path, path, diag) != 0 ||
            !job_add_shader(self, name, path, err, sizeof err)) {
            ok = false;
        }
        free(path);
    }
    if (ok) {
        /* compiling pulls the #included files into the set, from disk */
        sl_source_set_set_loader(self->sources, sl_source_load_from_disk, NULL);
        job_scene *js = job_scene_check(self, sc, cancel, diag);
        sc = NULL;                     /* the job_scene's */
        sl_source_set_set_loader(self->sources, NULL, NULL);
        ok = js != NULL && job_collect_files(self, js, diag);
        if (ok) {
            self->xres = js->world.camera.xres;
            self->yres = js->world.camera.yres;
        }
        job_scene_destroy(&js);
    }
    scene_destroy(&sc);
    if (ok && !job_finish(self, err, sizeof err)) {
        sl_diag_error(diag, (sl_pos){0}, "%s", err);
        ok = false;
    }
    if (!ok) job_destroy(&self);
    return self;
}

/*
 * frames.c: frame sequences: the --frames choice, the output name of each
 * frame, and loading one job per chosen frame (see frames.h).
 */
#include "job/frames.h"
#include "util/err.h"
#include "util/xalloc.h"
#include "scene/scene.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

enum { FRAME_MAX_NUMBER = 99999999 };

/* ---- --frames ---------------------------------------------------------- */

/* Reads a frame number at *p; false when there is none or it is too big. */
static bool read_number(const char **p, int *out)
{
    const char *s = *p;
    if (!isdigit((unsigned char)*s)) return false;
    long v = 0;
    while (isdigit((unsigned char)*s)) {
        v = v * 10 + (*s++ - '0');
        if (v > FRAME_MAX_NUMBER) return false;
    }
    *out = (int)v;
    *p = s;
    return true;
}

bool frame_spec_parse(const char *text, frame_spec *out, char *err, size_t errsz)
{
    memset(out, 0, sizeof *out);
    if (!text || !*text) {
        err_set(err, errsz, "--frames wants frame numbers, e.g. 3, 1-10 or 1,3,5-7; got an "
                "empty list");
        return false;
    }
    const char *p = text;
    for (;;) {
        const char *item = p;
        int lo, hi;
        bool ok = read_number(&p, &lo);
        hi = lo;
        if (ok && *p == '-') {
            p++;
            ok = read_number(&p, &hi);
        }
        if (!ok || (*p != ',' && *p != '\0')) {
            const char *end = strchr(item, ',');
            int n = end ? (int)(end - item) : (int)strlen(item);
            err_set(err, errsz, "--frames: '%.*s' (at character %d of '%s') is not a frame "
                    "number 0..%d or a range like 5-7", n, item, (int)(item - text) + 1, text,
                    FRAME_MAX_NUMBER);
            frame_spec_clear(out);
            return false;
        }
        if (hi < lo) {
            err_set(err, errsz, "--frames: the range %d-%d runs backwards (write %d-%d)", lo,
                    hi, hi, lo);
            frame_spec_clear(out);
            return false;
        }
        out->ranges = xrealloc(out->ranges, sizeof *out->ranges * (size_t)(out->count + 1));
        out->ranges[out->count][0] = lo;
        out->ranges[out->count][1] = hi;
        out->count++;
        if (*p == '\0') return true;
        p++;   /* ',' */
    }
}

void frame_spec_clear(frame_spec *spec)
{
    free(spec->ranges);
    spec->ranges = NULL;
    spec->count = 0;
}

bool frame_spec_has(const frame_spec *spec, int number)
{
    for (int i = 0; i < spec->count; i++)
        if (number >= spec->ranges[i][0] && number <= spec->ranges[i][1]) return true;
    return false;
}

/* "1-3, 7" for messages: the file's frame numbers, runs collapsed. */
static void describe_numbers(const int *numbers, int n, char *out, size_t outsz)
{
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < n && used + 32 < outsz;) {
        int j = i;
        while (j + 1 < n && numbers[j + 1] == numbers[j] + 1) j++;
        int w = j > i ? snprintf(out + used, outsz - used, "%s%d-%d", i ? ", " : "", numbers[i],
                                 numbers[j])
                      : snprintf(out + used, outsz - used, "%s%d", i ? ", " : "", numbers[i]);
        used += (size_t)w;
        i = j + 1;
    }
}

bool frame_choose(const int *numbers, int n, const frame_spec *spec, int **indices,
                  int *count, char *err, size_t errsz)
{
    static const int one = 1;
    int total = n > 0 ? n : 1;
    if (n == 0) numbers = &one;
    *indices = xmalloc(sizeof **indices * (size_t)total);
    *count = 0;
    for (int i = 0; spec && i < spec->count; i++) {
        bool any = false;
        for (int k = 0; k < total && !any; k++)
            any = numbers[k] >= spec->ranges[i][0] && numbers[k] <= spec->ranges[i][1];
        if (!any) {
            char have[200];
            describe_numbers(numbers, total, have, sizeof have);
            if (spec->ranges[i][0] == spec->ranges[i][1])
                err_set(err, errsz, "--frames: the scene has no frame %d (its frames: %s%s)",
                        spec->ranges[i][0], have, n == 0 ? "; it has no FrameBegin" : "");
            else
                err_set(err, errsz, "--frames: the scene has no frame in %d-%d (its frames: %s%s)",
                        spec->ranges[i][0], spec->ranges[i][1], have,
                        n == 0 ? "; it has no FrameBegin" : "");
            free(*indices);
            *indices = NULL;
            return false;
        }
    }
    for (int k = 0; k < total; k++)
        if (!spec || frame_spec_has(spec, numbers[k])) (*indices)[(*count)++] = k;
    return true;
}

/* ---- output names ------------------------------------------------------ */

/* Does the name hold `number` as a whole run of digits ("0003" for 3)? */
static bool holds_number(const char *name, int number)
{
    for (const char *p = name; *p;) {
        if (!isdigit((unsigned char)*p)) {
            p++;
            continue;
        }
        long v = 0;
        bool big = false;
        while (isdigit((unsigned char)*p)) {
            if (v < FRAME_MAX_NUMBER) v = v * 10 + (*p - '0');
            else big = true;
            p++;
        }
        if (!big && v == number) return true;
    }
    return false;
}

/* Writes name with its % patterns replaced; *patterns counts the frame
 * patterns. NULL with err on a pattern other than %d, %Nd, %0Nd, %%. */
static char *substitute(const char *name, int number, int *patterns, char *err, size_t errsz)
{
    size_t cap = strlen(name) + 64, used = 0;
    char *out = xmalloc(cap);
    *patterns = 0;
    for (const char *p = name; *p;) {
        if (used + 40 >= cap) {
            cap *= 2;
            out = xrealloc(out, cap);
        }
        if (*p != '%') {
            out[used++] = *p++;
            continue;
        }
        const char *q = p + 1;
        if (*q == '%') {
            out[used++] = '%';
            p = q + 1;
            continue;
        }
        bool zero = *q == '0';
        if (zero) q++;
        int width = 0;
        while (isdigit((unsigned char)*q) && width < 100) width = width * 10 + (*q++ - '0');
        if (*q != 'd' || width > 16) {
            err_set(err, errsz, "output name '%s': only %%d, %%4d, %%04d (the frame number) "
                    "and %%%% may follow a %% sign", name);
            free(out);
            return NULL;
        }
        used += (size_t)snprintf(out + used, cap - used, zero ? "%0*d" : "%*d", width, number);
        (*patterns)++;
        p = q + 1;
    }
    out[used] = '\0';
    return out;
}

char *frame_output_name(const char *name, int number, int nframes, bool display,
                        char *err, size_t errsz)
{
    int patterns = 0;
    char *out = substitute(name, number, &patterns, err, errsz);
    if (!out || patterns > 0 || nframes <= 1 || (display && holds_number(name, number)))
        return out;
    /* insert ".NNNN" before the extension of the last path component */
    const char *base = strrchr(out, '/');
    base = base ? base + 1 : out;
    const char *dot = strrchr(base, '.');
    size_t at = dot && dot != base ? (size_t)(dot - out) : strlen(out);
    char *named = xmalloc(strlen(out) + 24);
    snprintf(named, strlen(out) + 24, "%.*s.%04d%s", (int)at, out, number, out + at);
    free(out);
    return named;
}

/* ---- loading a sequence ------------------------------------------------ */

void frame_sequence_destroy(frame_sequence **self_p)
{
    frame_sequence *self = *self_p;
    if (!self) return;
    for (int i = 0; i < self->count; i++) {
        job_destroy(&self->jobs[i]);
        free(self->outputs[i]);
    }
    free(self->jobs);
    free(self->outputs);
    free(self);
    *self_p = NULL;
}

static bool name_outputs(frame_sequence *seq, const char *output, bool *usage, sl_diag *diag)
{
    char err[ERR_LEN];
    sl_pos none = {0};
    for (int i = 0; i < seq->count; i++) {
        const job *jb = seq->jobs[i];
        const char *name = output ? output : jb->display_name;
        if (!name) {
            sl_diag_error(diag, none, "%s needs -o OUT.exr: frame %d has no Display name (in "
                          "a file of several frames each output gets its frame number: "
                          "OUT.%04d.exr)", jb->scene_file, jb->frame_number, jb->frame_number);
            *usage = true;
            return false;
        }
        seq->outputs[i] = frame_output_name(name, jb->frame_number, seq->nframes, !output, err,
                                            sizeof err);
        if (!seq->outputs[i]) {
            sl_diag_error(diag, none, "%s", err);
            *usage = output != NULL;
            return false;
        }
        if (!seq->numbered && !strchr(name, '%') && strcmp(seq->outputs[i], name) != 0)
            seq->numbered = output ? output : jb->display_name;
        for (int k = 0; k < i; k++)
            if (strcmp(seq->outputs[k], seq->outputs[i]) == 0) {
                sl_diag_error(diag, none, "%s: frames %d and %d would both be written to %s; "
                              "give -o a pattern with the frame number, e.g. out.%%04d.exr",
                              jb->scene_file, seq->jobs[k]->frame_number, jb->frame_number,
                              seq->outputs[i]);
                *usage = output != NULL;
                return false;
            }
    }
    return true;
}

/* The file's frame numbers (scene_scan_frames, archives from disk);
 * -1 when the scan fails (its messages are dropped: the caller reports),
 * -2 when the file cannot be read (in diag). */
static int scan_frames(const char *rib_path, int **numbers, const atomic_int *cancel,
                       sl_diag *diag)
{
    size_t len = 0;
    char *text = job_read_scene(rib_path, &len, diag);
    if (!text) return -2;
    sl_diag *quiet = sl_diag_new();
    sl_source_set *archives = scene_archive_set_new();
    int n = scene_scan_frames(rib_path, text, len, archives, numbers, cancel, quiet);
    sl_source_set_destroy(&archives);
    sl_diag_destroy(&quiet);
    free(text);
    return n;
}

/* true when path a and file b are one file (an output not written yet is
 * no file at all) */
static bool same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return a && b && stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* An output that is the scene or a file its shaders read (a texture, often
 * an .exr itself) would be replaced by the image: refused, naming both. */
static bool outputs_spare_inputs(const frame_sequence *seq, const char *rib_path, bool *usage,
                                 sl_diag *diag)
{
    for (int i = 0; i < seq->count; i++) {
        const char *out = seq->outputs[i];
        const char *what = same_file(out, rib_path) ? "the scene file" : NULL, *name = rib_path;
        const job *jb = seq->jobs[i];
        for (int f = 0; !what && f < jb->nfiles; f++)
            if (same_file(out, jb->files[f].path)) {
                what = "the file its shaders read as";
                name = jb->files[f].name;
            }
        if (what) {
            sl_diag_error(diag, (sl_pos){0},
                          "the output %s is %s '%s': writing the image would replace it; "
                          "give another output name (-o)", out, what, name);
            *usage = true;
            return false;
        }
    }
    return true;
}

frame_sequence *frame_sequence_load(const char *rib_path, const job_options *options,
                                    const char *frames, const char *output, bool *usage,
                                    const atomic_int *cancel, sl_diag *diag)
{
    *usage = false;
    char err[ERR_LEN];
    frame_spec spec;
    if (frames && !frame_spec_parse(frames, &spec, err, sizeof err)) {
        sl_diag_error(diag, (sl_pos){0}, "%s", err);
        *usage = true;
        return NULL;
    }
    job_options opt;
    if (options) opt = *options;
    else job_options_default(&opt);
    opt.frame = 0;
    int *numbers = NULL;
    int nframes = scan_frames(rib_path, &numbers, cancel, diag);
    if (nframes == -2) {   /* unreadable: said so */
        if (frames) frame_spec_clear(&spec);
        return NULL;
    }
    if (nframes < 0) {
        /* the file does not parse outside its frames: loading the first
         * frame reports why (with file:line:col) */
        job *first = job_load(rib_path, &opt, cancel, diag);
        if (first) sl_diag_error(diag, (sl_pos){0}, "%s: cannot tell its frames", rib_path);
        job_destroy(&first);
        if (frames) frame_spec_clear(&spec);
        return NULL;
    }
    int *indices = NULL, count = 0;
    bool ok = frame_choose(numbers, nframes, frames ? &spec : NULL, &indices, &count, err,
                           sizeof err);
    free(numbers);
    if (!ok) sl_diag_error(diag, (sl_pos){0}, "%s", err);
    if (frames) frame_spec_clear(&spec);
    if (!ok) *usage = true;
    if (!ok) return NULL;
    frame_sequence *seq = xcalloc(1, sizeof *seq);
    seq->nframes = nframes;
    seq->jobs = xcalloc((size_t)count, sizeof *seq->jobs);
    seq->outputs = xcalloc((size_t)count, sizeof *seq->outputs);
    seq->count = count;
    for (int i = 0; i < count && ok; i++) {
        opt.frame = indices[i];
        seq->jobs[i] = job_load(rib_path, &opt, cancel, diag);
        ok = seq->jobs[i] != NULL;
    }
    free(indices);
    if (ok) ok = name_outputs(seq, output, usage, diag);
    if (ok) ok = outputs_spare_inputs(seq, rib_path, usage, diag);
    if (!ok) frame_sequence_destroy(&seq);
    return seq;
}

/*
 * bundle.c: a job queue's submission, encoded by aafarm-submit and decoded
 * by the serving master (see bundle.h for the format).
 */
#include "bundle.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "job_message.h"
#include "job_proto.h"
#include "util/err.h"
#include "util/hash.h"
#include "util/xalloc.h"

static const char magic[] = "AAFARM-JOB 1\n";

static void put_record(FILE *out, char type, const void *a, size_t alen, const void *b,
                       size_t blen)
{
    uint64_t n = (uint64_t)alen + blen;
    uint8_t len[8];
    for (int i = 0; i < 8; i++) len[i] = (uint8_t)(n >> (8 * i));
    fputc(type, out);
    fwrite(len, 1, sizeof len, out);
    if (alen) fwrite(a, 1, alen, out);
    if (blen) fwrite(b, 1, blen, out);
}

/* The whole file at path, xmalloc'd; NULL with the reason. */
static uint8_t *read_file(const char *path, uint64_t size, char *err, size_t errsz)
{
    FILE *in = fopen(path, "rb");
    if (!in) {
        err_set(err, errsz, "%s: %s", path, strerror(errno));
        return NULL;
    }
    uint8_t *data = xmalloc(size ? (size_t)size : 1);
    size_t got = fread(data, 1, (size_t)size, in);
    fclose(in);
    if (got != size) {
        err_set(err, errsz, "%s: read %zu of its %llu bytes (did it change?)", path, got,
                (unsigned long long)size);
        free(data);
        return NULL;
    }
    return data;
}

/* path made absolute against the current folder (the master may run elsewhere). */
static char *absolute(const char *path)
{
    if (path[0] == '/') return xstrdup(path);
    char cwd[PATH_MAX];
    if (!getcwd(cwd, sizeof cwd)) return xstrdup(path);
    size_t n = strlen(cwd) + strlen(path) + 2;
    char *s = xmalloc(n);
    snprintf(s, n, "%s/%s", cwd, path);
    return s;
}

static bool file_sent(const frame_sequence *seq, int frame, int file)
{
    const char *sha = seq->jobs[frame]->files[file].sha256;
    for (int i = 0; i <= frame; i++)
        for (int k = 0; k < seq->jobs[i]->nfiles && (i < frame || k < file); k++)
            if (strcmp(seq->jobs[i]->files[k].sha256, sha) == 0) return true;
    return false;
}

uint8_t *job_bundle_encode(const frame_sequence *seq, const char *scene, int priority,
                           const char *pool, size_t *len, char *err, size_t errsz)
{
    char *text = NULL;
    size_t n = 0;
    FILE *out = open_memstream(&text, &n);
    if (!out) {
        err_set(err, errsz, "open_memstream: %s", strerror(errno));
        return NULL;
    }
    fputs(magic, out);
    fprintf(out, "priority %d\n", priority);
    if (pool && *pool) fprintf(out, "pool %s\n", pool);
    fprintf(out, "scene %s\n", scene);
    for (int i = 0; i < seq->count; i++) {
        char *abs = absolute(seq->outputs[i]);
        fprintf(out, "frame %d %s\n", seq->jobs[i]->frame_number, abs);
        free(abs);
    }
    fputc('\n', out);
    bool ok = true;
    for (int i = 0; i < seq->count; i++) {
        const job *jb = seq->jobs[i];
        image_format fmt = {jb->xres, jb->yres, jb->options.tile_size, 0};
        job_message *msg = job_message_new(jb, &fmt);
        size_t plen = 0;
        uint8_t *packed = proto_job_pack(job_message_job(msg), &plen);
        put_record(out, 'J', packed, plen, NULL, 0);
        free(packed);
        job_message_destroy(&msg);
    }
    for (int i = 0; ok && i < seq->count; i++) {
        const job *jb = seq->jobs[i];
        for (int k = 0; ok && k < jb->nfiles; k++) {
            if (file_sent(seq, i, k)) continue;
            uint8_t *data = read_file(jb->files[k].path, jb->files[k].size, err, errsz);
            ok = data != NULL;
            if (ok) put_record(out, 'F', jb->files[k].sha256, HASH_HEX_SIZE - 1, data,
                               (size_t)jb->files[k].size);
            free(data);
        }
    }
    if (fclose(out) != 0 && ok) ok = err_set(err, errsz, "building the submission: out of memory");
    if (!ok) {
        free(text);
        return NULL;
    }
    *len = n;
    return (uint8_t *)text;
}

/* ---- decoding ---- */

void job_bundle_clear(job_bundle *b)
{
    for (int i = 0; i < b->nframes; i++) {
        free(b->outputs[i]);
        proto_saved_job_destroy(&b->jobs[i]);
    }
    free(b->outputs);
    free(b->jobs);
    free(b->frame_numbers);
    free(b->files);
    free(b->scene);
    memset(b, 0, sizeof *b);
}

/* The next header line of data[*pos..len) into line (without its '\n'). */
static bool next_line(const uint8_t *data, size_t len, size_t *pos, char *line, size_t n)
{
    const uint8_t *nl = memchr(data + *pos, '\n', len - *pos);
    if (!nl) return false;
    size_t l = (size_t)(nl - (data + *pos));
    if (l >= n) return false;
    memcpy(line, data + *pos, l);
    line[l] = '\0';
    if (strlen(line) != l) return false;   /* no NUL inside */
    *pos += l + 1;
    return true;
}

static bool decode_header(job_bundle *b, const uint8_t *data, size_t len, size_t *pos,
                          char *err, size_t errsz)
{
    char line[PATH_MAX + 64];
    if (len < sizeof magic - 1 || memcmp(data, magic, sizeof magic - 1) != 0)
        return err_set(err, errsz, "not a job submission (it starts with 'AAFARM-JOB 1'; "
                       "submit with aafarm-submit)");
    *pos = sizeof magic - 1;
    int cap = 0;
    for (;;) {
        if (!next_line(data, len, pos, line, sizeof line))
            return err_set(err, errsz, "the submission's header is cut short or has a line "
                           "over %zu bytes", sizeof line);
        if (!line[0]) break;
        int number = 0, used = 0;
        if (sscanf(line, "priority %d%n", &b->priority, &used) == 1 && !line[used]) continue;
        if (strncmp(line, "pool ", 5) == 0) {
            if (!proto_pool_name_check(line + 5, err, errsz)) return false;
            memcpy(b->pool, line + 5, strlen(line + 5) + 1);   /* checked: it fits */
            continue;
        }
        if (strncmp(line, "scene ", 6) == 0) {
            free(b->scene);
            b->scene = xstrdup(line + 6);
            continue;
        }
        if (sscanf(line, "frame %d %n", &number, &used) == 1 && used && line[used] == '/') {
            if (b->nframes == BUNDLE_MAX_FRAMES)
                return err_set(err, errsz, "more than %d frames", BUNDLE_MAX_FRAMES);
            if (b->nframes == cap) {
                cap = cap ? 2 * cap : 8;
                b->outputs = xreallocarray(b->outputs, (size_t)cap, sizeof *b->outputs);
                b->frame_numbers = xreallocarray(b->frame_numbers, (size_t)cap,
                                                 sizeof *b->frame_numbers);
                b->jobs = xreallocarray(b->jobs, (size_t)cap, sizeof *b->jobs);
            }
            b->outputs[b->nframes] = xstrdup(line + used);
            b->frame_numbers[b->nframes] = number;
            b->jobs[b->nframes] = NULL;
            b->nframes++;
            continue;
        }
        return err_set(err, errsz, "the submission's header has a line it does not know: '%.80s' "
                       "(outputs must be absolute paths)", line);
    }
    if (!b->nframes) return err_set(err, errsz, "the submission names no frame");
    if (!b->scene) b->scene = xstrdup("?");
    return true;
}

static bool decode_file(job_bundle *b, const uint8_t *p, uint64_t n, char *err, size_t errsz)
{
    if (n < HASH_HEX_SIZE - 1) return err_set(err, errsz, "a file record without its hash");
    bundle_file f;
    memcpy(f.sha256, p, HASH_HEX_SIZE - 1);
    f.sha256[HASH_HEX_SIZE - 1] = '\0';
    if (!hash_hex_valid(f.sha256)) return err_set(err, errsz, "a file record with a bad hash");
    f.data = p + HASH_HEX_SIZE - 1;
    f.size = n - (HASH_HEX_SIZE - 1);
    uint8_t digest[SHA256_DIGEST_SIZE];
    char hex[HASH_HEX_SIZE];
    sha256_digest(f.data, (size_t)f.size, digest);
    hash_hex(digest, hex);
    if (strcmp(hex, f.sha256) != 0)
        return err_set(err, errsz, "file %.12s...: its bytes hash to %.12s...", f.sha256, hex);
    b->files = xreallocarray(b->files, (size_t)b->nfiles + 1, sizeof *b->files);
    b->files[b->nfiles++] = f;
    return true;
}

static bool decode_records(job_bundle *b, const uint8_t *data, size_t len, size_t pos,
                           char *err, size_t errsz)
{
    int njobs = 0;
    while (pos < len) {
        if (len - pos < 9) return err_set(err, errsz, "a record is cut short");
        char type = (char)data[pos];
        uint64_t n = 0;
        for (int i = 0; i < 8; i++) n |= (uint64_t)data[pos + 1 + i] << (8 * i);
        pos += 9;
        if (n > len - pos) return err_set(err, errsz, "a record is cut short");
        const uint8_t *p = data + pos;
        pos += (size_t)n;
        if (type == 'J') {
            if (njobs == b->nframes)
                return err_set(err, errsz, "more Jobs than the %d frames named", b->nframes);
            char why[ERR_LEN];
            b->jobs[njobs] = proto_job_unpack(p, (size_t)n, NULL, why, sizeof why);
            if (!b->jobs[njobs])
                return err_set(err, errsz, "the Job of frame %d: %s", b->frame_numbers[njobs], why);
            njobs++;
        } else if (type == 'F') {
            if (!decode_file(b, p, n, err, errsz)) return false;
        } else {
            return err_set(err, errsz, "a record of unknown type %d", type);
        }
    }
    if (njobs != b->nframes)
        return err_set(err, errsz, "%d frames named, %d Jobs sent", b->nframes, njobs);
    for (int i = 0; i < b->nframes; i++) {
        const proto_job *m = proto_saved_job_get(b->jobs[i]);
        for (size_t k = 0; k < m->n_files; k++) {
            bool found = false;
            for (int j = 0; j < b->nfiles && !found; j++)
                found = strcmp(b->files[j].sha256, m->files[k].sha256) == 0 &&
                        b->files[j].size == m->files[k].size;
            if (!found)
                return err_set(err, errsz, "frame %d needs file %s (%.12s...), which was not "
                               "sent", b->frame_numbers[i], m->files[k].name, m->files[k].sha256);
        }
    }
    return true;
}

bool job_bundle_decode(job_bundle *b, const uint8_t *data, size_t len, char *err, size_t errsz)
{
    memset(b, 0, sizeof *b);
    size_t pos = 0;
    if (decode_header(b, data, len, &pos, err, errsz) &&
        decode_records(b, data, len, pos, err, errsz))
        return true;
    job_bundle_clear(b);
    return false;
}

job *job_bundle_job(const job_bundle *b, int i, image_format *fmt, char *err, size_t errsz)
{
    const proto_job *m = proto_saved_job_get(b->jobs[i]);
    char why[ERR_LEN];
    job *jb = job_from_proto(m, why, sizeof why);
    if (!jb) {
        err_set(err, errsz, "frame %d: %s", b->frame_numbers[i], why);
        return NULL;
    }
    jb->frame_number = b->frame_numbers[i];
    jb->xres = (int)m->options.width;
    jb->yres = (int)m->options.height;
    *fmt = (image_format){jb->xres, jb->yres, jb->options.tile_size, 0};
    return jb;
}

/*
 * tests/image/image_testutil.c: helpers of the common/image tests (see
 * image_testutil.h).
 */
#include "image_testutil.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "test_rng.h"

/* ---- splitmix64 ---- */

static uint64_t state = 0x1234abcd5678ef01u;

void tu_seed(uint64_t seed)
{
    state = seed;
}

uint64_t tu_next(void)
{
    return test_rng_next(&state);
}

uint32_t tu_below(uint32_t n)
{
    return (uint32_t) (tu_next() % n);
}

float tu_uniform(float lo, float hi)
{
    double u = (double) (tu_next() >> 11) * 0x1p-53;
    return (float) (lo + (hi - lo) * u);
}

/* ---- tiles ---- */

static void fill(float *v, size_t n, float lo, float hi)
{
    for (size_t i = 0; i < n; i++)
        v[i] = tu_uniform(lo, hi);
}

void tu_fill_random(image_tile *t)
{
    size_t px = (size_t) t->w * (size_t) t->h;
    fill(t->rgba, 4 * px, -0.5f, 4.0f);
    for (size_t i = 0; i < 4 * px; i += 7)
        t->rgba[i] = 0.5f;
    fill(t->z, px, 0.001f, 1000.0f);
    for (size_t i = 3; i < px; i += 11)
        t->z[i] = INFINITY;
    if (t->n)
        fill(t->n, 3 * px, -100.0f, 100.0f);
    if (t->p)
        fill(t->p, 3 * px, -100.0f, 100.0f);
}

void tu_fill_smooth(image_tile *t)
{
    for (int y = 0; y < t->h; y++) {
        for (int x = 0; x < t->w; x++) {
            size_t i = (size_t) y * (size_t) t->w + (size_t) x;
            float gx = (float) (t->x0 + x) / 64.0f, gy = (float) (t->y0 + y) / 64.0f;
            for (int c = 0; c < 3; c++)
                t->rgba[4 * i + c] = gx * (float) (c + 1) * 0.25f + gy * 0.5f;
            t->rgba[4 * i + 3] = 1.0f;
            t->z[i] = 10.0f + gy;
            for (int c = 0; c < 3; c++) {
                if (t->n)
                    t->n[3 * i + c] = c == 2 ? 1.0f : 0.0f;
                if (t->p)
                    t->p[3 * i + c] = c == 0 ? gx : c == 1 ? gy : 5.0f;
            }
        }
    }
}

image_tile *tu_tile(const image_format *fmt, int tx, int ty, uint64_t seed,
                    bool smooth)
{
    image_rect r = image_format_tile_rect(fmt, tx, ty);
    image_tile *t = image_tile_new(r.x0, r.y0, r.w, r.h, fmt->layers);
    if (!t)
        return NULL;
    uint64_t saved = state;
    tu_seed(seed * 1000003u + (uint64_t) tx * 7919u + (uint64_t) ty);
    if (smooth)
        tu_fill_smooth(t);
    else
        tu_fill_random(t);
    state = saved;
    return t;
}

/* ---- reference binary16 rounding ---- */

float tu_half_round(float f)
{
    if (isnan(f) || isinf(f) || f == 0.0f)
        return f;
    double a = fabs((double) f);
    if (a >= 65520.0)
        return copysignf(INFINITY, f);
    double spacing;
    if (a < 0x1p-14) {
        spacing = 0x1p-24;                 /* subnormal halves */
    } else {
        int e;
        frexp(a, &e);                      /* a in [2^(e-1), 2^e) */
        spacing = ldexp(1.0, e - 1 - 10);  /* 10 fraction bits */
    }
    double r = nearbyint(a / spacing) * spacing;   /* ties to even */
    return (float) copysign(r, (double) f);
}

/* ---- files ---- */

char *tu_make_dir(void)
{
    const char *base = getenv("TMPDIR");
    char tmpl[512];
    snprintf(tmpl, sizeof tmpl, "%s/aafarm-image-XXXXXX",
             base && *base ? base : "/tmp");
    char *dir = mkdtemp(tmpl);
    return dir ? strdup(dir) : NULL;
}

void tu_remove_dir(char **dir_p)
{
    if (!*dir_p)
        return;
    DIR *d = opendir(*dir_p);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
                unlink(tu_path(*dir_p, e->d_name));
        }
        closedir(d);
    }
    rmdir(*dir_p);
    free(*dir_p);
    *dir_p = NULL;
}

const char *tu_path(const char *dir, const char *name)
{
    static char bufs[4][1024];
    static int next;
    char *b = bufs[next++ % 4];
    snprintf(b, sizeof bufs[0], "%s/%s", dir, name);
    return b;
}

int tu_dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    return n;
}

bool tu_file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

uint8_t *tu_read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    uint8_t *buf = NULL;
    size_t cap = 0, n = 0, got;
    do {
        if (n == cap) {
            cap = cap ? 2 * cap : 65536;
            uint8_t *p = realloc(buf, cap);
            if (!p) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = p;
        }
        got = fread(buf + n, 1, cap - n, f);
        n += got;
    } while (got > 0);
    fclose(f);
    *len = n;
    return buf;
}

bool tu_write_file(const char *path, const void *bytes, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return false;
    bool ok = fwrite(bytes, 1, len, f) == len;
    return fclose(f) == 0 && ok;
}

/*
 * tex_bench: textures (common/tex, docs/textures.md "Memory"). For square
 * float maps of N x N texels (default 512 1024 2048 4096; give sizes as
 * arguments, e.g. `tex_bench 16384`), written as aafarm-maketx files (with
 * the min-max parts), each opened in a fresh process with a tile pool of
 * --budget bytes (default 64M; 0: no limit):
 *   - the file's size, the time to the first lookup (open: the header and
 *     the small levels read, then one texture() sample), the bytes kept in
 *     memory for good and the peak resident memory of the process so far;
 *   - two lookup phases, each printed with lookups per second, the tiles
 *     loaded and evicted, and the process's peak resident memory after it:
 *     "whole": a 1024 x 1024 grid over the whole map at the grid's
 *     footprint (a distant view: the level of 1024 texels across), float
 *     lookups then the bound of each grid cell; "zoom": a 2048 x 2048 grid
 *     over a quarter of the map's width at level 0 (a close-up: 4096 x 4096
 *     texels, 64 MiB of level-0 tiles), float lookups then bounds.
 * Each map is written by one child process and measured in another, so that
 * a peak is its own. Prints a table; never fails on time.
 *
 *   tex_bench [--budget B] [SIZE...]
 *   tex_bench --write N OUT.exr      (just the map; bench/tex_farm.sh)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "tex/tex.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static long status_kib(const char *key)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long v = -1;
    size_t n = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, key, n) == 0)
            v = strtol(line + n + 1, NULL, 10);
    if (f)
        fclose(f);
    return v;
}

/* a smooth map with detail: sums of sines (cheap to make at any size) */
static bool write_map(const char *path, int n)
{
    float *px = malloc((size_t)n * n * sizeof *px);
    if (!px)
        return false;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x = (i + 0.5) / n, y = (j + 0.5) / n;
            px[(size_t)j * n + i] = (float)(sin(2 * M_PI * 3 * x) * cos(2 * M_PI * 2 * y) +
                                            0.1 * sin(2 * M_PI * 61 * (x + y)));
        }
    tex_texture *t = tex_from_pixels(px, n, n, 1, "bench");
    free(px);
    char err[512];
    bool ok = t && tex_write_exr(path, t, true, err, sizeof err);
    if (t && !ok)
        fprintf(stderr, "tex_bench: %s\n", err);
    tex_destroy(&t);
    return ok;
}

static void phase(tex_texture *t, tex_tiles *pool, const char *name, int grid, double s0,
                  double side, double footprint)
{
    tex_tile_stats before;
    tex_tiles_stats(pool, &before);
    double t0 = now();
    volatile double sink = 0;
    for (int j = 0; j < grid; j++)
        for (int i = 0; i < grid; i++)
            sink += tex_sample(t, 0, s0 + side * (i + 0.5) / grid, s0 + side * (j + 0.5) / grid,
                               footprint, footprint, TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0,
                               NULL, NULL);
    double samples = (double)grid * grid / (now() - t0);
    double t1 = now();
    for (int j = 0; j < grid; j++)
        for (int i = 0; i < grid; i++) {
            double a = s0 + side * i / grid, b = s0 + side * j / grid, w = side / grid;
            tex_range r = { { a, a + w }, { b, b + w }, { footprint, footprint },
                            { footprint, footprint } };
            double lo, hi;
            tex_bound(t, 0, &r, TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0, &lo, &hi);
            sink += hi - lo;
        }
    double bounds = (double)grid * grid / (now() - t1);
    (void)sink;
    tex_tile_stats st;
    tex_tiles_stats(pool, &st);
    printf("        %-5s %5d^2 lookups: %10.0f samples/s %10.0f bounds/s, tiles %8llu loaded "
           "%8llu evicted (%.0f MiB at most), peak RSS %.0f MiB\n", name, grid, samples, bounds,
           st.loads - before.loads, st.evictions - before.evictions, st.peak_bytes / 1048576.0,
           status_kib("VmHWM:") / 1024.0);
}

static void measure(const char *path, double file_mib, size_t budget)
{
    char err[512];
    tex_tiles *pool = tex_tiles_new(budget);
    double t0 = now();
    tex_texture *t = tex_open_in(path, pool, err, sizeof err);
    if (!t) {
        fprintf(stderr, "tex_bench: %s\n", err);
        exit(1);
    }
    volatile double sink = tex_sample(t, 0, 0.3, 0.7, 0, 0, TEX_WRAP_PERIODIC,
                                      TEX_WRAP_PERIODIC, 0, NULL, NULL);
    (void)sink;
    double first = now() - t0;
    long peak = status_kib("VmHWM:");
    printf("%6d  %6d  %6d  %9.1f  %9.3f  %11.1f  %9.1f\n", tex_width(t), tex_levels(t),
           tex_tiled_levels(t), file_mib, first, tex_bytes(t) / 1048576.0, peak / 1024.0);
    int n = tex_width(t);
    phase(t, pool, "whole", 1024, 0.0, 1.0, 1.0 / 1024);
    if (n >= 4096)
        phase(t, pool, "zoom", 2048, 0.3, 0.25, 0.0);
    else
        phase(t, pool, "zoom", n / 4 > 16 ? n / 4 : 16, 0.3, 0.25, 0.0);
    fflush(stdout);
    tex_destroy(&t);
    tex_tiles_destroy(&pool);
}

static bool parse_bytes(const char *s, size_t *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || v < 0)
        return false;
    double mul = *end == 'K' ? 1024.0 : *end == 'M' ? 1048576.0 : *end == 'G' ? 1073741824.0 : 1;
    if (mul != 1)
        end++;
    if (*end)
        return false;
    *out = (size_t)(v * mul);
    return true;
}

int main(int argc, char **argv)
{
    int sizes[16] = { 512, 1024, 2048, 4096 }, nsizes = 0;
    size_t budget = (size_t)64 << 20;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--write") == 0 && i + 2 < argc) {
            int n = atoi(argv[i + 1]);
            if (n < 1 || n > 65536) {
                fprintf(stderr, "tex_bench: --write takes a size of 1 to 65536\n");
                return 2;
            }
            return write_map(argv[i + 2], n) ? 0 : 1;
        }
        if (strcmp(argv[i], "--budget") == 0 && i + 1 < argc) {
            if (!parse_bytes(argv[++i], &budget)) {
                fprintf(stderr, "tex_bench: --budget wants e.g. 64M or 0\n");
                return 2;
            }
            continue;
        }
        int v = atoi(argv[i]);
        if (v < 1 || v > 65536 || nsizes == 16) {
            fprintf(stderr, "usage: tex_bench [--budget B] [SIZE...]  (sizes 1 to 65536)\n"
                            "       tex_bench --write N OUT.exr\n");
            return 2;
        }
        sizes[nsizes++] = v;
    }
    if (nsizes == 0)
        nsizes = 4;
    char dir[] = "/tmp/tex_bench.XXXXXX";
    if (!mkdtemp(dir)) {
        perror("tex_bench: mkdtemp");
        return 1;
    }
    printf("tex_bench: one-channel float maps, aafarm-maketx files (mean, min, max), tiles "
           "on demand, budget %.0f MiB%s\n", budget / 1048576.0, budget ? "" : " (none)");
    printf("%6s  %6s  %6s  %9s  %9s  %11s  %9s\n", "N", "levels", "tiled", "file_MiB",
           "first_s", "memory_MiB", "peak_MiB");
    for (int k = 0; k < nsizes; k++) {
        char path[256];
        snprintf(path, sizeof path, "%s/map%d.exr", dir, sizes[k]);
        fflush(stdout);
        pid_t pid = fork();                 /* the map, made in its own process */
        if (pid == 0)
            _exit(write_map(path, sizes[k]) ? 0 : 1);
        int status = 0;
        waitpid(pid, &status, 0);
        struct stat st;
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || stat(path, &st) != 0) {
            fprintf(stderr, "tex_bench: cannot write a %d x %d map\n", sizes[k], sizes[k]);
            unlink(path);
            continue;
        }
        pid = fork();                       /* measured in a fresh one */
        if (pid == 0) {
            measure(path, st.st_size / 1048576.0, budget);
            fflush(stdout);
            _exit(0);
        }
        waitpid(pid, &status, 0);
        unlink(path);
    }
    rmdir(dir);
    return 0;
}

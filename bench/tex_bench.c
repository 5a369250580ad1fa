/*
 * tex_bench: textures (common/tex, docs/textures.md). For square float maps
 * of N x N texels (default 512 1024 2048 4096; give sizes as arguments,
 * e.g. `tex_bench 16384`), written as aafarm-maketx files (part "mean"
 * only, to keep the disk small): the file's size, the time to the first
 * lookup (read + pyramids + one texture() sample), the bytes of the
 * pyramids and the peak resident memory of a process that did only that,
 * then float lookups and range bounds per second. Each map is written by
 * one child process and measured in another, so that a peak is its own.
 * Prints a table; never fails on time.
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
    bool ok = t && tex_write_exr(path, t, false, err, sizeof err);
    if (t && !ok)
        fprintf(stderr, "tex_bench: %s\n", err);
    tex_free(t);
    return ok;
}

static void measure(const char *path, double file_mib)
{
    char err[512];
    double t0 = now();
    tex_texture *t = tex_open(path, err, sizeof err);
    if (!t) {
        fprintf(stderr, "tex_bench: %s\n", err);
        exit(1);
    }
    volatile double sink = tex_sample(t, 0, 0.3, 0.7, 0, 0, TEX_WRAP_PERIODIC,
                                      TEX_WRAP_PERIODIC, 0, NULL, NULL);
    double first = now() - t0;
    long peak = status_kib("VmHWM:");
    int reps = 2000000;
    double t1 = now();
    for (int k = 0; k < reps; k++)
        sink += tex_sample(t, 0, k * 0.6180339887, k * 0.3819660113, 1e-4, 1e-4,
                           TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0, NULL, NULL);
    double samples = reps / (now() - t1);
    int breps = 500000;
    double t2 = now(), width = 0;
    for (int k = 0; k < breps; k++) {
        double s = fmod(k * 0.6180339887, 1.0), tt = fmod(k * 0.3819660113, 1.0);
        double side = pow(2.0, -(k % 12));
        tex_range r = { { s, s + side }, { tt, tt + side }, { 1e-4, 1e-4 }, { 1e-4, 1e-4 } };
        double lo, hi;
        tex_bound(t, 0, &r, TEX_WRAP_PERIODIC, TEX_WRAP_PERIODIC, 0, &lo, &hi);
        width += hi - lo;
    }
    double bounds = breps / (now() - t2);
    (void)sink;
    printf("%6d  %6d  %9.1f  %10.3f  %9.1f  %9.1f  %12.0f  %12.0f\n", tex_width(t),
           tex_levels(t), file_mib, first, tex_bytes(t) / 1048576.0, peak / 1024.0, samples,
           bounds);
    tex_free(t);
}

int main(int argc, char **argv)
{
    int sizes[16] = { 512, 1024, 2048, 4096 }, nsizes = 4;
    if (argc > 1) {
        nsizes = 0;
        for (int i = 1; i < argc && nsizes < 16; i++) {
            int v = atoi(argv[i]);
            if (v < 1 || v > 65536) {
                fprintf(stderr, "usage: tex_bench [SIZE...]  (sizes 1 to 65536)\n");
                return 2;
            }
            sizes[nsizes++] = v;
        }
    }
    char dir[] = "/tmp/tex_bench.XXXXXX";
    if (!mkdtemp(dir)) {
        perror("tex_bench: mkdtemp");
        return 1;
    }
    printf("tex_bench: one-channel float maps, aafarm-maketx files (part \"mean\")\n");
    printf("%6s  %6s  %9s  %10s  %9s  %9s  %12s  %12s\n", "N", "levels", "file_MiB",
           "first_s", "tex_MiB", "peak_MiB", "samples/s", "bounds/s");
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
            measure(path, st.st_size / 1048576.0);
            fflush(stdout);
            _exit(0);
        }
        waitpid(pid, &status, 0);
        unlink(path);
    }
    rmdir(dir);
    return 0;
}

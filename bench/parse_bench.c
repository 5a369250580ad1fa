/*
 * bench/parse_bench.c: what reading a scene costs (issue 23): the parse
 * alone (scene_load: the RIB and the archives it reads, as a worker or
 * the standalone renderer parses them) or the master's whole check
 * (job_load: parse, compile, the check's world), in wall and CPU seconds,
 * with the process's peak RSS and the objects read. Never fails on timing.
 *
 *   parse_bench [--master] SCENE.rib
 *
 * Run it once per mode (the peak RSS is the process's).
 */
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "job/job.h"
#include "scene/scene.h"
#include "sl/diag.h"

static double now(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
    bool master = argc == 3 && strcmp(argv[1], "--master") == 0;
    if (argc != 2 + master) {
        fprintf(stderr, "usage: parse_bench [--master] SCENE.rib\n");
        return 2;
    }
    const char *path = argv[1 + master];
    sl_diag *diag = sl_diag_new();
    double w0 = now(CLOCK_MONOTONIC), c0 = now(CLOCK_PROCESS_CPUTIME_ID);
    long nobjects = -1;
    bool ok;
    if (master) {
        job_options opt;
        job_options_default(&opt);
        job *j = job_load(path, &opt, NULL, diag);
        ok = j != NULL;
        job_destroy(&j);
    } else {
        scene *s = scene_load(path, diag);
        ok = s != NULL;
        if (s) nobjects = s->nobjects;
        scene_destroy(&s);
    }
    double w1 = now(CLOCK_MONOTONIC), c1 = now(CLOCK_PROCESS_CPUTIME_ID);
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("%s %s: %s, %.2f s wall, %.2f s CPU, peak %ld MB", master ? "job_load" : "scene_load",
           path, ok ? "ok" : "errors", w1 - w0, c1 - c0, ru.ru_maxrss / 1024);
    if (nobjects >= 0) printf(", %ld objects", nobjects);
    printf("\n");
    return ok ? 0 : 1;
}

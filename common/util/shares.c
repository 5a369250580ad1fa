/*
 * shares.c: util_run_shares (shares.h): one POSIX thread a share but the
 * first, which the caller's thread runs.
 */
#include "util/shares.h"
#include "util/xalloc.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>

void util_run_shares(void *shares, size_t size, int n, void *(*fn)(void *))
{
    char *base = shares;
    pthread_t *tid = xcalloc((size_t)(n > 0 ? n : 1), sizeof *tid);
    bool *started = xcalloc((size_t)(n > 0 ? n : 1), sizeof *started);
    for (int i = 1; i < n; i++)
        started[i] = pthread_create(&tid[i], NULL, fn, base + (size_t)i * size) == 0;
    if (n > 0) fn(base);
    for (int i = 1; i < n; i++)
        if (started[i]) pthread_join(tid[i], NULL);
        else fn(base + (size_t)i * size);     /* no thread: the caller does it */
    free(started);
    free(tid);
}

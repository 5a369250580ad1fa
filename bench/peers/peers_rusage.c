/*
 * peers_rusage.c: CPU seconds and peak memory of one program run, for the
 * peer benchmark's alternating runs (bench/peers/run.sh):
 *
 *   peers_rusage LIMIT_S LOG CMD [ARG ...]
 *
 * runs CMD with stdout and stderr to LOG, kills it (SIGKILL, reaped by its
 * PID) when it runs past LIMIT_S seconds of wall time, and prints
 * "cpu_s C maxrss_kib M status S" from wait4()'s rusage of that child
 * alone: user + system CPU of all its threads, and its peak resident set.
 * Exit status: CMD's (124 when it was killed for time).
 */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: peers_rusage LIMIT_S LOG CMD [ARG ...]\n");
        return 2;
    }
    char *end = NULL;
    double limit = strtod(argv[1], &end);
    if (*end || !(limit > 0)) {
        fprintf(stderr, "peers_rusage: LIMIT_S wants seconds > 0, got '%s'\n", argv[1]);
        return 2;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        perror("peers_rusage: fork");
        return 1;
    }
    if (pid == 0) {
        int fd = open(argv[2], O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
            close(fd);
        }
        execvp(argv[3], &argv[3]);
        fprintf(stderr, "peers_rusage: cannot run %s: %s\n", argv[3], strerror(errno));
        _exit(127);
    }
    struct timespec t0, now;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int status = 0;
    struct rusage ru;
    int killed = 0;
    for (;;) {
        pid_t r = wait4(pid, &status, WNOHANG, &ru);
        if (r == pid) break;
        if (r < 0 && errno != EINTR) {
            perror("peers_rusage: wait4");
            return 1;
        }
        clock_gettime(CLOCK_MONOTONIC, &now);
        double el = (double)(now.tv_sec - t0.tv_sec) + (double)(now.tv_nsec - t0.tv_nsec) * 1e-9;
        if (!killed && el > limit) {
            kill(pid, SIGKILL);
            killed = 1;
        }
        struct timespec nap = {0, 2000000};    /* 2 ms: negligible CPU */
        nanosleep(&nap, NULL);
    }
    double cpu = (double)ru.ru_utime.tv_sec + (double)ru.ru_utime.tv_usec * 1e-6 +
                 (double)ru.ru_stime.tv_sec + (double)ru.ru_stime.tv_usec * 1e-6;
    int code = killed ? 124 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    printf("cpu_s %.4f maxrss_kib %ld status %d\n", cpu, ru.ru_maxrss, code);
    return code;
}

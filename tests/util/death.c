/*
 * death.c: fork-and-wait death tests, and runs in a child starved of
 * memory (see death.h).
 */
#include "death.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

bool death_run(void (*fn)(void *), void *arg, const char *expect, char *why, int whylen)
{
    int fd[2];
    if (pipe(fd) != 0) {
        snprintf(why, (size_t)whylen, "pipe: %s", strerror(errno));
        return false;
    }
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(why, (size_t)whylen, "fork: %s", strerror(errno));
        return false;
    }
    if (pid == 0) {
        close(fd[0]);
        dup2(fd[1], 2);
        signal(SIGABRT, SIG_DFL);
        fn(arg);
        _exit(0);   /* lived: no assert fired */
    }
    close(fd[1]);
    char out[4096];
    size_t n = 0;
    for (;;) {
        ssize_t r = read(fd[0], out + n, sizeof out - 1 - n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        n += (size_t)r;
        if (n == sizeof out - 1)
            break;
    }
    out[n] = '\0';
    close(fd[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (!WIFSIGNALED(status) || WTERMSIG(status) != SIGABRT) {
        if (WIFEXITED(status))
            snprintf(why, (size_t)whylen, "expected an abort, the child exited with %d; it printed: %s",
                     WEXITSTATUS(status), out);
        else
            snprintf(why, (size_t)whylen, "expected SIGABRT, the child died of signal %d; it printed: %s",
                     WTERMSIG(status), out);
        return false;
    }
    if (expect && !strstr(out, expect)) {
        snprintf(why, (size_t)whylen, "the child aborted, but its message lacks '%s': %s", expect, out);
        return false;
    }
    return true;
}

bool starved_run(int (*fn)(void *), void *arg, unsigned long headroom, char *why, int whylen)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(why, (size_t)whylen, "fork: %s", strerror(errno));
        return false;
    }
    if (pid == 0) {
        long pages = 0;
        FILE *f = fopen("/proc/self/statm", "r");
        if (!f || fscanf(f, "%ld", &pages) != 1)
            _exit(3);
        fclose(f);
        struct rlimit rl;
        getrlimit(RLIMIT_AS, &rl);
        rl.rlim_cur = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + (rlim_t)headroom;
        if (setrlimit(RLIMIT_AS, &rl) != 0)
            _exit(3);
        _exit(fn(arg));
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
        return true;
    snprintf(why, (size_t)whylen, "the child %s %d (0: refused with the message; 3: no limit set)",
             WIFEXITED(status) ? "exited with" : "died of signal",
             WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
    return false;
}

/*
 * stale.c: leftovers of dead masters (see stale.h).
 */
#include "stale.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Does process pid exist? (EPERM: yes, someone else's.) */
static bool alive(long pid)
{
    return pid > 0 && pid <= INT_MAX && (kill((pid_t)pid, 0) == 0 || errno == EPERM);
}

/* The pid of "<prefix><digits>", or -1. */
static long pid_suffix(const char *name, const char *prefix)
{
    size_t n = strlen(prefix);
    if (strncmp(name, prefix, n) != 0 || !name[n]) return -1;
    char *end;
    errno = 0;
    long pid = strtol(name + n, &end, 10);
    return *end || errno || pid <= 0 || name[n] < '0' || name[n] > '9' ? -1 : pid;
}

int stale_clean_outputs(const char *output, stale_report_fn report, void *arg)
{
    char dir[PATH_MAX], prefix[NAME_MAX + 8];
    const char *slash = strrchr(output, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", (int)(slash - output + (slash == output)), output);
    else snprintf(dir, sizeof dir, ".");
    const char *base = slash ? slash + 1 : output;
    if (!*base || strlen(base) > NAME_MAX) return 0;
    snprintf(prefix, sizeof prefix, "%s.tmp-", base);
    DIR *d = opendir(dir);
    if (!d) return 0;
    int removed = 0;
    long self = (long)getpid();
    struct dirent *e;
    while ((e = readdir(d))) {
        long pid = pid_suffix(e->d_name, prefix);
        if (pid < 0 || pid == self) continue;
        char path[PATH_MAX + NAME_MAX + 2];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        bool gone = !alive(pid) && unlink(path) == 0;
        if (gone) removed++;
        report(arg, path, pid, gone);
    }
    closedir(d);
    return removed;
}

/* The pid in folder/master.pid, or -1 when the folder is not one of ours
 * (no pid file, or files other than the pid file and the socket). */
static long ipc_dir_pid(const char *folder)
{
    DIR *d = opendir(folder);
    if (!d) return -1;
    bool has_pid = false, foreign = false;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") ||
            !strcmp(e->d_name, "master.sock"))
            continue;
        if (!strcmp(e->d_name, STALE_PID_FILE)) has_pid = true;
        else foreign = true;
    }
    closedir(d);
    if (!has_pid || foreign) return -1;
    char path[PATH_MAX + 16], text[32] = "";
    snprintf(path, sizeof path, "%s/%s", folder, STALE_PID_FILE);
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    char *end;
    long pid = strtol(text, &end, 10);
    return end != text && (*end == '\n' || !*end) && pid > 0 ? pid : -1;
}

int stale_clean_ipc_dirs(const char *tmpdir, stale_report_fn report, void *arg)
{
    DIR *d = opendir(tmpdir);
    if (!d) return 0;
    int removed = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strncmp(e->d_name, "aafarm-", 7) != 0 || strlen(e->d_name) != 13) continue;
        char folder[PATH_MAX];
        snprintf(folder, sizeof folder, "%s/%s", tmpdir, e->d_name);
        struct stat st;
        if (lstat(folder, &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != geteuid()) continue;
        long pid = ipc_dir_pid(folder);
        if (pid < 0 || pid == (long)getpid() || alive(pid)) continue;   /* a running master's */
        char path[PATH_MAX + 16];
        snprintf(path, sizeof path, "%s/master.sock", folder);
        unlink(path);
        snprintf(path, sizeof path, "%s/%s", folder, STALE_PID_FILE);
        unlink(path);
        bool gone = rmdir(folder) == 0;
        if (gone) removed++;
        report(arg, folder, pid, gone);
    }
    closedir(d);
    return removed;
}

/*
 * cli.c: the version line and getopt's option problems (see cli.h).
 * AAFARM_VERSION, AAFARM_GIT_COMMIT and AAFARM_BUILD_TYPE come from CMake
 * (common/util/CMakeLists.txt), set when the build is configured.
 */
#include "util/cli.h"

#include <stdio.h>
#include <string.h>

#ifndef AAFARM_VERSION
#define AAFARM_VERSION "unknown"
#endif
#ifndef AAFARM_GIT_COMMIT
#define AAFARM_GIT_COMMIT "unknown"
#endif
#ifndef AAFARM_BUILD_TYPE
#define AAFARM_BUILD_TYPE "unknown"
#endif

const char *cli_version(void)
{
    return AAFARM_VERSION " (commit " AAFARM_GIT_COMMIT ", " AAFARM_BUILD_TYPE ")";
}

void cli_option_problem(int ch, int optind_now, int optopt_now, char *const *argv, char *buf,
                        size_t size)
{
    /* a long option is named by its text (up to '='), a short one by
     * optopt (it may sit in a cluster like -qZ) */
    const char *arg = optind_now > 0 ? argv[optind_now - 1] : "";
    char opt[256];
    if (strncmp(arg, "--", 2) == 0) {
        size_t n = strcspn(arg, "=");
        snprintf(opt, sizeof opt, "%.*s", (int)(n < 200 ? n : 200), arg);
    } else {
        snprintf(opt, sizeof opt, "-%c", optopt_now > 32 && optopt_now < 127 ? optopt_now : '?');
    }
    if (ch == ':')
        snprintf(buf, size, "option '%s' needs a value (see --help)", opt);
    else
        snprintf(buf, size, "unknown option '%s' (see --help)", opt);
}

/*
 * cli.h: what every aafarm program says the same way on its command line
 * (docs/conventions in CONTRIBUTING.md, "Programs"): `--version` (the
 * version, the git commit and the build type it was built from), and one
 * line plus "(see --help)" for an option getopt_long did not take.
 * The strings are returned; the program prints them.
 */
#ifndef UTIL_CLI_H
#define UTIL_CLI_H

#include <stddef.h>

/* "0.1.0 (commit 1a2b3c4d5e6f, RelWithDebInfo)": the project version, the
 * git commit the build was configured at ("unknown" outside a checkout)
 * and the CMake build type. */
const char *cli_version(void);

/* The one line for what getopt_long returned as ch ('?': an unknown
 * option; ':': a missing value, when the option string starts with ':'),
 * with optind/optopt as it left them: "unknown option '--x' (see --help)"
 * or "option '--tile' needs a value (see --help)". */
void cli_option_problem(int ch, int optind_now, int optopt_now, char *const *argv, char *buf,
                        size_t size);

#endif

/*
 * aafarm-slc: checks and compiles shading-language sources and prints
 * their diagnostics, the way the master does before a job and a worker
 * does when a job arrives (the same sl_compile), optionally with the
 * bytecode listing.
 *
 *   aafarm-slc [--dump] [-I DIR]... FILE.sl...
 *
 * Exit status 0 when every file compiled, 1 when one had errors, 2 on a
 * usage error, 130 when SIGINT/SIGTERM stopped it (the compiler looks at
 * the flag as it goes: sl_compile's cancel).
 */
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl/diag.h"
#include "sl/shader.h"
#include "sl/source.h"
#include "util/cli.h"
#include "util/exitcodes.h"
#include "util/xalloc.h"

static void usage(FILE *out)
{
    fputs("usage: aafarm-slc [--dump] [-I DIR]... FILE.sl...\n"
          "  Checks and compiles shaders (RenderMan Shading Language subset),\n"
          "  printing errors and warnings as file:line:col.\n"
          "  --dump    print the bytecode of each compiled shader\n"
          "  -I DIR    add DIR to the #include search path\n"
          "  Exit status: 0 compiled, 1 errors, 2 usage, 130 SIGINT/SIGTERM.\n",
          out);
}

/* Set by SIGINT/SIGTERM; the compiler looks at it (sl_compile's cancel). */
static atomic_int interrupted;

static void on_signal(int sig)
{
    (void)sig;
    atomic_store(&interrupted, 1);
}

static int compile_one(const char *path, const char *const *search, bool dump)
{
    sl_source_set *set = sl_source_set_new();
    sl_source_set_set_loader(set, sl_source_load_from_disk, NULL);
    sl_diag *diag = sl_diag_new();
    sl_program *prog = sl_compile(set, path, search, &interrupted, diag);
    if (atomic_load(&interrupted)) {
        fprintf(stderr, "aafarm-slc: interrupted while compiling %s\n", path);
        sl_program_destroy(&prog);
        sl_diag_destroy(&diag);
        sl_source_set_destroy(&set);
        return AAFARM_EXIT_INTERRUPTED;
    }
    sl_diag_print(diag, stderr);
    int status = 0;
    if (prog) {
        printf("%s: %s shader '%s' compiled (%d parameter%s)\n", path,
               sl_program_kind(prog) == SL_SHADER_SURFACE ? "surface"
               : sl_program_kind(prog) == SL_SHADER_LIGHT ? "light" : "displacement",
               sl_program_name(prog), sl_program_param_count(prog),
               sl_program_param_count(prog) == 1 ? "" : "s");
        if (dump)
            sl_program_dump(prog, stdout);
        sl_program_destroy(&prog);
    } else {
        int n = sl_diag_error_count(diag);
        fprintf(stderr, "%s: %d error%s\n", path, n, n == 1 ? "" : "s");
        status = 1;
    }
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return status;
}

int main(int argc, char **argv)
{
    bool dump = false;
    const char **search = xcalloc((size_t)argc + 1, sizeof *search);
    const char **files = xcalloc((size_t)argc + 1, sizeof *files);
    int nsearch = 0, nfiles = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--dump") == 0) {
            dump = true;
        } else if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            free(search);
            free(files);
            return 0;
        } else if (strcmp(argv[i], "--version") == 0) {
            printf("aafarm-slc %s\n", cli_version());
            free(search);
            free(files);
            return 0;
        } else if (strcmp(argv[i], "-I") == 0 && i + 1 < argc) {
            search[nsearch++] = argv[++i];
        } else if (strncmp(argv[i], "-I", 2) == 0 && argv[i][2]) {
            search[nsearch++] = argv[i] + 2;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "aafarm-slc: unknown option '%s' (see --help)\n", argv[i]);
            free(search);
            free(files);
            return 2;
        } else {
            files[nfiles++] = argv[i];
        }
    }
    if (nfiles == 0) {
        usage(stderr);
        free(search);
        free(files);
        return 2;
    }
    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    int status = 0;
    for (int i = 0; i < nfiles && status != AAFARM_EXIT_INTERRUPTED; i++) {
        int one = compile_one(files[i], search, dump);
        status = one == AAFARM_EXIT_INTERRUPTED ? one : status | one;
    }
    free(search);
    free(files);
    return status;
}

/*
 * keygen_main.c: aafarm-keygen, a CurveZMQ key pair for the farm
 * (curve_cert.h; docs/cluster.md, "Keys").
 *
 *   aafarm-keygen NAME     writes NAME.key (public) and NAME.key_secret
 *                          (secret, mode 0600); never overwrites
 */
#include <stdio.h>
#include <string.h>
#include <zmq.h>

#include "curve_cert.h"
#include "util/cli.h"
#include "util/err.h"
#include "util/exitcodes.h"

static void usage(FILE *out)
{
    fprintf(out,
        "usage: aafarm-keygen NAME\n"
        "\n"
        "Writes a CurveZMQ key pair in ZeroMQ's certificate format:\n"
        "  NAME.key         the public key: give it to the other side (a worker's to the\n"
        "                   master's --allow-keys folder, the master's to --master-key)\n"
        "  NAME.key_secret  the secret key (mode 0600): stays on this host\n"
        "                   (--curve-secret of the master or the worker)\n"
        "Refuses to overwrite either file. The certificate's name is NAME's last part.\n"
        "\n"
        "Exit status: 0 written, 1 not written (the reason is printed), 2 usage.\n");
}

int main(int argc, char **argv)
{
    if (argc == 2 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0)) {
        usage(stdout);
        return AAFARM_EXIT_OK;
    }
    if (argc == 2 && strcmp(argv[1], "--version") == 0) {
        printf("aafarm-keygen %s\n", cli_version());
        return AAFARM_EXIT_OK;
    }
    if (argc >= 2 && argv[1][0] == '-' && argv[1][1]) {
        fprintf(stderr, "aafarm-keygen: unknown option '%s' (see --help)\n", argv[1]);
        return AAFARM_EXIT_USAGE;
    }
    if (argc != 2 || !argv[1][0] || argv[1][0] == '-') {
        usage(stderr);
        return AAFARM_EXIT_USAGE;
    }
    if (!zmq_has("curve")) {
        fprintf(stderr, "aafarm-keygen: this libzmq has no CURVE support (it needs libsodium; "
                "Debian 12's libzmq5 has it)\n");
        return AAFARM_EXIT_FAILURE;
    }
    const char *base = argv[1];
    const char *name = strrchr(base, '/');
    name = name ? name + 1 : base;
    char err[2 * ERR_LEN];   /* "already exists" names the key's path three times */
    if (!curve_cert_generate(base, name, err, sizeof err)) {
        fprintf(stderr, "aafarm-keygen: %s\n", err);
        return AAFARM_EXIT_FAILURE;
    }
    printf("wrote %s.key (public) and %s.key_secret (secret, mode 0600)\n", base, base);
    return AAFARM_EXIT_OK;
}

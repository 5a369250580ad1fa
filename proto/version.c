/*
 * version.c: the protocol version check (the rule: version.h and
 * docs/protocol.md, "Versions").
 */
#include "version.h"
#include "util/err.h"

#include <stdio.h>

int proto_version_check(uint32_t master, uint32_t worker, char *err, size_t errsz)
{
    if (master == worker && master != 0)
        return 0;
    if (err && errsz > 0) {
        if (master == 0 || worker == 0)
            err_set(err, errsz, "the %s sent no protocol version (master %u, worker %u): "
                    "it is not an aafarm %s, or a broken one",
                    master == 0 ? "master" : "worker", (unsigned)master, (unsigned)worker,
                    master == 0 ? "master" : "worker");
        else
            err_set(err, errsz, "master speaks protocol %u, worker %u: upgrade the older side",
                    (unsigned)master, (unsigned)worker);
    }
    return -1;
}

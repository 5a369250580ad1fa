/*
 * curve_cert.h: CurveZMQ key pairs on disk (docs/cluster.md, "Keys").
 *
 * A key pair NAME is two files in ZeroMQ's certificate format (the text
 * format of CZMQ's zcert, Z85-encoded 32-byte Curve25519 keys):
 *
 *     NAME.key         public-key = "<40 Z85 characters>"       mode 0644
 *     NAME.key_secret  public-key and secret-key                mode 0600
 *
 * The master reads its NAME.key_secret (--curve-secret) and a folder of
 * workers' NAME.key files (--allow-keys); a worker reads its own
 * NAME.key_secret and the master's NAME.key (--master-key). Bad files are
 * reported as FILE:LINE:COL with what to do; a secret file that others
 * can read is refused (as ssh refuses such a private key).
 *
 * Also here: whether an endpoint stays on this host (loopback, ipc,
 * inproc), the one place that decides when CURVE is required.
 */
#ifndef PROTO_CURVE_CERT_H
#define PROTO_CURVE_CERT_H

#include <stdbool.h>
#include <stddef.h>

enum { CURVE_Z85_LEN = 40 };   /* a 32-byte key in Z85 */

typedef struct curve_cert {
    char public_key[CURVE_Z85_LEN + 1];   /* Z85, NUL-terminated */
    char secret_key[CURVE_Z85_LEN + 1];   /* "" when the file holds no secret */
} curve_cert;

/* Writes base.key and base.key_secret (a new random key pair; `name` goes
 * into the metadata). Refuses when either file exists (nothing is
 * overwritten, nothing half-written is left). False with err on failure. */
bool curve_cert_generate(const char *base, const char *name, char *err, size_t errsz);

/* Reads a certificate file. want_secret: the file must hold a secret-key
 * and must not be readable by group or others. False with err naming
 * FILE:LINE:COL (or FILE) and what to do. */
bool curve_cert_read(const char *path, bool want_secret, curve_cert *out, char *err,
                     size_t errsz);

/* False for endpoints another host can reach: tcp:// other than on
 * 127.x.x.x, localhost or [::1] (a wildcard, a host name, an interface
 * address), and the other network transports (udp, pgm, epgm, norm, ws,
 * wss, tipc, vmci): those need CURVE or --insecure. True otherwise (ipc,
 * inproc, loopback; a transport ZeroMQ does not know fails at bind). */
bool curve_endpoint_is_local(const char *endpoint);

#endif

/*
 * curve_cert.c: CurveZMQ certificate files (see curve_cert.h): writing a
 * new key pair, reading one back with FILE:LINE:COL diagnostics, and the
 * rule for endpoints that stay on this host.
 */
#include "curve_cert.h"
#include "util/err.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include <zmq.h>

/* ---- writing ---- */

static bool write_all(int fd, const char *text)
{
    size_t len = strlen(text), off = 0;
    while (off < len) {
        ssize_t n = write(fd, text + off, len - off);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        off += (size_t)n;
    }
    return true;
}

/* Creates path exclusively with mode and writes text; on failure nothing
 * is left behind. */
static bool create_file(const char *path, mode_t mode, const char *text, char *err, size_t errsz)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
    if (fd < 0) {
        err_set(err, errsz, "cannot create %s: %s%s", path, strerror(errno),
                errno == EEXIST ? " (remove it first if you mean to replace the key)" : "");
        return false;
    }
    bool ok = fchmod(fd, mode) == 0 && write_all(fd, text) && fsync(fd) == 0;
    int e = errno;
    if (close(fd) != 0) ok = false;
    if (!ok) {
        err_set(err, errsz, "cannot write %s: %s", path, strerror(e));
        unlink(path);
    }
    return ok;
}

static void header(char *buf, size_t n, const char *kind, const char *name)
{
    char when[64] = "";
    time_t t = time(NULL);
    struct tm tm;
    if (gmtime_r(&t, &tm)) strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", &tm);
    snprintf(buf, n,
             "#   ****  Generated on %s by aafarm-keygen  ****\n"
             "#   ZeroMQ CURVE %s Certificate\n"
             "%s"
             "\n"
             "metadata\n"
             "    name = \"%s\"\n"
             "curve\n",
             when, kind,
             strcmp(kind, "**Secret**") == 0
                 ? "#   DO NOT PROVIDE THIS FILE TO OTHER USERS nor change its permissions.\n"
                 : "#   Exchange securely, or use a secure mechanism to verify the contents\n"
                   "#   of this file after exchange.\n",
             name);
}

bool curve_cert_generate(const char *base, const char *name, char *err, size_t errsz)
{
    char pub_path[4096], sec_path[4096];
    if (snprintf(pub_path, sizeof pub_path, "%s.key", base) >= (int)sizeof pub_path ||
        snprintf(sec_path, sizeof sec_path, "%s.key_secret", base) >= (int)sizeof sec_path) {
        err_set(err, errsz, "the name '%.200s...' is too long", base);
        return false;
    }
    for (const char *p = name; *p; p++)
        if (*p == '"' || *p == '\n' || *p == '\\') {
            err_set(err, errsz, "the name '%s' has a quote, backslash or line break", name);
            return false;
        }
    struct stat st;
    if (lstat(pub_path, &st) == 0 || lstat(sec_path, &st) == 0) {
        err_set(err, errsz, "%s already exists: not overwriting a key (remove %s and %s "
                "first if you mean to replace it)", lstat(pub_path, &st) == 0 ? pub_path : sec_path,
                pub_path, sec_path);
        return false;
    }
    char pub[CURVE_Z85_LEN + 1], sec[CURVE_Z85_LEN + 1];
    if (zmq_curve_keypair(pub, sec) != 0) {
        err_set(err, errsz, "cannot make a key pair: %s (is libzmq built with CURVE, i.e. "
                "libsodium?)", zmq_strerror(errno));
        return false;
    }
    char head[1024], text[1400];
    header(head, sizeof head, "**Secret**", name);
    snprintf(text, sizeof text, "%s    public-key = \"%s\"\n    secret-key = \"%s\"\n", head, pub,
             sec);
    if (!create_file(sec_path, 0600, text, err, errsz)) return false;
    header(head, sizeof head, "Public", name);
    snprintf(text, sizeof text, "%s    public-key = \"%s\"\n", head, pub);
    if (!create_file(pub_path, 0644, text, err, errsz)) {
        unlink(sec_path);
        return false;
    }
    return true;
}

/* ---- reading ---- */

/* Parses `key = "Z85"` at p (after the key name); the column of any error
 * goes to *col. */
static bool parse_value(const char *line, const char *p, char out[CURVE_Z85_LEN + 1], int *col,
                        const char **why)
{
    while (*p == ' ' || *p == '\t') p++;
    if (*p != '=') {
        *col = (int)(p - line) + 1;
        *why = "expected '=' after the key's name";
        return false;
    }
    p++;
    while (*p == ' ' || *p == '\t') p++;
    if (*p != '"') {
        *col = (int)(p - line) + 1;
        *why = "expected a quoted Z85 key";
        return false;
    }
    const char *start = ++p;
    while (*p && *p != '"') p++;
    if (*p != '"' || p - start != CURVE_Z85_LEN) {
        *col = (int)(start - line) + 1;
        *why = "a key is 40 Z85 characters in double quotes";
        return false;
    }
    memcpy(out, start, CURVE_Z85_LEN);
    out[CURVE_Z85_LEN] = '\0';
    uint8_t raw[32];
    if (!zmq_z85_decode(raw, out)) {
        *col = (int)(start - line) + 1;
        *why = "not a valid Z85 key";
        return false;
    }
    return true;
}

bool curve_cert_read(const char *path, bool want_secret, curve_cert *out, char *err,
                     size_t errsz)
{
    memset(out, 0, sizeof *out);
    FILE *fp = fopen(path, "r");
    if (!fp) {
        err_set(err, errsz, "cannot read %s: %s%s", path, strerror(errno),
                errno == ENOENT ? " (make a key pair with aafarm-keygen NAME)" : "");
        return false;
    }
    struct stat st;
    if (want_secret && fstat(fileno(fp), &st) == 0 && (st.st_mode & 077)) {
        err_set(err, errsz, "%s: permissions %04o are too open for a secret key: others could "
                "read it (chmod 600 %s)", path, (unsigned)(st.st_mode & 07777), path);
        fclose(fp);
        return false;
    }
    char line[1024];
    int lineno = 0;
    bool ok = true;
    while (ok && fgets(line, sizeof line, fp)) {
        lineno++;
        const char *p = line;
        while (*p == ' ' || *p == '\t') p++;
        char *target = NULL;
        size_t skip = 0;
        if (strncmp(p, "public-key", 10) == 0) target = out->public_key, skip = 10;
        else if (strncmp(p, "secret-key", 10) == 0) target = out->secret_key, skip = 10;
        if (!target) continue;
        int col = 0;
        const char *why = "";
        if (!parse_value(line, p + skip, target, &col, &why)) {
            err_set(err, errsz, "%s:%d:%d: %s (is this a certificate from aafarm-keygen?)", path,
                    lineno, col, why);
            ok = false;
        }
    }
    fclose(fp);
    if (!ok) return false;
    if (!out->public_key[0]) {
        err_set(err, errsz, "%s: no public-key line: not a ZeroMQ certificate (make one with "
                "aafarm-keygen NAME)", path);
        return false;
    }
    if (want_secret && !out->secret_key[0]) {
        err_set(err, errsz, "%s: no secret-key line: this is a public key; give the "
                "NAME.key_secret file", path);
        return false;
    }
    if (out->secret_key[0]) {
        /* the pair must match: derive the public key from the secret */
        char derived[CURVE_Z85_LEN + 1];
        if (zmq_curve_public(derived, out->secret_key) != 0 ||
            strcmp(derived, out->public_key) != 0) {
            err_set(err, errsz, "%s: its public-key does not belong to its secret-key (the file "
                    "was edited; make a new pair with aafarm-keygen)", path);
            return false;
        }
    }
    return true;
}

/* ---- endpoints ---- */

bool curve_endpoint_is_local(const char *ep)
{
    static const char *const network[] = {"udp://", "pgm://", "epgm://", "norm://", "ws://",
                                          "wss://", "tipc://", "vmci://"};
    for (size_t i = 0; i < sizeof network / sizeof *network; i++)
        if (strncmp(ep, network[i], strlen(network[i])) == 0) return false;
    if (strncmp(ep, "tcp://", 6) != 0) return true;   /* ipc, inproc, or ZeroMQ refuses it */
    const char *host = ep + 6;
    const char *semi = strchr(host, ';');   /* "source;dest": judge the bound side */
    if (semi) host = semi + 1;
    if (strncmp(host, "127.", 4) == 0) return true;
    if (strncmp(host, "localhost:", 10) == 0) return true;
    if (strncmp(host, "[::1]:", 6) == 0) return true;
    return false;
}

/*
 * zap.c: the master's ZAP handler for CurveZMQ (see zap.h; ZeroMQ RFC 27
 * for the request and reply frames).
 */
#include "zap.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zmq.h>

#include "curve_cert.h"
#include "util/err.h"
#include "util/xalloc.h"

enum { ZAP_MAX_KEYS = 65536, ZAP_LOGGED_PEERS = 256, ZAP_FRAMES = 8 };

typedef struct refused_peer {
    char address[64];
    uint8_t key[32];
} refused_peer;

struct zap {
    void *rep;
    console *con;
    uint8_t (*keys)[32];
    int nkeys;
    refused_peer logged[ZAP_LOGGED_PEERS];
    int nlogged;
    uint64_t admitted, refused, unlogged;
};

static bool has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n > k && strcmp(s + n - k, suffix) == 0;
}

static bool load_keys(zap *z, const char *dir, char *err, size_t errsz)
{
    DIR *d = opendir(dir);
    if (!d) {
        err_set(err, errsz, "--allow-keys %s: %s", dir, strerror(errno));
        return false;
    }
    bool ok = true;
    for (struct dirent *e; ok && (e = readdir(d));) {
        /* a secret key has no business here: only its owner may hold it */
        if (has_suffix(e->d_name, ".key_secret")) {
            err_set(err, errsz, "--allow-keys %s: %s/%s is a secret key; only the workers' "
                    "public keys (NAME.key) belong there: move it out and keep it with "
                    "its worker", dir, dir, e->d_name);
            ok = false;
            break;
        }
        if (!has_suffix(e->d_name, ".key")) continue;
        if (z->nkeys >= ZAP_MAX_KEYS) {
            err_set(err, errsz, "--allow-keys %s: more than %d keys", dir, ZAP_MAX_KEYS);
            ok = false;
            break;
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        curve_cert c;
        if (!curve_cert_read(path, false, &c, err, errsz)) {
            ok = false;
            break;
        }
        if (c.secret_key[0]) {   /* a secret renamed NAME.key */
            memset(&c, 0, sizeof c);
            err_set(err, errsz, "--allow-keys %s: %s holds a secret key; only the workers' "
                    "public keys (NAME.key) belong there: put the public key in its "
                    "place", dir, path);
            ok = false;
            break;
        }
        uint8_t (*grown)[32] = xrealloc(z->keys, sizeof *z->keys * (size_t)(z->nkeys + 1));
        z->keys = grown;
        zmq_z85_decode(z->keys[z->nkeys++], c.public_key);
    }
    closedir(d);
    if (ok && z->nkeys == 0) {
        err_set(err, errsz, "--allow-keys %s: no NAME.key file in it (copy each worker's "
                "public key there; make them with aafarm-keygen NAME)", dir);
        ok = false;
    }
    return ok;
}

zap *zap_new(void *ctx, const char *allow_dir, console *con, char *err, size_t errsz)
{
    zap *z = xcalloc(1, sizeof *z);
    z->con = con;
    if (!load_keys(z, allow_dir, err, errsz)) {
        zap_destroy(&z);
        return NULL;
    }
    z->rep = zmq_socket(ctx, ZMQ_REP);
    int linger = 0;
    if (!z->rep || zmq_setsockopt(z->rep, ZMQ_LINGER, &linger, sizeof linger) != 0 ||
        zmq_bind(z->rep, "inproc://zeromq.zap.01") != 0) {
        err_set(err, errsz, "cannot start the authentication handler: %s", zmq_strerror(errno));
        zap_destroy(&z);
        return NULL;
    }
    return z;
}

void zap_destroy(zap **self_p)
{
    if (!self_p || !*self_p) return;
    zap *z = *self_p;
    if (z->rep) zmq_close(z->rep);
    free(z->keys);
    free(z);
    *self_p = NULL;
}

void *zap_socket(zap *self) { return self ? self->rep : NULL; }
int zap_key_count(const zap *self) { return self ? self->nkeys : 0; }
uint64_t zap_admitted(const zap *self) { return self ? self->admitted : 0; }
uint64_t zap_refused(const zap *self) { return self ? self->refused : 0; }

static bool allowed(const zap *z, const uint8_t key[32])
{
    for (int i = 0; i < z->nkeys; i++)
        if (memcmp(z->keys[i], key, 32) == 0) return true;
    return false;
}

/* Logs a refusal the first time this (address, key) is refused. */
static void log_refusal(zap *z, const char *address, const uint8_t key[32], const char *why)
{
    for (int i = 0; i < z->nlogged; i++)
        if (strcmp(z->logged[i].address, address) == 0 &&
            memcmp(z->logged[i].key, key, 32) == 0)
            return;
    if (z->nlogged == ZAP_LOGGED_PEERS) {
        if (z->unlogged++ % 1000 == 0)
            console_log(z->con, CONSOLE_INFO, "refused more peers (%llu refusals so far; not "
                        "logging each)", (unsigned long long)z->refused);
        return;
    }
    refused_peer *p = &z->logged[z->nlogged++];
    snprintf(p->address, sizeof p->address, "%s", address);
    memcpy(p->key, key, 32);
    char z85[CURVE_Z85_LEN + 1] = "?";
    uint8_t raw[32];
    memcpy(raw, key, 32);
    zmq_z85_encode(z85, raw, 32);
    console_log(z->con, CONSOLE_INFO, "refused a connection from %s: %s (key %s); further "
                "attempts from it are not logged", address[0] ? address : "?", why, z85);
}

static void send_frame(void *s, const void *data, size_t len, bool more)
{
    zmq_send(s, data, len, more ? ZMQ_SNDMORE : 0);
}

static void reply(zap *z, const zmq_msg_t *request_id, const char *status, const char *text)
{
    send_frame(z->rep, "1.0", 3, true);
    send_frame(z->rep, zmq_msg_data((zmq_msg_t *)request_id), zmq_msg_size((zmq_msg_t *)request_id),
               true);
    send_frame(z->rep, status, strlen(status), true);
    send_frame(z->rep, text, strlen(text), true);
    send_frame(z->rep, "", 0, true);    /* user id */
    send_frame(z->rep, "", 0, false);   /* metadata */
}

static void copy_str(char *dst, size_t n, zmq_msg_t *m)
{
    size_t len = zmq_msg_size(m);
    if (len >= n) len = n - 1;
    memcpy(dst, zmq_msg_data(m), len);
    dst[len] = '\0';
}

/* One request: version, request id, domain, address, identity, mechanism,
 * credentials... */
static bool answer_one(zap *z)
{
    zmq_msg_t f[ZAP_FRAMES];
    int n = 0;
    bool more = true;
    while (more) {
        zmq_msg_t m;
        zmq_msg_init(&m);
        if (zmq_msg_recv(&m, z->rep, n == 0 ? ZMQ_DONTWAIT : 0) < 0) {
            zmq_msg_close(&m);
            for (int i = 0; i < n; i++) zmq_msg_close(&f[i]);
            return false;
        }
        more = zmq_msg_more(&m);
        if (n < ZAP_FRAMES) f[n++] = m;
        else zmq_msg_close(&m);
    }
    char mechanism[16] = "", address[64] = "";
    if (n >= 6) {
        copy_str(mechanism, sizeof mechanism, &f[5]);
        copy_str(address, sizeof address, &f[3]);
    }
    if (n < 2) {
        /* not a ZAP request: answer nothing sensible, but answer (REP) */
        zmq_msg_t empty;
        zmq_msg_init(&empty);
        reply(z, &empty, "500", "malformed request");
        zmq_msg_close(&empty);
    } else if (strcmp(mechanism, "NULL") == 0) {
        z->admitted++;
        reply(z, &f[1], "200", "OK");
    } else if (strcmp(mechanism, "CURVE") == 0 && n >= 7 && zmq_msg_size(&f[6]) == 32) {
        const uint8_t *key = zmq_msg_data(&f[6]);
        if (allowed(z, key)) {
            z->admitted++;
            reply(z, &f[1], "200", "OK");
        } else {
            z->refused++;
            log_refusal(z, address, key, "its public key is not in --allow-keys");
            reply(z, &f[1], "400", "key not allowed");
        }
    } else {
        z->refused++;
        uint8_t none[32] = {0};
        log_refusal(z, address, none, "not a CURVE client");
        reply(z, &f[1], "400", "CURVE required");
    }
    for (int i = 0; i < n; i++) zmq_msg_close(&f[i]);
    return true;
}

void zap_answer(zap *self)
{
    if (!self) return;
    for (int i = 0; i < 1000 && answer_one(self); i++) {}
}

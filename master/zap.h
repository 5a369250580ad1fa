/*
 * zap.h: the master's ZeroMQ authentication handler (ZAP, ZeroMQ RFC 27)
 * for CurveZMQ (docs/cluster.md, "Security").
 *
 * With --curve-secret and --allow-keys the master's network endpoint
 * speaks CURVE: every connection is encrypted, and libzmq asks this
 * handler, on inproc://zeromq.zap.01 of the master's context, whether the
 * client's long-term public key may connect. It may when it is one of the
 * NAME.key files in the --allow-keys folder (read once at start). Every
 * other key is refused (status 400), and each refusal is logged once per
 * peer: its IP address and key (the rest are counted). The NULL mechanism
 * is admitted: only the private ipc:// endpoint of the local workers
 * (a 0700 folder) speaks it; the network endpoint refuses plaintext in
 * the handshake, before ZAP.
 *
 * Single-threaded: the master's loop polls zap_socket() and calls
 * zap_answer().
 */
#ifndef MASTER_ZAP_H
#define MASTER_ZAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "console.h"

typedef struct zap zap;

/* Reads the public keys in allow_dir (files named *.key) and binds the
 * handler in ctx. NULL with err when the folder cannot be read, a key
 * file is bad, or there is no key at all. */
zap *zap_new(void *ctx, const char *allow_dir, console *con, char *err, size_t errsz);
void zap_destroy(zap **self_p);

void *zap_socket(zap *self);      /* for zmq_poll */
int zap_key_count(const zap *self);

/* Answers every pending request without waiting. */
void zap_answer(zap *self);

uint64_t zap_admitted(const zap *self);
uint64_t zap_refused(const zap *self);

#endif

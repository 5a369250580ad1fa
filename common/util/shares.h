/*
 * shares.h: running one function over shares of a piece of work, each on a
 * thread of its own (the world's build, trace/; a mesh's faces, scene/
 * rib_mesh.c). The caller splits the work and puts the results together in
 * its own order, so what it makes does not depend on the number of shares.
 */
#ifndef UTIL_SHARES_H
#define UTIL_SHARES_H

#include <stddef.h>

/* Runs fn on each of the n shares (shares[i] at shares + i * size): share
 * 0 on the calling thread, the others on threads of their own, joined
 * before it returns; a share whose thread cannot be started runs on the
 * calling thread after share 0. */
void util_run_shares(void *shares, size_t size, int n, void *(*fn)(void *));

#endif

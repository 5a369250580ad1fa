/*
 * lazy_roots.h: a displaced mesh's pieces' root boxes, made when a ray
 * first reaches a piece (issue 23; mesh.c) and shared by every thread of
 * the world: a piece's root box is its shader run over the whole piece
 * (Heidrich & Seidel 1998 §3.1), kept with its du and dv. Each is a pure
 * function of the scene, so whichever thread makes one first publishes
 * it, and a thread that made it too drops its copy (the same bits): what
 * a render sees does not depend on the order of the work.
 *
 * Budget (issue 23): the store holds at most budget_bytes (0: unlimited),
 * its table and slots counted. Piece k goes to slot k mod nslots, nslots
 * as many as the budget pays for (at most one a piece); a root published
 * into a slot that holds another piece's evicts it, and the evicted root
 * is made again where a ray reaches its piece: the same bits, so the
 * budget changes speed only, never pixels, at any thread count.
 * trace_options.roots_bytes is the world's budget, shared by its displaced
 * meshes in proportion to their pieces (mesh.c).
 *
 * Storage grows by chunks of 16 slots, made when a root is first
 * published into one: a mesh whose rays reach a tenth of its pieces holds
 * about a tenth of the slots. Lock-free: a slot is a sequence lock
 * (Boehm, "Can seqlocks get along with programming language memory
 * models?", 2012): a writer claims it by moving its count from even to
 * odd (and gives up if it cannot: another thread is writing), a reader
 * copies it and keeps the copy only when the count was even and the same
 * before and after. Slots are never freed before the store.
 */
#ifndef TRACE_LAZY_ROOTS_H
#define TRACE_LAZY_ROOTS_H

#include <stdbool.h>
#include <stddef.h>

#include "trace/box.h"

typedef struct trace_lazy_roots trace_lazy_roots;

/* budget_bytes: what the store may hold, all counted (0: unlimited); at
 * least one slot whatever the budget */
trace_lazy_roots *trace_lazy_roots_new(int npieces, size_t budget_bytes);
void trace_lazy_roots_destroy(trace_lazy_roots **self);

/* Piece k's root box into *root (and its du, dv into dudv) when it is
 * held; false when not (never made, or evicted). */
bool trace_lazy_root(const trace_lazy_roots *self, int k, trace_box *root, double dudv[2]);
/* True when this call stored it (false: it was held already, or another
 * thread is writing its slot: the root is dropped, to be made again). */
bool trace_lazy_root_put(trace_lazy_roots *self, int k, const trace_box *root, double du,
                         double dv);

/* Root boxes held now (tests, bench), and evicted so far */
long trace_lazy_roots_known(const trace_lazy_roots *self);
long trace_lazy_roots_evicted(const trace_lazy_roots *self);
/* Slots: roots the store can hold at once */
int trace_lazy_roots_slots(const trace_lazy_roots *self);

/* Bytes held: the store, its chunk table and the chunks made */
size_t trace_lazy_roots_bytes(const trace_lazy_roots *self);

#endif

/*
 * lazy_roots.h: a displaced mesh's pieces' root boxes, made when a ray
 * first reaches a piece (issue 23; mesh.c) and shared by every thread of
 * the world: a piece's root box is its shader run over the whole piece
 * (Heidrich & Seidel 1998 §3.1), kept with its du and dv. Each is a pure
 * function of the scene, so whichever thread makes one first publishes
 * it, and a thread that made it too drops its copy (the same bits): what
 * a render sees does not depend on the order of the work.
 *
 * Storage grows by chunks of 16 pieces, made when their first piece is
 * published: a mesh whose rays reach a tenth of its pieces holds about a
 * tenth of the root boxes. Lock-free: an entry goes empty -> being
 * written -> known (a release store), and readers load it with acquire.
 */
#ifndef TRACE_LAZY_ROOTS_H
#define TRACE_LAZY_ROOTS_H

#include <stdbool.h>
#include <stddef.h>

#include "trace/box.h"

typedef struct trace_lazy_roots trace_lazy_roots;

trace_lazy_roots *trace_lazy_roots_new(int npieces);
void trace_lazy_roots_destroy(trace_lazy_roots **self);

/* Piece k's root box (and its du, dv into dudv) when published; NULL when
 * not yet. The box stays valid until the store is destroyed. */
const trace_box *trace_lazy_root(const trace_lazy_roots *self, int k, double dudv[2]);
/* True when this call published it (false: another thread had). */
bool trace_lazy_root_put(trace_lazy_roots *self, int k, const trace_box *root, double du,
                         double dv);

/* Root boxes published so far (tests, bench) */
long trace_lazy_roots_known(const trace_lazy_roots *self);

/* Bytes held: the chunk table and the chunks made */
size_t trace_lazy_roots_bytes(const trace_lazy_roots *self);

#endif

/*
 * converge.h: does an object's displaced surface converge under
 * subdivision? (issue 9, bounded work.) Heidrich & Seidel's subdivision
 * (§3) relies on boxes that shrink with their (u,v) cells; a shader with
 * an extreme parameter (a frequency of -1e308) or a result that is NaN or
 * infinite everywhere gives boxes that never do, and every ray would run
 * to the work limit. When a ray reaches the limit, the renderer asks this
 * once per object and thread; a surface that does not converge fails the
 * render with a message that names the shader, the object and the likely
 * cause, instead of spending minutes on an image it cannot resolve.
 *
 * The test is a pure function of the object: at 16 fixed (u,v) positions
 * it compares the box of the 2^-20-wide cell with that of the 2^-14-wide
 * cell around it. A continuous surface shrinks its box about 64-fold over
 * those six levels; the surface fails when the median ratio exceeds 1/2,
 * or when every sampled box is unbounded.
 */
#ifndef TRACE_CONVERGE_H
#define TRACE_CONVERGE_H

#include <stdbool.h>
#include <stddef.h>

#include "trace/thread.h"
#include "trace/world.h"

bool trace_surface_converges(trace_thread *th, const trace_object *obj, char *err,
                             size_t errsz);

#endif

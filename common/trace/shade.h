/*
 * shade.h: what a primary hit looks like: the surface shader (float mode)
 * run with RenderMan's globals, the scene's lights (RI Spec 3.2 Appendix A:
 * ambientlight, distantlight, pointlight, spotlight) through the VM's light
 * callback, and ray-traced shadows (displaced objects cast and receive
 * them through the same subdivision intersector).
 *
 * Shadow rays leave the surface from the hit point moved along the normal,
 * on the light's side, by twice the size of the leaf box the hit came from
 * (plus a relative epsilon): the displaced surface is only known to within
 * that box, so a smaller offset could find the surface itself.
 *
 * Shaders trace rays too (RI Spec 3.2 §15.6, §15.7, through the VM's
 * sl_tracer): trace(P, R) in a surface shader shades the hit it finds with
 * that object's surface shader on the VM of the next depth (at most
 * TRACE_MAX_RAY_DEPTH deep, then black); shadow(map, P) in a light shader
 * or an illuminance loop traces a shadow ray towards the light (there are
 * no shadow maps yet: one warning per light says so). Both leave the
 * surface like shadow rays, with the shadow rays' tolerance.
 */
#ifndef TRACE_SHADE_H
#define TRACE_SHADE_H

#include "trace/render.h"

/* Colour (premultiplied), alpha and camera-space point of a hit. */
void trace_shade_hit(const trace_renderer *r, trace_thread *th,
                     const trace_ray *ray, const trace_hit *hit,
                     double rgb[3], double *alpha, vec3 *P_out);

#endif

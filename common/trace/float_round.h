/*
 * float_round.h: doubles as floats rounded down or up (and the float next
 * to a float): the box cache's float boxes (box.h), the float boxes of the
 * BVHs (mesh.c, region.c) and the linear bounds' radii (lin_bound.h).
 */
#ifndef TRACE_FLOAT_ROUND_H
#define TRACE_FLOAT_ROUND_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* The float after f towards +infinity (up) or -infinity: nextafterf's
 * number without the call, for an f that is not NaN and not the infinity
 * it steps towards (floats of one sign are ordered as their bits; from a
 * zero, the smallest subnormal) */
static inline float trace_float_step(float f, bool up)
{
    if (f == 0.0f) return up ? 0x1p-149f : -0x1p-149f;
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    b += (f > 0.0f) == up ? 1u : ~0u;
    memcpy(&f, &b, sizeof f);
    return f;
}

/* x as a float rounded down (up) */
static inline float trace_float_down(double x)
{
    float f = (float)x;
    return (double)f > x ? trace_float_step(f, false) : f;
}

static inline float trace_float_up(double x)
{
    float f = (float)x;
    return (double)f < x ? trace_float_step(f, true) : f;
}

#endif

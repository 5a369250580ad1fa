/*
 * sampler.h: deterministic sample positions. Every random number of a
 * render derives from (pixel x, pixel y, sample index, purpose) through a
 * hash (SplitMix64's finaliser, Steele, Lea & Flood 2014), never from a
 * stream, so a pixel's samples do not depend on tile size, tile order,
 * thread or worker (the determinism contract, DESIGN.md §2).
 */
#ifndef TRACE_SAMPLER_H
#define TRACE_SAMPLER_H

#include <stdint.h>

static inline uint64_t trace_hash64(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/* A number in [0, 1) for (px, py, sample, purpose). */
static inline double trace_sample_1d(int64_t px, int64_t py, int sample, int purpose)
{
    uint64_t h = trace_hash64((uint64_t)px * 0x100000001b3ull);
    h = trace_hash64(h ^ (uint64_t)py);
    h = trace_hash64(h ^ ((uint64_t)(uint32_t)sample << 8) ^ (uint64_t)(uint32_t)purpose);
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* Stratified jittered position of sample s of pixel (px, py) with
 * nx * ny strata: raster coordinates inside [px, px+1) x [py, py+1). */
static inline void trace_sample_position(int64_t px, int64_t py, int s, int nx, int ny,
                                         double *x, double *y)
{
    int sx = s % nx, sy = s / nx;
    double jx = trace_sample_1d(px, py, s, 0), jy = trace_sample_1d(px, py, s, 1);
    /* offsets stay below 1 - 2^-24, so px + offset < px + 1 exactly for
     * any raster coordinate below 2^28: a sample never leaves its pixel */
    const double top = 1.0 - 1.0 / 16777216.0;
    double ox = (sx + jx) / nx, oy = (sy + jy) / ny;
    *x = (double)px + (ox < top ? ox : top);
    *y = (double)py + (oy < top ? oy : top);
}

/* The lens position of sample s of pixel (px, py), in [0,1)^2: stratified
 * on the same nx * ny grid as the pixel samples, the strata handed out in
 * an order rotated per pixel (so that a sample's lens stratum does not
 * follow its pixel stratum), jittered by purposes 2 and 3. Deterministic
 * like every sample: a farm render equals the standalone one. */
static inline void trace_sample_lens(int64_t px, int64_t py, int s, int nx, int ny,
                                     double *u, double *v)
{
    int ns = nx * ny;
    int rot = (int)(trace_hash64(((uint64_t)px << 32) ^ (uint64_t)(uint32_t)py ^
                                 0x6c656e73ull) % (uint64_t)ns);
    int ls = (s + rot) % ns;
    int sx = ls % nx, sy = ls / nx;
    *u = (sx + trace_sample_1d(px, py, s, 2)) / nx;
    *v = (sy + trace_sample_1d(px, py, s, 3)) / ny;
}

#endif

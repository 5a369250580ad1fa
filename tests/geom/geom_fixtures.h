/*
 * geom_fixtures.h: what the tests of common/geom share: a fixed-seed random
 * generator, a set of prepared surfaces of every kind (full and partial
 * sweeps, odd orientations), and an independent long double oracle of P,
 * dPdu, dPdv and Ng written straight from the RI spec §5.2 formulas (not
 * from the library's rotation-of-a-profile scheme), against which the
 * float, interval and affine evaluations are checked.
 */
#ifndef TESTS_GEOM_FIXTURES_H
#define TESTS_GEOM_FIXTURES_H

#include <stdint.h>

#include "geom/surface.h"

/* ---- random numbers (splitmix64, fixed seed per test, varied by the
 * environment variable AAFARM_PROPERTY_SEED) ---- */
void fx_seed(uint64_t seed);
double fx_unit(void);                    /* [0, 1) */
double fx_range(double lo, double hi);
vec3 fx_unit_vector(void);

/* ---- fixtures ---- */
typedef struct fx_surface {
    const char *name;
    geom_surface s;
    double size;                         /* rough extent of the surface */
} fx_surface;

/* All fixtures, prepared (the function asserts that prepare succeeds). */
int fx_surfaces(fx_surface **out);

/* A zero-initialised surface of the kind, with RenderMan's typical
 * parameters for it (not prepared). */
geom_surface fx_default(geom_kind kind);

/* ---- the oracle ---- */
typedef struct fx_exact {
    long double P[3], Pu[3], Pv[3], Ng[3];
} fx_exact;

void fx_oracle(const geom_surface *s, double u, double v, fx_exact *out);

/* Is (u,v) a real point of the surface (polygons: inside)? */
bool fx_on_surface(const geom_surface *s, double u, double v);

#endif

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

/* ---- subdivision meshes (geom/subdiv.h); NULL if refused (a message on
 * stderr) ---- */
struct geom_subdiv;
/* The cube of FX_CUBE_P (8 points, 6 quads, valence 3) with the creases
 * and corners given (geom_subdiv_desc's fields) */
extern const double FX_CUBE_P[24];
struct geom_subdiv *fx_subdiv_cube(int ncreases, const int *clen, const int *cverts,
                                   const double *csharp, int ncorners, const int *corners,
                                   const double *csh);
/* n quads (n <= FX_FAN_MAX) around point 0, a boundary outside
 * (interpolateboundary): points 0, the edge points E_i = 1 + 2i and the
 * face points F_i = 2 + 2i, their coordinates in *P (3 doubles a point,
 * until the next call) */
enum { FX_FAN_MAX = 40 };
struct geom_subdiv *fx_subdiv_fan(int n, const double **P);

#endif

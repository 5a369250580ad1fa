/*
 * subdiv_ev.h: a proven cone of normals over the irregular sub-face at an
 * interior smooth extraordinary point (EV) of a Catmull-Clark surface, from
 * the sub-face's 2n+8 control points (docs/geometry.md, "Proven normals at
 * smooth extraordinary points"). Not wired into the renderer yet.
 *
 * The ring's canonical order (n the valence, sector i between the EV's edges
 * i and i+1, G_i(a, b) the grid point a steps along edge i and b along edge
 * i+1): the EV, e_0..e_{n-1} = G_i(1, 0), f_0..f_{n-1} = G_i(1, 1), then
 * G_0(2,0) G_0(2,1) G_0(2,2) G_0(1,2) G_0(0,2) G_0(-1,2) G_0(2,-1). The
 * sub-face is sector 0's cell [0,1]^2, u along e_0, v along e_1.
 */
#ifndef GEOM_SUBDIV_EV_H
#define GEOM_SUBDIV_EV_H

#include <stdbool.h>

#include "aa/interval.h"

enum { SD_EV_NMAX = 16, SD_EV_RING_MAX = 2 * SD_EV_NMAX + 8 };

/* What the per-valence proof found (for tests, benches and the docs). */
typedef struct sd_ev_info {
    bool proven;        /* every step below succeeded */
    const char *failed; /* else the step that failed (a static string) */
    double lambda_lo;   /* the subdominant eigenvalue, lower end */
    double eig_rad;     /* radius of the eigenvector enclosures (after normalising) */
    int P;              /* ||B^P||_inf <= lambda^P / 2 first at this P */
    double omega_sum;   /* sum of the decay weights */
    double C;           /* bound of |c1| + |c2| (characteristic map's derivatives) */
    double J;           /* lower bound of |J| over the 3 patches */
    int J_pieces;       /* the G x G split of each patch that gave J */
} sd_ev_info;

/* The per-valence constants, computed with interval arithmetic at first use
 * (under a lock; later calls read them without one). NULL where n is out of
 * range (3..SD_EV_NMAX, not 4) or a step of the proof failed. */
typedef struct sd_ev_consts sd_ev_consts;
const sd_ev_consts *sd_ev_consts_get(int n);
/* Why sd_ev_consts_get(n) is NULL (NULL where it is not). */
const char *sd_ev_failed(int n);
void sd_ev_consts_info(const sd_ev_consts *K, sd_ev_info *out);

/* One exact Catmull-Clark step on a ring in canonical order (2n+8 points,
 * each coordinate an interval), into out (may not alias X): the same points
 * one level down, enclosed. */
void sd_ev_step(const sd_ev_consts *K, const ia_interval (*X)[3], ia_interval (*out)[3]);

/* The cone: for the sub-face whose ring's exact points lie in X (each
 * coordinate an interval: the float ring widened by its rounding), every
 * nonzero Ng = dP/du x dP/dv of the exact limit surface over the sub-face
 * satisfies Ng / |Ng| = (a + eps) / |a + eps| for some unit vector a in
 * axis[] and |eps| <= *rho. False (nothing proven) where rho would not be
 * finite; a useful cone needs rho < 1. */
bool sd_ev_cone(const sd_ev_consts *K, const ia_interval (*X)[3], ia_interval axis[3],
                double *rho);

/* The unit normal box from the cone: axis +- sqrt(2) scale rho + pad, met
 * with [-1, 1]. False where the cone is not proven or rho >= 1. scale is 1
 * for the sound box (tests halve it on purpose to watch it fail); pad
 * covers the float evaluator's rounding (not part of the proof). */
bool sd_ev_unit_normal_box(const sd_ev_consts *K, const ia_interval (*X)[3], double scale,
                           double pad, ia_interval N[3]);

#endif

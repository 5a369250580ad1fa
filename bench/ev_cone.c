/*
 * ev_cone.c: how far the unit normals of a Catmull-Clark limit surface
 * stray from the limit normal at an interior smooth extraordinary point
 * (EV), level by level (issue 24: EV chains walk to the depth cap because
 * the irregular sub-face's unit normal is [-1,1]^3). A measurement, not a
 * bound: it samples the float evaluator (geom_eval_dual) on the L-shaped
 * ring of regular sub-patches at each level k next to the EV (the points
 * 2^-k (a, b), (a, b) in [0,1]^2 minus [0,1/2)^2) and prints the largest
 * angle to the normal at 2^-26 from the EV (deeper, the float normals
 * are the refinement's rounding: Ng is exactly 0 past 2^-40 at valence 3), with the ratio of
 * successive levels, next to the eigenvalues that predict it (Stam 1998: the subdominant lambda and
 * the next one, mu; the normal's spread at level k decays like (mu / lambda)^k, the sub-face's size
 * like lambda^k).
 *
 * Usage: ev_cone [levels]   (valence 3 on a bent cube, 5, 6, 8 on fans)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "geom/subdiv.h"
#include "geom/surface.h"

static double lam(int n, int w, int sign)
{
    double c = cos(2 * M_PI * w / n), h = cos(M_PI * w / n);
    return (5 + c + sign * h * sqrt(2 * (9 + c))) / 16;
}

static vec3 unit_normal(const geom_surface *s, int corner, double a, double b)
{
    /* (a, b) from the EV's corner of the face */
    double u = corner == 1 || corner == 2 ? 1 - a : a;
    double v = corner == 2 || corner == 3 ? 1 - b : b;
    geom_sample g;
    geom_eval_dual(s, u, v, &g);
    return v3_normalize(g.Ng);
}

static double angle(vec3 a, vec3 b)
{
    return atan2(v3_length(v3_cross(a, b)), v3_dot(a, b)) * 180 / M_PI;
}

static void study(const char *name, geom_subdiv *sd, int ev, int n, int levels)
{
    double l1 = lam(n, 1, 1), mu = fmax(fmax(0.25, lam(n, 1, -1)), n > 3 ? lam(n, 2, 1) : 0);
    printf("%s: valence %d, lambda %.4f, mu %.4f, mu/lambda %.4f\n", name, n, l1, mu, mu / l1);
    printf("  level  max angle (deg) on the ring   ratio to level above\n");
    /* the faces at the EV: take the first */
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        int p[4];
        geom_subdiv_face_points(sd, f, p);
        /* the EV at (u, v) = (0, 0): next to u = 1 the doubles are too
         * coarse (1 - 2^-40 keeps 13 bits) */
        int corner = p[0] == ev ? 0 : -1;
        if (corner < 0 || !geom_subdiv_face_drawn(sd, f)) continue;
        geom_surface s;
        geom_subdiv_surface(sd, f, &s);
        vec3 N0 = unit_normal(&s, corner, ldexp(1, -26), ldexp(1, -26));
        double prev = NAN;
        for (int k = 1; k <= levels; k++) {
            double worst = 0, sc = ldexp(1, -k);
            enum { G = 12 };
            for (int i = 0; i <= G; i++)
                for (int j = 0; j <= G; j++) {
                    double a = (double)i / G, b = (double)j / G;
                    if (a < 0.5 && b < 0.5) continue;
                    worst = fmax(worst, angle(unit_normal(&s, corner, a * sc, b * sc), N0));
                }
            printf("  %5d  %14.3e                 %.4f\n", k, worst, worst / prev);
            prev = worst;
        }
        break;
    }
    geom_subdiv_destroy(&sd);
}

int main(int argc, char **argv)
{
    int levels = argc > 1 ? atoi(argv[1]) : 24;
    char why[200];
    /* a bent cube: its corner 0 has valence 3 */
    static const double P[] = {-1, -1, -1, 1,   -1, -1,  1,   1,   -1,  -1, 1, -1,
                               -1, -1, 1,  1.2, -1, 1.1, 1.1, 0.8, 1.3, -1, 1, 0.9};
    static const int NV[] = {4, 4, 4, 4, 4, 4};
    static const int V[] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
    geom_subdiv_desc d = {6, NV, V, 8, P, 0, NULL, NULL, NULL, 0, NULL, NULL, 0, NULL, false};
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    if (!sd) {
        fprintf(stderr, "ev_cone: cube: %s\n", why);
        return 1;
    }
    study("bent cube", sd, 0, 3, levels);
    int vals[] = {5, 6, 8};
    for (int q = 0; q < 3; q++) {
        int n = vals[q];
        double fp[3 * 17];
        int fv[4 * 8], fnv[8];
        fp[0] = 0.1, fp[1] = -0.05, fp[2] = 0.3;
        for (int i = 0; i < n; i++) {
            double a = 2 * M_PI * i / n, b = 2 * M_PI * (i + 0.5) / n;
            double *E = fp + 3 * (1 + 2 * i), *F = fp + 3 * (2 + 2 * i);
            E[0] = cos(a), E[1] = sin(a), E[2] = 0.2 * sin(3 * a);
            F[0] = 1.5 * cos(b), F[1] = 1.5 * sin(b), F[2] = -0.3 + 0.1 * i;
            fv[4 * i] = 0, fv[4 * i + 1] = 1 + 2 * i, fv[4 * i + 2] = 2 + 2 * i;
            fv[4 * i + 3] = 1 + 2 * ((i + 1) % n);
            fnv[i] = 4;
        }
        geom_subdiv_desc fd = {n,    fnv, fv,   2 * n + 1, fp, 0,    NULL, NULL,
                               NULL, 0,   NULL, NULL,      0,  NULL, true};
        sd = geom_subdiv_new(&fd, why, sizeof why);
        if (!sd) {
            fprintf(stderr, "ev_cone: fan %d: %s\n", n, why);
            return 1;
        }
        char name[32];
        snprintf(name, sizeof name, "fan of %d", n);
        study(name, sd, 0, n, levels);
    }
    return 0;
}

/*
 * ev_check.c: EXPERIMENT (goes with subdiv_ev.c's numerical constants):
 * with EV_ROUTE=1, the unit normal boxes of the sub-faces at the
 * extraordinary corners (levels 1..22) against the float evaluator's
 * normals at 17 x 17 points of each box and of boxes 2^-3, 2^-6, ... deeper,
 * no nearer the point than 2^-(LIMIT+4) (the float normals are rounding
 * noise deeper). Usage: ev_check [shrink] [LIMIT]: shrink < 1 narrows the
 * boxes on purpose (0.5 must fail).
 */
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include "geom/subdiv.h"
#include "geom/surface.h"
static double HALVE = 1; static int LIMIT = 22;
static void check(const char *name, geom_subdiv *sd, int ev)
{
    long viol = 0, boxes = 0, samples = 0; double worst = 0;
    for (int f = 0; f < geom_subdiv_nfaces(sd); f++) {
        int p[4]; geom_subdiv_face_points(sd, f, p);
        for (int k = 0; k < 4; k++) {
            if (p[k] != ev) continue;
            geom_surface s; geom_subdiv_surface(sd, f, &s);
            for (int j = 1; j <= 22; j++) {
                double w = ldexp(1, -j);
                double u0 = (k == 1 || k == 2) ? 1 - w : 0, v0 = (k >= 2) ? 1 - w : 0;
                ia_interval Nn[3];
                if (!geom_subdiv_unit_normal_box(&s, ia_make(u0, u0 + w), ia_make(v0, v0 + w), Nn)) { printf("  %s f%d level %d: no box\n", name, f, j); continue; }
                boxes++;
                double width = Nn[0].hi - Nn[0].lo;
                for (int q = 0; q < 3; q++) { double c = (Nn[q].lo + Nn[q].hi) / 2, h = (Nn[q].hi - Nn[q].lo) / 2 * HALVE; Nn[q] = ia_make(c - h, c + h); }
                for (int a = 0; a <= 16; a++) for (int b = 0; b <= 16; b++) {
                    for (int d = 0; d < 6; d++) {   /* deeper too */
                        if (j + 3 * d > LIMIT) continue;
                        double sc = w * ldexp(1, -3 * d);
                        double uu = (k == 1 || k == 2) ? 1 - sc * a / 16 : sc * a / 16;
                        double vv = (k >= 2) ? 1 - sc * b / 16 : sc * b / 16;
                        if (a == 0 && b == 0) continue;
                        geom_sample g; geom_eval_dual(&s, uu, vv, &g);
                        double L = v3_length(g.Ng); if (!(L > 0)) continue;
                        vec3 N = v3_scale(g.Ng, 1 / L); samples++;
                        for (int q = 0; q < 3; q++) { double c = v3_comp(N, q); double out = fmax(Nn[q].lo - c, c - Nn[q].hi); if (out > 0) { viol++; if (out > worst) { worst = out; printf("    worst now %.3g: f%d corner %d level %d depth +%d (a,b)=(%d,%d) comp %d\n", out, f, k, j, 3 * d, a, b, q); } } }
                    }
                }
                if (j % 7 == 1 && f == 0) printf("  %s level %d box width %.3g\n", name, j, width);
            }
        }
    }
    printf("%s: %ld boxes, %ld samples, %ld violations (worst %.3g)\n", name, boxes, samples, viol, worst);
}
int main(int argc, char **argv)
{
    if (argc > 1) HALVE = atof(argv[1]);
    if (argc > 2) LIMIT = atoi(argv[2]);
    char why[200];
    static const double P[] = { -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1.2, -1, 1.1, 1.1, 0.8, 1.3, -1, 1, 0.9 };
    static const int NV[] = { 4, 4, 4, 4, 4, 4 };
    static const int V[] = { 0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7 };
    geom_subdiv_desc d = { 6, NV, V, 8, P, 0, NULL, NULL, NULL, 0, NULL, NULL, 0, NULL, false };
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    check("bent cube, valence 3 (corner 0)", sd, 0);
    check("bent cube, valence 3 (corner 6)", sd, 6);
    geom_subdiv_destroy(&sd);
    int vals[] = { 5, 6, 8 };
    for (int q = 0; q < 3; q++) {
        int n = vals[q]; double fp[3 * 17]; int fv[32], fnv[8];
        fp[0] = 0.1, fp[1] = -0.05, fp[2] = 0.3;
        for (int i = 0; i < n; i++) {
            double a = 2 * M_PI * i / n, b = 2 * M_PI * (i + 0.5) / n;
            double *E = fp + 3 * (1 + 2 * i), *F = fp + 3 * (2 + 2 * i);
            E[0] = cos(a), E[1] = sin(a), E[2] = 0.2 * sin(3 * a);
            F[0] = 1.5 * cos(b), F[1] = 1.5 * sin(b), F[2] = -0.3 + 0.1 * i;
            fv[4 * i] = 0, fv[4 * i + 1] = 1 + 2 * i, fv[4 * i + 2] = 2 + 2 * i, fv[4 * i + 3] = 1 + 2 * ((i + 1) % n);
            fnv[i] = 4;
        }
        geom_subdiv_desc fd = { n, fnv, fv, 2 * n + 1, fp, 0, NULL, NULL, NULL, 0, NULL, NULL, 0, NULL, true };
        sd = geom_subdiv_new(&fd, why, sizeof why);
        char nm[32]; snprintf(nm, sizeof nm, "fan %d", n);
        check(nm, sd, 0);
        geom_subdiv_destroy(&sd);
    }
}

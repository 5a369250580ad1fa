/*
 * converge.c: the convergence test of a displaced surface (see converge.h).
 */
#include "trace/converge.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "trace/displace.h"
#include "util/err.h"

enum { PROBES = 16, COARSE = 14, FINE = 20 };

static void cell_box(trace_thread *th, const trace_object *obj, double u, double v,
                     int level, trace_box *out)
{
    double w = ldexp(1.0, -level);
    double u0 = fmin(floor(u / w) * w, 1.0 - w), v0 = fmin(floor(v / w) * w, 1.0 - w);
    trace_surface_box(th, obj, u0, u0 + w, v0, v0 + w, out);
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

bool trace_surface_converges(trace_thread *th, const trace_object *obj, char *err,
                             size_t errsz)
{
    double ratio[PROBES];
    int n = 0, probes = 0;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            /* off the lines a shader likes (s = 0.5, t = 0.25): an irrational shift */
            double u = (i + 0.5 + 0.0731) / 4.0, v = (j + 0.5 + 0.0417) / 4.0;
            if (!geom_uv_inside(&obj->surf, u, v)) continue;
            probes++;
            trace_box coarse, fine;
            cell_box(th, obj, u, v, COARSE, &coarse);
            cell_box(th, obj, u, v, FINE, &fine);
            if (th->failed) return true;     /* a shader error: reported as such */
            if ((fine.flags & AA_UNBOUNDED) || trace_box_is_empty(&fine)) continue;
            double ec = trace_box_extent(&coarse), ef = trace_box_extent(&fine);
            ratio[n++] = (coarse.flags & AA_UNBOUNDED) ? 0.0 : ec > 0 ? ef / ec : 0.0;
        }
    const char *shader = obj->displacement
        ? sl_program_name(sl_instance_program(obj->displacement)) : "(none)";
    if (probes > 0 && n == 0) {
        err_set(err, errsz, "%s: displacement shader '%s' gives no finite surface: its "
                 "bounds are infinite at every (u,v) sampled; it computes NaN or infinity "
                 "(0/0, a division by zero, sqrt or log of a negative number, an overflow)",
                 obj->name, shader);
        return false;
    }
    if (n == 0) return true;
    qsort(ratio, (size_t)n, sizeof ratio[0], compare_doubles);
    double median = ratio[n / 2];
    if (median > 0.5) {
        err_set(err, errsz, "%s: displacement shader '%s' does not converge: its bounds "
                 "over (u,v) cells of 2^-%d are %.0f%% as wide as over cells of 2^-%d (a "
                 "continuous surface: about 2%%), so no ray can resolve it; is a parameter "
                 "extreme (a frequency of 1e308?) or the result NaN or infinite?",
                 obj->name, shader, FINE, 100.0 * median, COARSE);
        return false;
    }
    return true;
}

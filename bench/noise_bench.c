/*
 * bench/noise_bench.c: benchmark of the shading language's noise
 * (common/sl/noise.h: Perlin's improved noise, Perlin 2002, in float,
 * interval and affine modes). Prints tables, never asserts.
 *
 * Table 1, "float": evaluations per second of sl_noise for 1-4D, and of
 * sl_noise_grad, sl_vnoise and sl_cellnoise in 3D, at random points.
 *
 * Table 2, "boxes": for cubes of side w = 1e-4 .. 2 at random positions,
 * 3D noise in interval mode (sl_noise_ia) and affine mode (sl_noise_aa
 * with three aa_input inputs; the timing includes the three aa_input calls
 * and a context reset, ~20 ns): evaluations per second, mean width of the
 * interval result, of the affine result's range, and of the true range
 * estimated by sampling each box (corners and 200 random points, so a
 * slight underestimate), and how often the affine result was the
 * linearisation (rather than the interval on a new symbol).
 *
 * Table 3: the same mean widths for 1D, 2D and 4D at a few sides.
 *
 * Table 4, "box methods": 3D cubes of side w bounded by the Taylor model
 * at the centre alone, by the interval jets over the cell pieces alone,
 * and by the default rule (sl_noise_set_box_method): affine evaluations
 * per second, mean widths of the affine range and of the gradient bounds
 * (sl_noise_gradient_ia, the proofs' slopes; mean over the components).
 *
 * Usage: noise_bench [--quick]
 * Timing uses clock_gettime(CLOCK_MONOTONIC); results go to a volatile sink.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "sl/noise.h"

static volatile double g_sink;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static uint64_t rng_state = 0x0123456789abcdefu;

static double urand(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1p-53;
}

/* ---- table 1 ---- */

static void table_float(long n)
{
    static double pts[4096][4];
    for (int i = 0; i < 4096; i++)
        for (int k = 0; k < 4; k++)
            pts[i][k] = 200.0 * urand() - 100.0;
    printf("\nfloat mode, %ld evaluations each\n", n);
    printf("%-22s %14s %10s\n", "function", "evals/s", "ns/eval");
    for (int what = 0; what < 7; what++) {
        const char *name;
        double t0 = now_s(), acc = 0.0;
        for (long i = 0; i < n; i++) {
            const double *p = pts[i & 4095];
            double g[4], v3[3];
            switch (what) {
            case 0: acc += sl_noise(1, p); break;
            case 1: acc += sl_noise(2, p); break;
            case 2: acc += sl_noise(3, p); break;
            case 3: acc += sl_noise(4, p); break;
            case 4: acc += sl_noise_grad(3, p, NULL, g) + g[0]; break;
            case 5: sl_vnoise(3, p, v3); acc += v3[0] + v3[2]; break;
            default: acc += sl_cellnoise(3, p); break;
            }
        }
        double dt = now_s() - t0;
        g_sink = acc;
        static const char *const names[7] = {
            "noise 1D", "noise 2D", "noise 3D", "noise 4D", "noise_grad 3D",
            "vnoise 3D (3 values)", "cellnoise 3D",
        };
        name = names[what];
        printf("%-22s %14.3g %10.1f\n", name, (double)n / dt, 1e9 * dt / (double)n);
    }
}

/* ---- tables 2 and 3 ---- */

typedef struct box_stats {
    double ia_rate, aa_rate;
    double w_ia, w_aa, w_true;
    double linear;       /* fraction of affine results that are linear */
} box_stats;

static void run_boxes(int dim, double side, int nboxes, int timing_reps,
                      box_stats *st)
{
    static double lo[2048][4];
    if (nboxes > 2048)
        nboxes = 2048;
    for (int i = 0; i < nboxes; i++)
        for (int k = 0; k < dim; k++)
            lo[i][k] = 200.0 * urand() - 100.0;

    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    ia_interval P[4];
    aa_form in[4], out;

    /* widths */
    double wia = 0.0, waa = 0.0, wtrue = 0.0;
    int lin = 0;
    for (int i = 0; i < nboxes; i++) {
        aa_context_reset(&ctx);
        for (int k = 0; k < dim; k++) {
            P[k] = ia_make(lo[i][k], lo[i][k] + side);
            aa_input(&ctx, &in[k], lo[i][k], lo[i][k] + side);
        }
        ia_interval r = sl_noise_ia(dim, P);
        sl_noise_aa(&ctx, &out, dim, in);
        ia_interval ra = aa_range(&out);
        wia += r.hi - r.lo;
        waa += ra.hi - ra.lo;
        if (out.n > 0 && out.c[0] != 0.0)
            lin++;
        double vmin = 1.0, vmax = 0.0;
        for (int s = 0; s < (1 << dim) + 200; s++) {
            double x[4];
            for (int k = 0; k < dim; k++)
                x[k] = s < (1 << dim) ? lo[i][k] + (((s >> k) & 1) ? side : 0.0)
                                      : lo[i][k] + side * urand();
            double v = sl_noise(dim, x);
            vmin = v < vmin ? v : vmin;
            vmax = v > vmax ? v : vmax;
        }
        wtrue += vmax - vmin;
    }
    st->w_ia = wia / nboxes;
    st->w_aa = waa / nboxes;
    st->w_true = wtrue / nboxes;
    st->linear = (double)lin / nboxes;
    if (timing_reps <= 0)
        return;

    /* timing */
    double acc = 0.0;
    double t0 = now_s();
    for (int rep = 0; rep < timing_reps; rep++)
        for (int i = 0; i < nboxes; i++) {
            for (int k = 0; k < dim; k++)
                P[k] = ia_make(lo[i][k], lo[i][k] + side);
            acc += sl_noise_ia(dim, P).hi;
        }
    double t_ia = now_s() - t0;
    t0 = now_s();
    for (int rep = 0; rep < timing_reps; rep++)
        for (int i = 0; i < nboxes; i++) {
            aa_context_reset(&ctx);
            for (int k = 0; k < dim; k++)
                aa_input(&ctx, &in[k], lo[i][k], lo[i][k] + side);
            sl_noise_aa(&ctx, &out, dim, in);
            acc += out.x0;
        }
    double t_aa = now_s() - t0;
    g_sink = acc;
    double n = (double)nboxes * timing_reps;
    st->ia_rate = n / t_ia;
    st->aa_rate = n / t_aa;
}

static const double sides[] = { 1e-4, 1e-3, 1e-2, 0.05, 0.1, 0.3, 1.0, 2.0 };
enum { NSIDES = sizeof sides / sizeof sides[0] };

static void table_boxes(int nboxes, int reps)
{
    printf("\n3D noise over cubes of side w, %d boxes per side\n", nboxes);
    printf("%-8s %12s %12s %10s %10s %10s %9s %9s %8s\n", "w", "IA evals/s",
           "AA evals/s", "IA width", "AA width", "true", "AA/IA", "AA/true",
           "linear");
    for (int i = 0; i < NSIDES; i++) {
        box_stats st;
        run_boxes(3, sides[i], nboxes, reps, &st);
        printf("%-8g %12.3g %12.3g %10.4g %10.4g %10.4g %9.3f %9.3f %7.0f%%\n",
               sides[i], st.ia_rate, st.aa_rate, st.w_ia, st.w_aa, st.w_true,
               st.w_aa / st.w_ia, st.w_aa / st.w_true, 100.0 * st.linear);
    }
}

static void table_dims(int nboxes, int reps)
{
    static const double s3[] = { 1e-3, 0.05, 0.3 };
    printf("\nmean widths (IA / AA / true) and evals/s (IA, AA) by dimension\n");
    printf("%-4s %-7s %10s %10s %10s %12s %12s\n", "dim", "w", "IA width",
           "AA width", "true", "IA evals/s", "AA evals/s");
    for (int dim = 1; dim <= 4; dim++)
        for (int i = 0; i < 3; i++) {
            box_stats st;
            run_boxes(dim, s3[i], nboxes, reps, &st);
            printf("%-4d %-7g %10.4g %10.4g %10.4g %12.3g %12.3g\n", dim, s3[i],
                   st.w_ia, st.w_aa, st.w_true, st.ia_rate, st.aa_rate);
        }
}

static void table_methods(int nboxes, int reps)
{
    static const double sw[] = { 1e-3, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2 };
    static const char *const mname[3] = { "auto", "jets", "taylor" };
    printf("\n3D noise over cubes of side w by box method, %d boxes per side\n", nboxes);
    printf("%-6s %-7s %12s %12s %12s %12s\n", "w", "method", "AA evals/s",
           "AA width", "IA width", "grad width");
    for (unsigned i = 0; i < sizeof sw / sizeof sw[0]; i++) {
        uint64_t start = rng_state;     /* the same boxes for each method */
        for (int m = 0; m < 3; m++) {
            sl_noise_set_box_method(m);
            box_stats st;
            rng_state = start;
            run_boxes(3, sw[i], nboxes, reps, &st);
            /* the gradient bounds (other boxes, the same for each method) */
            double gw = 0.0;
            for (int b = 0; b < nboxes; b++) {
                ia_interval P[3], v, g[3];
                for (int k = 0; k < 3; k++) {
                    double lo = 200.0 * urand() - 100.0;
                    P[k] = ia_make(lo, lo + sw[i]);
                }
                if (sl_noise_gradient_ia(3, P, NULL, -1, &v, g))
                    gw += (g[0].hi - g[0].lo + g[1].hi - g[1].lo + g[2].hi - g[2].lo) / 3.0;
            }
            printf("%-6g %-7s %12.3g %12.4g %12.4g %12.4g\n", sw[i], mname[m],
                   st.aa_rate, st.w_aa, st.w_ia, gw / nboxes);
        }
    }
    sl_noise_set_box_method(SL_NOISE_BOX_AUTO);
}

int main(int argc, char **argv)
{
    int quick = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else {
            fprintf(stderr, "usage: %s [--quick]\n", argv[0]);
            return 2;
        }
    }
    printf("noise_bench%s: Perlin improved noise (common/sl/noise.h)\n",
           quick ? " --quick" : "");
    table_float(quick ? 200000 : 4000000);
    table_boxes(quick ? 300 : 2000, quick ? 1 : 10);
    table_dims(quick ? 200 : 1000, quick ? 1 : 5);
    table_methods(quick ? 200 : 1000, quick ? 1 : 5);
    return 0;
}

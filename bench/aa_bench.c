/*
 * bench/aa_bench.c: benchmark of common/aa. Prints tables, never asserts.
 *
 * Table 1, "ns per operation": the main operations in affine mode, with
 * operands that carry the 2 input symbols (u, v) plus 0, 4 or 8 other
 * symbols, and in interval mode. Each timed call starts from a copy of the
 * same context, so that every affine operation takes the same path (a fresh
 * symbol for its error, as in a query with capacity left).
 *
 * Table 3 (printed second), "dense": the dense fixed-width forms of
 * dense.h against aa_form, ns per add, sub, lincomb, mul and range on the
 * same operands (u, v and their error symbols). A second aa_form column,
 * "varied", takes its operands from 256 sets in a fixed random order (the
 * other columns cycle through 8): whether a sum was rounded, and which
 * way, then varies as in a renderer, and a branch on it is mispredicted
 * as it is there (the 256 sets live in L2, not L1).
 *
 * Table 2, "full vs reduced": shader-like expressions over (u, v) squares of
 * side 1, 1/4, 1/16 and 1/64 tiling [0,1]^2, evaluated with context
 * capacities 2 (fully reduced: only u and v are symbols, every new error is
 * folded into the private term), 4, 8, 16 and 32, and in interval mode as
 * the peer. For each it prints the mean range width relative to capacity 32
 * and the ns per evaluation of the whole expression. The absolute mean width
 * at capacity 32 is printed as well.
 *
 *   wave      r = sqrt((u-.5)^2 + (v-.5)^2); 0.1*sin(20r)*exp(-3r)
 *             (the wave displacement of Heidrich & Seidel 1998)
 *   ufo       d as r; 0.3*pow(1 - smoothstep(.05,.45,d), 2.5)
 *             + 0.05*(1 - smoothstep(.42,.48,d)): a noise-free saucer profile
 *   poly      u^3 - 2u^2v + v^2/2 - uv
 *   sincos    sin(10u)*cos(10v)
 *
 * Usage: aa_bench [--quick]   (--quick: few iterations, for `make demo`)
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
#include "aa/dense.h"
#include "aa/interval.h"

static volatile double g_sink;

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* ======================================================================
 * Table 1: ns per operation
 * ====================================================================== */

enum { B_ADD, B_MUL, B_DIV, B_SQR, B_SQRT, B_EXP, B_LOG, B_SIN, B_COS, B_POW,
       B_FLOOR, B_STEP, B_SMOOTHSTEP, B_ABS, B_MIN, B_COUNT };

static const char *const BENCH_NAMES[B_COUNT] = {
    "add", "mul", "div", "sqr", "sqrt", "exp", "log", "sin", "cos", "pow",
    "floor", "step", "smoothstep", "abs", "min",
};

#define NSETS 8          /* operand sets cycled through, to vary the data */

typedef struct aa_operands {
    aa_context ctx;      /* the context after the operands were built */
    aa_form x, y, e0, e1;
} aa_operands;

/* x in about [0.05, 0.95] and y in about [0.3, 1.3], both over u, v and
 * `extra` other symbols; e0, e1 constant edges for smoothstep. */
static void build_aa_operands(aa_operands *o, int extra, int set)
{
    aa_form u, v, w;
    double sh = 0.01 * set;
    aa_context_init(&o->ctx, AA_MAX_SYMBOLS);
    aa_input(&o->ctx, &u, 0.25 + sh, 0.5 + sh);
    aa_input(&o->ctx, &v, 0.5 - sh, 0.75 - sh);
    aa_lincomb(&o->ctx, &o->x, 0.8, &u, 0.6, &v, -0.05);
    aa_lincomb(&o->ctx, &o->y, -0.5, &u, 1.2, &v, 0.2);
    for (int k = 0; k < extra; k++) {
        aa_input(&o->ctx, &w, -0.01, 0.01);
        aa_lincomb(&o->ctx, &o->x, 1.0, &o->x, 1.0 + 0.1 * k, &w, 0.0);
        aa_lincomb(&o->ctx, &o->y, 1.0, &o->y, -0.5 - 0.1 * k, &w, 0.0);
    }
    aa_const(&o->e0, 0.3);
    aa_const(&o->e1, 0.7);
}

static void run_aa_op(int op, aa_context *c, aa_form *z, const aa_operands *o)
{
    switch (op) {
    case B_ADD:        aa_add(c, z, &o->x, &o->y); break;
    case B_MUL:        aa_mul(c, z, &o->x, &o->y); break;
    case B_DIV:        aa_div(c, z, &o->x, &o->y); break;
    case B_SQR:        aa_sqr(c, z, &o->x); break;
    case B_SQRT:       aa_sqrt(c, z, &o->x); break;
    case B_EXP:        aa_exp(c, z, &o->x); break;
    case B_LOG:        aa_log(c, z, &o->x); break;
    case B_SIN:        aa_sin(c, z, &o->x); break;
    case B_COS:        aa_cos(c, z, &o->x); break;
    case B_POW:        aa_pow(c, z, &o->x, &o->y); break;
    case B_FLOOR:      aa_floor(c, z, &o->y); break;
    case B_STEP:       aa_step(c, z, &o->e1, &o->x); break;
    case B_SMOOTHSTEP: aa_smoothstep(c, z, &o->e0, &o->e1, &o->x); break;
    case B_ABS:        aa_abs(c, z, &o->x); break;
    default:           aa_min(c, z, &o->x, &o->y); break;
    }
}

static ia_interval run_ia_op(int op, ia_interval x, ia_interval y)
{
    switch (op) {
    case B_ADD:        return ia_add(x, y);
    case B_MUL:        return ia_mul(x, y);
    case B_DIV:        return ia_div(x, y);
    case B_SQR:        return ia_sqr(x);
    case B_SQRT:       return ia_sqrt(x);
    case B_EXP:        return ia_exp(x);
    case B_LOG:        return ia_log(x);
    case B_SIN:        return ia_sin(x);
    case B_COS:        return ia_cos(x);
    case B_POW:        return ia_pow(x, y);
    case B_FLOOR:      return ia_floor(y);
    case B_STEP:       return ia_step(ia_point(0.7), x);
    case B_SMOOTHSTEP: return ia_smoothstep(ia_point(0.3), ia_point(0.7), x);
    case B_ABS:        return ia_abs(x);
    default:           return ia_min(x, y);
    }
}

static double time_aa_op(int op, const aa_operands *sets, long iters)
{
    aa_form z;
    double sum = 0.0;
    double t0 = now_ns();
    for (long i = 0; i < iters; i++) {
        const aa_operands *o = &sets[i & (NSETS - 1)];
        aa_context c = o->ctx;
        run_aa_op(op, &c, &z, o);
        sum += z.x0;
    }
    double t1 = now_ns();
    g_sink = sum;
    return (t1 - t0) / (double)iters;
}

static double time_ia_op(int op, const ia_interval *xs, const ia_interval *ys, long iters)
{
    double sum = 0.0;
    double t0 = now_ns();
    for (long i = 0; i < iters; i++) {
        ia_interval z = run_ia_op(op, xs[i & (NSETS - 1)], ys[i & (NSETS - 1)]);
        sum += z.hi;
    }
    double t1 = now_ns();
    g_sink = sum;
    return (t1 - t0) / (double)iters;
}

static void table_ops(long iters)
{
    static const int extras[3] = {0, 4, 8};
    static aa_operands sets[3][NSETS];
    ia_interval xs[NSETS], ys[NSETS];
    for (int e = 0; e < 3; e++)
        for (int s = 0; s < NSETS; s++)
            build_aa_operands(&sets[e][s], extras[e], s);
    for (int s = 0; s < NSETS; s++) {
        xs[s] = aa_range(&sets[0][s].x);
        ys[s] = aa_range(&sets[0][s].y);
    }

    printf("ns per operation (%ld iterations each; affine operands carry u, v and k other "
           "symbols)\n", iters);
    printf("%-12s %10s %10s %10s %10s\n", "operation", "affine+0", "affine+4", "affine+8",
           "interval");
    for (int op = 0; op < B_COUNT; op++) {
        double t[4];
        for (int e = 0; e < 3; e++) {
            time_aa_op(op, sets[e], iters / 10 + 1);          /* warm up */
            t[e] = time_aa_op(op, sets[e], iters);
        }
        time_ia_op(op, xs, ys, iters / 10 + 1);
        t[3] = time_ia_op(op, xs, ys, iters);
        printf("%-12s %10.1f %10.1f %10.1f %10.1f\n", BENCH_NAMES[op], t[0], t[1], t[2], t[3]);
    }
    printf("\n");
}

/* ======================================================================
 * Table 2: full vs reduced affine forms on shader-like expressions
 * ====================================================================== */

enum { E_WAVE, E_UFO, E_POLY, E_SINCOS, E_COUNT };
static const char *const EXPR_NAMES[E_COUNT] = {"wave", "ufo", "poly", "sincos"};

static void radius_aa(aa_context *c, aa_form *r, const aa_form *u, const aa_form *v)
{
    aa_form a, b;
    aa_add_s(c, &a, u, -0.5);
    aa_sqr(c, &a, &a);
    aa_add_s(c, &b, v, -0.5);
    aa_sqr(c, &b, &b);
    aa_add(c, r, &a, &b);
    aa_sqrt(c, r, r);
}

static ia_interval radius_ia(ia_interval u, ia_interval v)
{
    ia_interval a = ia_sqr(ia_add_s(u, -0.5)), b = ia_sqr(ia_add_s(v, -0.5));
    return ia_sqrt(ia_add(a, b));
}

static void expr_aa(int e, aa_context *c, aa_form *h, const aa_form *u, const aa_form *v)
{
    aa_form r, s, t, w, k0, k1;
    switch (e) {
    case E_WAVE:
        radius_aa(c, &r, u, v);
        aa_mul_s(c, &t, &r, 20.0);
        aa_sin(c, &s, &t);
        aa_mul_s(c, &t, &r, -3.0);
        aa_exp(c, &w, &t);
        aa_mul(c, h, &s, &w);
        aa_mul_s(c, h, h, 0.1);
        break;
    case E_UFO:
        radius_aa(c, &r, u, v);
        aa_const(&k0, 0.05);
        aa_const(&k1, 0.45);
        aa_smoothstep(c, &s, &k0, &k1, &r);
        aa_lincomb(c, &s, -1.0, &s, 0.0, &s, 1.0);          /* 1 - s */
        aa_const(&k0, 2.5);
        aa_pow(c, &t, &s, &k0);                             /* dome */
        aa_const(&k0, 0.42);
        aa_const(&k1, 0.48);
        aa_smoothstep(c, &w, &k0, &k1, &r);                 /* rim edge */
        aa_lincomb(c, h, 0.3, &t, -0.05, &w, 0.05);
        break;
    case E_POLY:
        aa_sqr(c, &s, u);                                   /* u^2 */
        aa_mul(c, &t, &s, u);                               /* u^3 */
        aa_mul(c, &w, &s, v);                               /* u^2 v */
        aa_lincomb(c, h, 1.0, &t, -2.0, &w, 0.0);
        aa_sqr(c, &s, v);
        aa_mul(c, &t, u, v);
        aa_lincomb(c, &w, 0.5, &s, -1.0, &t, 0.0);
        aa_add(c, h, h, &w);
        break;
    default:
        aa_mul_s(c, &t, u, 10.0);
        aa_sin(c, &s, &t);
        aa_mul_s(c, &t, v, 10.0);
        aa_cos(c, &w, &t);
        aa_mul(c, h, &s, &w);
        break;
    }
}

static ia_interval expr_ia(int e, ia_interval u, ia_interval v)
{
    ia_interval r, s, t, w;
    switch (e) {
    case E_WAVE:
        r = radius_ia(u, v);
        s = ia_sin(ia_mul_s(r, 20.0));
        w = ia_exp(ia_mul_s(r, -3.0));
        return ia_mul_s(ia_mul(s, w), 0.1);
    case E_UFO:
        r = radius_ia(u, v);
        s = ia_add_s(ia_neg(ia_smoothstep(ia_point(0.05), ia_point(0.45), r)), 1.0);
        t = ia_pow(s, ia_point(2.5));
        w = ia_smoothstep(ia_point(0.42), ia_point(0.48), r);
        return ia_add(ia_mul_s(t, 0.3), ia_add_s(ia_mul_s(w, -0.05), 0.05));
    case E_POLY:
        s = ia_sqr(u);
        t = ia_sub(ia_mul(s, u), ia_mul_s(ia_mul(s, v), 2.0));
        w = ia_sub(ia_mul_s(ia_sqr(v), 0.5), ia_mul(u, v));
        return ia_add(t, w);
    default:
        return ia_mul(ia_sin(ia_mul_s(u, 10.0)), ia_cos(ia_mul_s(v, 10.0)));
    }
}

#define MAX_TILES 256

typedef struct tiles {
    int n;
    double u0[MAX_TILES], v0[MAX_TILES], side;
} tiles;

/* Squares of the given side tiling [0,1]^2: all of them, or MAX_TILES of
 * them spread evenly (deterministic) where there are more. */
static void make_tiles(tiles *t, int per_side)
{
    int total = per_side * per_side;
    t->side = 1.0 / per_side;
    t->n = total < MAX_TILES ? total : MAX_TILES;
    for (int i = 0; i < t->n; i++) {
        long k = (long)i * total / t->n;
        t->u0[i] = (double)(k % per_side) * t->side;
        t->v0[i] = (double)(k / per_side) * t->side;
    }
}

/* Mean width and ns per evaluation of expression e over the tiles;
 * capacity 0 means interval mode. */
static void measure_expr(int e, const tiles *t, int capacity, long reps, double *mean_width,
                         double *ns)
{
    double wsum = 0.0, sink = 0.0;
    for (int i = 0; i < t->n; i++) {
        double u0 = t->u0[i], v0 = t->v0[i], u1 = u0 + t->side, v1 = v0 + t->side;
        ia_interval r;
        if (capacity == 0) {
            r = expr_ia(e, ia_make(u0, u1), ia_make(v0, v1));
        } else {
            aa_context c;
            aa_form u, v, h;
            aa_context_init(&c, capacity);
            aa_input(&c, &u, u0, u1);
            aa_input(&c, &v, v0, v1);
            expr_aa(e, &c, &h, &u, &v);
            r = aa_range(&h);
        }
        wsum += r.hi - r.lo;
    }
    *mean_width = wsum / t->n;

    double t0 = now_ns();
    for (long k = 0; k < reps; k++) {
        for (int i = 0; i < t->n; i++) {
            double u0 = t->u0[i], v0 = t->v0[i], u1 = u0 + t->side, v1 = v0 + t->side;
            if (capacity == 0) {
                ia_interval r = expr_ia(e, ia_make(u0, u1), ia_make(v0, v1));
                sink += r.hi;
            } else {
                aa_context c;
                aa_form u, v, h;
                aa_context_init(&c, capacity);
                aa_input(&c, &u, u0, u1);
                aa_input(&c, &v, v0, v1);
                expr_aa(e, &c, &h, &u, &v);
                sink += h.x0;
            }
        }
    }
    double t1 = now_ns();
    g_sink = sink;
    *ns = (t1 - t0) / ((double)reps * t->n);
}

static void table_full_vs_reduced(long evals)
{
    static const int caps[5] = {2, 4, 8, 16, 32};
    static const int sides[4] = {1, 4, 16, 64};
    printf("full vs reduced: mean range width relative to capacity 32, (ns per evaluation)\n");
    printf("capacity 2 = fully reduced (u, v only); interval = ia_* peer; "
           "~%ld evaluations per cell\n", evals);
    printf("%-7s %-5s %12s %15s %15s %15s %15s %15s %15s\n", "expr", "size", "width@32",
           "cap 2", "cap 4", "cap 8", "cap 16", "cap 32", "interval");
    for (int e = 0; e < E_COUNT; e++) {
        for (int s = 0; s < 4; s++) {
            tiles t;
            make_tiles(&t, sides[s]);
            long reps = evals / t.n + 1;
            double w[6], ns[6];
            for (int k = 0; k < 5; k++)
                measure_expr(e, &t, caps[k], reps, &w[k], &ns[k]);
            measure_expr(e, &t, 0, reps, &w[5], &ns[5]);
            char size[16];
            snprintf(size, sizeof size, "1/%d", sides[s]);
            printf("%-7s %-5s %12.4g", EXPR_NAMES[e], sides[s] == 1 ? "1" : size, w[4]);
            for (int k = 0; k < 6; k++) {
                char cell[32];
                if (w[4] > 0 && isfinite(w[k]))
                    snprintf(cell, sizeof cell, "%.3f (%.0f)", w[k] / w[4], ns[k]);
                else
                    snprintf(cell, sizeof cell, "%.3g (%.0f)", w[k], ns[k]);
                printf(" %15s", cell);
            }
            printf("\n");
        }
    }
    printf("\n");
}

/* Table 3: the dense fixed-width forms (dense.h) against aa_form on the
 * same operands (u, v and the error symbols of building them: n <= 4) */
enum { D_ADD, D_SUB, D_LINCOMB, D_MUL, D_RANGE, D_COUNT };
static const char *const DENSE_NAMES[D_COUNT] = {"add", "sub", "lincomb", "mul", "range"};

#define VARIED_SETS 256
#define VARIED_ORDER 4096

/* order: NULL to cycle through NSETS sets, else VARIED_ORDER indices */
static double time_dense_op(int op, bool dense, const aa_operands *sets,
                            const unsigned char *order, long iters)
{
    aa_dense dx[NSETS], dy[NSETS], dz;
    for (int k = 0; k < NSETS; k++) {
        aa_dense_from_form(&dx[k], &sets[k].x);
        aa_dense_from_form(&dy[k], &sets[k].y);
    }
    aa_form z;
    double sum = 0.0;
    double t0 = now_ns();
    for (long i = 0; i < iters; i++) {
        int k = order ? order[i & (VARIED_ORDER - 1)] : (int)(i & (NSETS - 1));
        const aa_operands *o = &sets[k];
        aa_context c = o->ctx;
        if (dense) {
            switch (op) {
            case D_ADD: aa_dense_add(&dz, &dx[k], &dy[k]); break;
            case D_SUB: aa_dense_sub(&dz, &dx[k], &dy[k]); break;
            case D_LINCOMB: aa_dense_lincomb(&dz, 0.8, &dx[k], 0.6, &dy[k], 0.1); break;
            case D_MUL: aa_dense_mul(&c, &dz, &dx[k], &dy[k]); break;
            default: dz.x0 = aa_dense_range(&dx[k]).hi; break;
            }
            sum += dz.x0;
        } else {
            switch (op) {
            case D_ADD: aa_add(&c, &z, &o->x, &o->y); break;
            case D_SUB: aa_sub(&c, &z, &o->x, &o->y); break;
            case D_LINCOMB: aa_lincomb(&c, &z, 0.8, &o->x, 0.6, &o->y, 0.1); break;
            case D_MUL: aa_mul(&c, &z, &o->x, &o->y); break;
            default: z.x0 = aa_range(&o->x).hi; break;
            }
            sum += z.x0;
        }
    }
    double t1 = now_ns();
    g_sink = sum;
    return (t1 - t0) / (double)iters;
}

static void table_dense(long iters)
{
    static aa_operands sets[NSETS], varied[VARIED_SETS];
    static unsigned char order[VARIED_ORDER];
    for (int k = 0; k < NSETS; k++)
        build_aa_operands(&sets[k], 0, k);
    for (int k = 0; k < VARIED_SETS; k++)          /* u, v shifted by 0.01 k */
        build_aa_operands(&varied[k], 0, k);
    uint64_t r = 0x9e3779b97f4a7c15ull;            /* a fixed random order */
    for (int i = 0; i < VARIED_ORDER; i++) {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        order[i] = (unsigned char)(r >> 56);
    }
    printf("dense fixed-width forms (dense.h, %d symbols + err, no hull) against aa_form,\n"
           "ns per operation on the same operands (%ld iterations each; varied: aa_form on\n"
           "%d operand sets in a random order)\n", AA_DENSE_W, iters, VARIED_SETS);
    printf("%-12s %10s %10s %10s %8s\n", "operation", "aa_form", "varied", "dense", "ratio");
    for (int op = 0; op < D_COUNT; op++) {
        double f = time_dense_op(op, false, sets, NULL, iters);
        double v = time_dense_op(op, false, varied, order, iters);
        double d = time_dense_op(op, true, sets, NULL, iters);
        printf("%-12s %10.1f %10.1f %10.1f %7.1fx\n", DENSE_NAMES[op], f, v, d, f / d);
    }
    printf("\n");
}

int main(int argc, char **argv)
{
    int quick = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else {
            fprintf(stderr, "usage: %s [--quick]\n", argv[0]);
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    double t0 = now_ns();
    printf("aa_bench%s: common/aa, AA_MAX_SYMBOLS %d, AA_DEFAULT_CAPACITY %d\n\n",
           quick ? " --quick" : "", AA_MAX_SYMBOLS, AA_DEFAULT_CAPACITY);
    table_ops(quick ? 20000 : 100000);
    table_dense(quick ? 200000 : 2000000);
    table_full_vs_reduced(quick ? 300 : 1500);
    printf("total %.2f s\n", (now_ns() - t0) * 1e-9);
    return 0;
}

/*
 * tests/sl/test_sl_conformance.c: the conformance suite of the shading
 * language (issue 15), the shaders in tests/shaders/conformance, each
 * exercising one feature in the idioms of the books and of the widely
 * copied helper headers (patterns.h, noises.h, voronoi.h, filterwidth.h,
 * written for this suite).
 *
 * Every shader is a displacement shader on the plane P = (2u-1, 2v-1, 0),
 * N = (0, 0, 1), s = u, t = v, that sets P to three values. Per shader:
 *
 *   float      P at 7x7 points of the plane against an independent C
 *              computation of the same values (ref_* below)
 *   dual       at the same points, dual mode gives the float values, and
 *              derivatives matching central differences where those are
 *              stable
 *   range      over 12 random (u,v) boxes (sides 2^-2 .. 2^-6), the
 *              interval and the affine enclosure of P contain P in dual
 *              mode (the renderer's hit points) at 4x4 points of the box (paper §4, issue 9); the
 *              enclosures must be finite (the range modes carry
 *              derivative bounds, so filterwidth is bounded too)
 *
 * The shaders in errors/ must stay errors: their diagnostics are compared
 * whole (file:line:col, message, source line, caret).
 *
 * Prints the features covered, the cases run and the failures; fails when
 * there is any failure.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <unistd.h>
#include <cmocka.h>

#include "sl/noise.h"
#include "sl_harness.h"

#ifndef AAFARM_CONFORMANCE_DIR
#define AAFARM_CONFORMANCE_DIR "tests/shaders/conformance"
#endif

/* ---------------------------------------------------------------------- */
/* independent computations                                                */
/* ---------------------------------------------------------------------- */

static double sgn(double x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }
static double fmodf_(double a, double b) { return a - b * floor(a / b); }
static double clampd(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }
static double stepd(double e, double x) { return x < e ? 0 : 1; }
static double smooth(double e0, double e1, double x)
{
    if (x < e0)
        return 0;
    if (x >= e1)
        return 1;
    double r = (x - e0) / (e1 - e0);
    return r * r * (3 - 2 * r);
}
static double noise1(double x) { return sl_noise(1, &x); }
static double noise3(double x, double y, double z)
{
    double p[3] = { x, y, z };
    return sl_noise(3, p);
}

static void ref_shadow_global_local(double u, double v, double o[3])
{
    o[0] = u + 9 * v * v; o[1] = u; o[2] = 0;
}

static double tilecoord(double s, double t, double f)
{
    return fmodf_(s * f, 1) * fmodf_(t * f, 1);
}
static void ref_shadow_function_params(double u, double v, double o[3])
{
    o[0] = tilecoord(v, u, 3); o[1] = tilecoord(u + 0.1, v, 2); o[2] = 0;
}

static void ref_shadow_shader_param(double u, double v, double o[3])
{
    o[0] = 2 * v; o[1] = 3; o[2] = u;
}

static void ref_shadow_builtin_names(double u, double v, double o[3])
{
    o[0] = u * 0.75 + 2 * 0.25; o[1] = stepd(0.5, v); o[2] = 2;
}

static double filteredabs(double x, double dx)
{
    double x0 = x - 0.5 * dx, x1 = x0 + dx;
    return (sgn(x1) * 0.5 * x1 * x1 - sgn(x0) * 0.5 * x0 * x0) / dx;
}
static void ref_nested_filteredabs(double u, double v, double o[3])
{
    o[0] = filteredabs(u - 0.5, 0.2); o[1] = filteredabs(v - 0.3, 0.1); o[2] = 0;
}

static void ref_nested_extern_accumulate(double u, double v, double o[3])
{
    o[0] = 0.5 * u + 0.5 * v * v + 0.5; o[1] = 0; o[2] = 0;
}

static double outer(double a) { return 2 * a * (a + 1) + 1; }
static void ref_nested_two_levels(double u, double v, double o[3])
{
    o[0] = outer(u); o[1] = outer(v); o[2] = 0;
}

static void ref_nested_in_loop(double u, double v, double o[3])
{
    (void)v;
    o[0] = u + u * u / 2 + u * u * u / 3; o[1] = 0; o[2] = 0;
}

static double bias_perlin(double b, double x) { return pow(x, log(b) / log(0.5)); }
static double bias_schlick(double b, double x) { return x / ((1 / b - 2) * (1 - x) + 1); }
static void ref_nested_hides_file_level(double u, double v, double o[3])
{
    o[0] = bias_perlin(0.7, u) - bias_schlick(0.7, u); o[1] = bias_perlin(0.3, v); o[2] = 0;
}

static void ref_overload_snoise(double u, double v, double o[3])
{
    double p[3] = { 2 * u - 1, 2 * v - 1, 0 }, vn[3];
    sl_vnoise(3, p, vn);
    o[0] = 2 * noise1(u * 4) - 1;
    o[1] = 2 * noise3(3 * u, 3 * v, 0) - 1;
    o[2] = 2 * vn[1] - 1;
}

static void ref_overload_return_type(double u, double v, double o[3])
{
    double x = 2 * u - 1, y = 2 * v - 1;
    o[0] = x + y; o[1] = 2 * y; o[2] = 2 * x + 2 * y;
}

static void ref_overload_builtin(double u, double v, double o[3])
{
    o[0] = u + v + 1; o[1] = sqrt(u * u + v * v); o[2] = clampd((u - 0.2) / 0.6, 0, 1);
}

static void ref_overload_output(double u, double v, double o[3])
{
    o[0] = 1 + u; o[1] = 0.125; o[2] = 1 + v;
}

static void ref_overload_conversion_cost(double u, double v, double o[3])
{
    o[0] = 13; o[1] = u; o[2] = -v;
}

static void ref_list_assign(double u, double v, double o[3])
{
    o[0] = u; o[1] = v; o[2] = 0.5;
}

static void ref_list_param_default(double u, double v, double o[3])
{
    o[0] = 2 * u - 1 - 0.5; o[1] = 0.5; o[2] = 0.25 * v;
}

static void ref_list_return_arg(double u, double v, double o[3])
{
    o[0] = u + v + 1; o[1] = u > 0.5 ? 0 : 1; o[2] = v > 0.5 ? 1 : 0;
}

static void ref_list_operators(double u, double v, double o[3])
{
    o[0] = 1 - 2 * u; o[1] = 1 - 2 * v; o[2] = -1 + v;
    if (u > 0.5) {
        o[0] = (o[0] + 1) / 2; o[1] /= 2; o[2] /= 2;
    }
}

static void ref_list_matrix(double u, double v, double o[3])
{
    o[0] = 2 + u; o[1] = 3 + v; o[2] = 1;
}

static double filteredpulse(double e0, double e1, double x, double dx)
{
    double x0 = x - dx / 2, x1 = x0 + dx;
    double a = (fmin(x1, e1) - fmax(x0, e0)) / dx;
    return a > 0 ? a : 0;
}
static void ref_patterns_pulses(double u, double v, double o[3])
{
    o[0] = filteredpulse(0.3, 0.7, u, 0.05);
    o[1] = smooth(0.1, 0.3, v) - smooth(0.6, 0.9, v);
    o[2] = 2 * (stepd(0.3, u) - stepd(0.7, u));
}

static double fbm3(double x, double y, double z, int oct, double lac, double gain)
{
    double sum = 0, amp = 1;
    for (int i = 0; i < oct; i++) {
        sum += amp * (2 * noise3(x, y, z) - 1);
        amp *= gain;
        x *= lac; y *= lac; z *= lac;
    }
    return sum;
}
static double fbm1(double x, int oct, double lac, double gain)
{
    double sum = 0, amp = 1;
    for (int i = 0; i < oct; i++) {
        sum += amp * (2 * noise1(x) - 1);
        amp *= gain;
        x *= lac;
    }
    return sum;
}
static void ref_noises_fbm(double u, double v, double o[3])
{
    o[0] = fbm3(2 * u, 2 * v, 0, 3, 2, 0.5); o[1] = fbm1(3 * v, 3, 2.17, 0.6); o[2] = 0;
}

static void ref_noises_turbulence(double u, double v, double o[3])
{
    double sum = 0, f = 1;
    for (int i = 0; i < 3; i++) {
        sum += fabs(2 * noise3(2 * u * f, 2 * v * f, f) - 1) / f;
        f *= 2;
    }
    o[0] = 2 * u - 1; o[1] = 2 * v - 1; o[2] = sum;
}

static void ref_voronoi_cells(double u, double v, double o[3])
{
    double ss = 3 * u, tt = 3 * v, f1 = 1000, sp = 0, tp = 0;
    double sc = floor(ss) + 0.5, tc = floor(tt) + 0.5;
    for (int i = -1; i <= 1; i++) {
        for (int j = -1; j <= 1; j++) {
            double cell[2] = { sc + i, tc + j }, jit[3];
            sl_vcellnoise(2, cell, jit);
            double ps = cell[0] + 0.8 * (jit[0] - 0.5), pt = cell[1] + 0.8 * (jit[1] - 0.5);
            double d = (ps - ss) * (ps - ss) + (pt - tt) * (pt - tt);
            if (d < f1) {
                f1 = d; sp = ps; tp = pt;
            }
        }
    }
    o[0] = sqrt(f1); o[1] = sp; o[2] = tp;
}

static void ref_filterwidth_overloads(double u, double v, double o[3])
{
    (void)v;   /* float mode: no derivatives, so both widths are MINFILTWIDTH */
    o[0] = filteredpulse(0.25, 0.75, u, 1e-6 + 0.1); o[1] = 1e-6 * 1e6; o[2] = 0;
}

static void ref_scope_blocks_for(double u, double v, double o[3])
{
    (void)v;
    o[0] = 2 * u - 1 + 3 * u; o[1] = 1; o[2] = 1 + u;
}

static void ref_extern_globals_nested(double u, double v, double o[3])
{
    o[0] = 2 * u - 1; o[1] = 2 * v - 1; o[2] = 0.1 * u + 0.1 * 2 * v;
}

static void ref_array_lookup(double u, double v, double o[3])
{
    static const double h[5] = { 0, 0.1, 0.3, 0.2, 0.05 };
    o[0] = 2 * u - 1; o[1] = 2 * v - 1; o[2] = h[(int)floor(5 * v)];
}

static void ref_array_unsized_param(double u, double v, double o[3])
{
    o[0] = (1 + 2 * u + 3 * u * u) / 6; o[1] = (4 + v * v * v) / 5; o[2] = 4;
}

static void ref_array_store_loop(double u, double v, double o[3])
{
    double k = floor(4 * v);
    bool on = u > 0.25 * k;
    o[0] = on ? k : -1; o[1] = on ? k * k : -1; o[2] = on ? 1 : -1;
}

static void ref_array_nested_extern(double u, double v, double o[3])
{
    static const double oct[3] = { 1, 0.5, 0.25 };
    double k = floor(3 * v);
    o[0] = 0;
    for (int i = 0; i < 3; i++)
        o[0] += oct[i] * sin(2 * u * pow(2, i));
    o[1] = oct[(int)k] * sin(pow(2, 3 * v));   /* the index rounds down, pow does not */
    o[2] = 0;
}

static void ref_shadow_output_param(double u, double v, double o[3])
{
    o[0] = 2 * u - 1; o[1] = 2 * v - 1; o[2] = 0.2 * u + v;
}

static void ref_shadow_global_in_nested(double u, double v, double o[3])
{
    o[0] = 6 + u; o[1] = 2; o[2] = v;
}

static void ref_nested_sibling_calls(double u, double v, double o[3])
{
    o[0] = u * u * u * u; o[1] = v * v + 0.0625; o[2] = 0;
}

static void ref_nested_output_param(double u, double v, double o[3])
{
    (void)v;
    double w = floor(3 * u);
    o[0] = w; o[1] = 3 * u - w; o[2] = 0;
}

static void ref_overload_nested_local(double u, double v, double o[3])
{
    o[0] = 0.3 * u + 0.59 * v + 0.11; o[1] = v; o[2] = 0;
}

static void ref_overload_triples(double u, double v, double o[3])
{
    o[0] = 321; o[1] = u; o[2] = v;
}

static void ref_overload_return_noise(double u, double v, double o[3])
{
    double p[3] = { 2 * (2 * u - 1), 2 * (2 * v - 1), 0 }, c[3];
    sl_vnoise(3, p, c);
    o[0] = sl_noise(3, p); o[1] = c[0]; o[2] = c[2];
}

static void ref_list_nested_return(double u, double v, double o[3])
{
    o[0] = (u < 0.5) + (v < 0.5); o[1] = 0; o[2] = (u >= 0.5) + (v >= 0.5);
}

static void ref_list_builtins(double u, double v, double o[3])
{
    double x = 2 * u - 1, y = 2 * v - 1;
    o[0] = 0.6 + 0.8; o[1] = sqrt(x * x + y * y); o[2] = sqrt(u * u + v * v);
}

static void ref_array_color_ramp(double u, double v, double o[3])
{
    static const double k[5] = { 0, 0.2, 0.9, 0.4, 1 };
    double x = 4 * u, i = floor(x), f = x - i;
    int a = (int)i, b = a + 1 < 4 ? a + 1 : 4;
    o[0] = k[a] * (1 - f) + k[b] * f; o[1] = k[(int)floor(5 * v)]; o[2] = 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
static void ref_array_sort(double u, double v, double o[3])
{
    double a[4] = { u, v, 0.5, 1 - u };
    qsort(a, 4, sizeof a[0], cmp_double);
    o[0] = a[0]; o[1] = a[1]; o[2] = a[3];
}

static void ref_array_output_fill(double u, double v, double o[3])
{
    double x = u + 0.5;
    o[0] = x + x * x; o[1] = x * x * x; o[2] = pow(x, floor(4 * v));
}

static void ref_array_points(double u, double v, double o[3])
{
    double d0 = sqrt(u * u + v * v), d1 = sqrt((u - 1) * (u - 1) + v * v);
    double d2 = sqrt(u * u + (v - 1) * (v - 1));
    static const double px[3] = { 0, 1, 0 };
    o[0] = fmin(fmin(d0, d1), d2); o[1] = px[(int)floor(3 * u)]; o[2] = 0;
}

static double pulsetrain_integral(double t, double nedge)
{
    double f = t - floor(t) - nedge;
    return (1 - nedge) * floor(t) + (f > 0 ? f : 0);
}
static double filteredpulsetrain(double edge, double period, double x, double dx)
{
    double w = dx / period, x0 = x / period - w / 2, x1 = x0 + w, ne = edge / period;
    return (pulsetrain_integral(x1, ne) - pulsetrain_integral(x0, ne)) / w;
}
static void ref_nested_pulsetrain(double u, double v, double o[3])
{
    o[0] = filteredpulsetrain(0.5, 1, 4 * u, 0.03);
    o[1] = filteredpulsetrain(0.25, 0.5, 2 * v, 0.12);
    o[2] = 0;
}

static void ref_nested_early_return(double u, double v, double o[3])
{
    double c = floor(u * 8);
    o[0] = c; o[1] = c + 1; o[2] = floor(v * 8);
}

static void ref_overload_arrays(double u, double v, double o[3])
{
    o[0] = u + v + 1; o[1] = u + 2 * v; o[2] = 0;
}

static void ref_list_array_init(double u, double v, double o[3])
{
    o[0] = u; o[1] = v; o[2] = u * v;
}

static void ref_nested_break_continue(double u, double v, double o[3])
{
    (void)v;
    double n = floor(u * 10), acc = 0;
    for (int i = 1; i < n; i += 2)
        acc += i;
    o[0] = acc; o[1] = 1 + 3 + 5; o[2] = 0;
}

static void ref_shadow_overload_params(double u, double v, double o[3])
{
    o[0] = 10 * v + u; o[1] = 10 * u + v; o[2] = 10 * (2 * u - 1) + (2 * v - 1);
}

static void ref_extern_write_chain(double u, double v, double o[3])
{
    o[0] = (1 + (u > 0.5)) + (1 + (v > 0.5)) + 2; o[1] = 0; o[2] = 0;
}

static void ref_array_matrices(double u, double v, double o[3])
{
    double k = floor(2 * u) + 1;
    o[0] = k; o[1] = k * v; o[2] = k;
}

static void ref_nested_shadows_builtin(double u, double v, double o[3])
{
    o[0] = 2 * u; o[1] = noise3(u, v, 0); o[2] = 0;
}

/* spline, written from each basis' own formula (not the basis matrices
 * the compiler uses): the segment of x = clamp(t, 0, 1) * segments */
static double spline_ref(const char *basis, double t, const double *k, int n)
{
    int step = strcmp(basis, "bezier") == 0 ? 3 : strcmp(basis, "hermite") == 0 ? 2 : 1;
    int segs = (n - 4) / step + 1;
    double x = clampd(t, 0, 1) * segs;
    double seg = floor(x) < segs - 1 ? floor(x) : segs - 1, f = x - seg;
    const double *p = k + (int)seg * step;
    if (strcmp(basis, "catmull-rom") == 0)
        return p[1] + 0.5 * f * (p[2] - p[0] + f * (2 * p[0] - 5 * p[1] + 4 * p[2] - p[3] +
                                                     f * (3 * (p[1] - p[2]) + p[3] - p[0])));
    if (strcmp(basis, "bezier") == 0) {           /* de Casteljau */
        double a = p[0] + f * (p[1] - p[0]), b = p[1] + f * (p[2] - p[1]);
        double c = p[2] + f * (p[3] - p[2]);
        double ab = a + f * (b - a), bc = b + f * (c - b);
        return ab + f * (bc - ab);
    }
    if (strcmp(basis, "b-spline") == 0) {
        double g = 1 - f;
        return (g * g * g * p[0] + (3 * f * f * f - 6 * f * f + 4) * p[1] +
                (-3 * f * f * f + 3 * f * f + 3 * f + 1) * p[2] + f * f * f * p[3]) / 6;
    }
    if (strcmp(basis, "hermite") == 0)
        return (2 * f * f * f - 3 * f * f + 1) * p[0] + (f * f * f - 2 * f * f + f) * p[1] +
               (-2 * f * f * f + 3 * f * f) * p[2] + (f * f * f - f * f) * p[3];
    if (strcmp(basis, "linear") == 0)
        return p[1] + f * (p[2] - p[1]);
    return p[1];                                  /* constant */
}

/* lane k of a spline over n triples */
static double spline3(const char *basis, double t, const double (*k)[3], int n, int lane)
{
    double x[16];
    for (int i = 0; i < n; i++)
        x[i] = k[i][lane];
    return spline_ref(basis, t, x, n);
}

static void ref_spline_float(double u, double v, double o[3])
{
    static const double a[] = { 0, 0, 0.3, 0.8, 1, 1 }, b[] = { -1, 0, 1, 0.5, 2, 0.25, 3 };
    static const double c[] = { 0, 1, 2, 3 };
    o[0] = spline_ref("catmull-rom", u, a, 6);
    o[1] = spline_ref("catmull-rom", v, b, 7);
    o[2] = 0.5 * spline_ref("catmull-rom", 0.5, c, 4);
}

static void ref_spline_color_ramp(double u, double v, double o[3])
{
    static const double k[7][3] = { { 0.3, 0.12, 0.03 }, { 0.3, 0.12, 0.03 },
                                    { 0.69, 0.44, 0.25 }, { 0.8, 0.5, 0.3 },
                                    { 0.69, 0.44, 0.25 }, { 0.3, 0.12, 0.03 },
                                    { 0.3, 0.12, 0.03 } };
    double ring = fmodf_(u * 3 + 0.5 * v, 1);
    for (int i = 0; i < 3; i++)
        o[i] = spline3("catmull-rom", ring, k, 7, i);
}

static void ref_spline_bezier_point(double u, double v, double o[3])
{
    static const double k[7][3] = { { 0, 0, 0 }, { 1, 2, 0 }, { 2, -1, 1 }, { 3, 0, 1 },
                                    { 4, 1, 1 }, { 5, 0, 2 }, { 6, 3, 0 } };
    for (int i = 0; i < 3; i++)
        o[i] = spline3("bezier", u, k, 7, i);
    o[2] += v;
}

static void ref_spline_bspline(double u, double v, double o[3])
{
    static const double a[] = { 0, 1, 0, 1, 0, 1, 0 }, b[] = { 0, 0, 0, 1, 1, 1 };
    o[0] = spline_ref("b-spline", u, a, 7);
    o[1] = spline_ref("b-spline", v * v, b, 6);
    o[2] = o[0] * o[1];
}

static void ref_spline_hermite(double u, double v, double o[3])
{
    static const double a[] = { 0, 2, 1, 0 };
    static const double k[6][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 },
                                    { 0, 0, 1 }, { 1, 1, 0 }, { -1, 0, 0 } };
    o[0] = spline_ref("hermite", u, a, 4);
    o[1] = spline3("hermite", v, k, 6, 1) + spline3("hermite", v, k, 6, 0);
    o[2] = spline3("hermite", v, k, 6, 2);
}

static void ref_spline_linear_constant(double u, double v, double o[3])
{
    static const double a[] = { 9, 0, 1, 0.5, 2, 9 }, c[] = { 9, 1, 0.5, 9 };
    o[0] = spline_ref("linear", u, a, 6);
    o[1] = spline_ref("constant", v, a, 6);
    o[2] = spline_ref("linear", v, c, 4);
}

static void ref_spline_array(double u, double v, double o[3])
{
    static const double h[] = { 0, 0.2, 0.1, 0.7, 1, 1.2 }, g[] = { 0, 0.4, 0.8, 1 };
    o[0] = spline_ref("catmull-rom", u, h, 6);
    o[1] = spline_ref("linear", v, h, 6);
    o[2] = spline_ref("b-spline", v, g, 4);
}

static void ref_spline_unsized_param(double u, double v, double o[3])
{
    static const double a[] = { 0, 1, 2, 3 }, b[] = { 1, 0, 0.5, 0.25, 1, 0 };
    o[0] = spline_ref("catmull-rom", u, a, 4);
    o[1] = spline_ref("catmull-rom", v, b, 6);
    o[2] = spline_ref("catmull-rom", u * v, b, 6);
}

static void ref_spline_noise_marble(double u, double v, double o[3])
{
    double n = noise3(3 * u, 3 * v, 0);
    double k[] = { 0, 0.1, 0.6, 0.3 * 0.6, 1, 0.8 }, b[] = { 0, 1, -1, 0 };
    o[0] = spline_ref("catmull-rom", n, k, 6);
    o[1] = n;
    o[2] = spline_ref("bezier", n, b, 4);
}

/* color spaces, the textbook way (Foley & van Dam's sector switch) */
static void hsv_to_rgb(double h, double s, double v, double o[3])
{
    double h6 = fmodf_(h, 1) * 6, i = floor(h6), f = h6 - i;
    double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    double tab[6][3] = { { v, t, p }, { q, v, p }, { p, v, t },
                         { p, q, v }, { t, p, v }, { v, p, q } };
    for (int k = 0; k < 3; k++)
        o[k] = tab[(int)i % 6][k];
}

static double hue_channel(double p, double q, double t)
{
    t = fmodf_(t, 1);
    if (t < 1 / 6.0)
        return p + (q - p) * 6 * t;
    if (t < 0.5)
        return q;
    if (t < 2 / 3.0)
        return p + (q - p) * (2 / 3.0 - t) * 6;
    return p;
}

static void hsl_to_rgb(double h, double s, double l, double o[3])
{
    double q = l < 0.5 ? l * (1 + s) : l + s - l * s, p = 2 * l - q;
    o[0] = hue_channel(p, q, h + 1 / 3.0);
    o[1] = hue_channel(p, q, h);
    o[2] = hue_channel(p, q, h - 1 / 3.0);
}

static void rgb_to_hsv(const double c[3], double o[3])
{
    double M = fmax(c[0], fmax(c[1], c[2])), m = fmin(c[0], fmin(c[1], c[2])), d = M - m;
    double h = 0;
    if (d > 0) {
        if (M == c[0])
            h = fmodf_((c[1] - c[2]) / d, 6);
        else if (M == c[1])
            h = (c[2] - c[0]) / d + 2;
        else
            h = (c[0] - c[1]) / d + 4;
    }
    o[0] = h / 6; o[1] = M > 0 ? d / M : 0; o[2] = M;
}

static void ref_color_hsv(double u, double v, double o[3])
{
    hsv_to_rgb(u, 0.8, 0.5 + 0.5 * v, o);
}

static void ref_color_hsl(double u, double v, double o[3])
{
    hsl_to_rgb(v + 0.5, 0.6, 0.2 + 0.6 * u, o);
}

static void ref_color_hue_shift(double u, double v, double o[3])
{
    double c[3] = { u, 1 - u, 0.1 }, hsv[3], back[3], d[3] = { 0.5 * u, 0.25 * v, 1.2 }, b[3];
    rgb_to_hsv(c, hsv);
    hsv_to_rgb(hsv[0] + 0.1, hsv[1], hsv[2], back);
    rgb_to_hsv(d, b);
    o[0] = hsv[0]; o[1] = back[1] + back[2]; o[2] = b[0] + b[1];
}

/* CIE XYZ of linear Rec. 709 primaries (D65) and NTSC YIQ */
static const double M_xyz[3][3] = { { 0.4124564, 0.3575761, 0.1804375 },
                                    { 0.2126729, 0.7151522, 0.0721750 },
                                    { 0.0193339, 0.1191920, 0.9503041 } };
static const double M_yiq[3][3] = { { 0.299, 0.587, 0.114 },
                                    { 0.596, -0.274, -0.322 },
                                    { 0.211, -0.523, 0.312 } };
static void mat3_apply(const double m[3][3], const double x[3], double o[3])
{
    for (int r = 0; r < 3; r++)
        o[r] = m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2];
}
/* x = m^-1 y by Cramer's rule */
static void mat3_solve(const double m[3][3], const double y[3], double x[3])
{
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    for (int k = 0; k < 3; k++) {
        double a[3][3];
        memcpy(a, m, sizeof a);
        for (int r = 0; r < 3; r++)
            a[r][k] = y[r];
        x[k] = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])) / det;
    }
}

static void ref_color_xyz_yiq(double u, double v, double o[3])
{
    double c[3] = { u, v, 0.5 }, xyz[3], yiq[3];
    mat3_apply(M_xyz, c, xyz);
    mat3_apply(M_yiq, c, yiq);
    double sum = xyz[0] + xyz[1] + xyz[2];
    double xyY[3] = { xyz[0] / sum, xyz[1] / sum, xyz[1] };
    /* back: "xyY" -> rgb is c again */
    double in[3] = { 0.5, 0.1 * u, -0.1 * v }, rgb[3], lum[3], fromxyz[3];
    mat3_solve(M_yiq, in, rgb);
    mat3_apply(M_xyz, rgb, lum);
    double given[3] = { u, v, 1 };
    mat3_solve(M_xyz, given, fromxyz);
    o[0] = xyz[0] + yiq[1];
    o[1] = xyY[0] + c[1];
    o[2] = lum[2] + fromxyz[0];
}

/* the conformance VM's "object" space: object -> current scales by 2, then
 * translates by (1, 2, 3) */
static void ref_ptransform_spaces(double u, double v, double o[3])
{
    double P[3] = { 2 * u - 1, 2 * v - 1, 0 };
    double obj[3] = { (P[0] - 1) / 2, (P[1] - 2) / 2, (P[2] - 3) / 2 };
    double m[3] = { 2 * u + 1, 2 * v + 2, 3 };
    o[0] = obj[0]; o[1] = P[1] + m[0]; o[2] = m[2] + v / 2;
}

/* determinant by Gaussian elimination with partial pivoting */
static double det4(double a[4][4])
{
    double det = 1;
    for (int c = 0; c < 4; c++) {
        int p = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        if (a[p][c] == 0)
            return 0;
        if (p != c) {
            for (int k = 0; k < 4; k++) {
                double t = a[c][k];
                a[c][k] = a[p][k];
                a[p][k] = t;
            }
            det = -det;
        }
        det *= a[c][c];
        for (int r = c + 1; r < 4; r++) {
            double f = a[r][c] / a[c][c];
            for (int k = c; k < 4; k++)
                a[r][k] -= f * a[c][k];
        }
    }
    return det;
}

static void ref_matrix_determinant(double u, double v, double o[3])
{
    double a[4][4] = { { 2, u, 0, 0 }, { v, 1, 0.5, 0 }, { 0, 0.25, 3, 0 }, { u, v, 1, 1 } };
    double b[4][4] = { { 1, 0, 0, 0 }, { 0, 1 + u, 0, 0 }, { 0, v, 2, 0 }, { 0, 0, 0, 1 } };
    double ab[4][4], a2[4][4];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            ab[r][c] = 0;
            for (int k = 0; k < 4; k++)
                ab[r][c] += a[r][k] * b[k][c];
        }
    memcpy(a2, a, sizeof a2);
    o[0] = det4(a2); o[1] = det4(ab); o[2] = 16;
}

/* rotation of p about the unit axis a by angle w (Rodrigues) */
static void rodrigues(const double a[3], double w, const double p[3], double o[3])
{
    double c = cos(w), s = sin(w), d = a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
    double x[3] = { a[1] * p[2] - a[2] * p[1], a[2] * p[0] - a[0] * p[2],
                    a[0] * p[1] - a[1] * p[0] };
    for (int k = 0; k < 3; k++)
        o[k] = p[k] * c + x[k] * s + a[k] * d * (1 - c);
}

static void ref_matrix_build(double u, double v, double o[3])
{
    static const double z[3] = { 0, 0, 1 };
    double k = 1 / sqrt(3.0), diag[3] = { k, k, k };
    double p[3] = { 1, 2, v }, r[3], q[3], e[3] = { 1, 0, 0 };
    rodrigues(z, 90 * u * M_PI / 180, p, r);     /* scale, rotate, translate */
    r[0] += 0.5;
    rodrigues(diag, v, e, q);
    o[0] = r[0] + q[2]; o[1] = r[1]; o[2] = r[2] + q[0];
}

static void ref_matrix_comp(double u, double v, double o[3])
{
    double m[4][4] = { { 1, 2, 3, 4 }, { 5, 6, 7, 8 }, { 9, 10, 11, 12 }, { 13, v, 15, 16 } };
    int row = (int)floor(u * 4);
    o[0] = m[3][0] + m[0][2]; o[1] = m[3][1] + m[row][1];
    o[2] = 2 + 3;    /* object -> current: scale 2, then translate (1, 2, 3) */
}

static void normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] /= l;
}

/* Snell's law: T = eta I + (eta c1 - c2) N, c1 = -I.N, c2 = cos of the
 * refracted angle; none (0) past the critical angle */
static void snell(const double I[3], const double N[3], double eta, double T[3])
{
    double c1 = -(I[0] * N[0] + I[1] * N[1] + I[2] * N[2]);
    double s2 = eta * eta * (1 - c1 * c1);
    for (int k = 0; k < 3; k++)
        T[k] = s2 > 1 ? 0 : eta * I[k] + (eta * c1 - sqrt(1 - s2)) * N[k];
}

static void ref_geom_refract(double u, double v, double o[3])
{
    double I1[3] = { u - 0.5, v - 0.5, -1 }, I2[3] = { 3 * u - 1.5, 0.5, -1 };
    double N[3] = { 0, 0, 1 }, a[3], b[3];
    normalize3(I1);
    normalize3(I2);
    snell(I1, N, 1 / 1.5, a);
    snell(I2, N, 1.5, b);
    o[0] = a[0] + a[2]; o[1] = a[1]; o[2] = b[0] + b[2];
}

/* unpolarised Fresnel reflectance from the s and p amplitudes; n = n2/n1 */
static double fresnel_sp(double c, double n)
{
    double sin_t2 = (1 - c * c) / (n * n);
    if (sin_t2 > 1)
        return 1;
    double ct = sqrt(1 - sin_t2);
    double rs = (c - n * ct) / (c + n * ct), rp = (n * c - ct) / (n * c + ct);
    return (rs * rs + rp * rp) / 2;
}

static void ref_geom_fresnel(double u, double v, double o[3])
{
    double N[3] = { 0, 0, 1 }, V[3] = { u - 0.5, 0.3 * v, -1 }, T[3], R[3];
    double V2[3] = { 2 * v - 1, 0.2, -0.5 };
    normalize3(V);
    normalize3(V2);
    double kr = fresnel_sp(fabs(V[2]), 1.5);
    for (int k = 0; k < 3; k++)
        R[k] = V[k] - 2 * V[2] * N[k];
    snell(V, N, 1 / 1.5, T);
    double kr2 = fresnel_sp(fabs(V2[2]), 1 / 1.5);
    o[0] = kr + T[0]; o[1] = 1 - kr + R[2] + T[1]; o[2] = kr2 + (1 - kr2) * 0.5;
}

static void ref_geom_faceforward_reflect(double u, double v, double o[3])
{
    double V[3] = { u - 0.5, v - 0.3, 0.25 - u * v };
    double nf = V[2] < 0 ? 1 : -1;                   /* z of faceforward(N, V, N) */
    normalize3(V);
    double R[3] = { V[0], V[1], V[2] - 2 * V[2] * nf * nf };
    o[0] = R[0]; o[1] = R[1] + nf; o[2] = R[2] - 1;  /* I . Ng > 0: -(0, 1, 0) */
}

static double rnd(double x) { return x < 0 ? -floor(-x + 0.5) : floor(x + 0.5); }
static void ref_math_round_sign(double u, double v, double o[3])
{
    double x = 6 * u - 3, q[3] = { x, 4 * v - 2, x * v };
    double r[3];
    for (int k = 0; k < 3; k++)
        r[k] = rnd(q[k]) + sgn(q[k]) * 10;
    o[0] = r[0] + 1 / sqrt(1 + u * u);
    o[1] = r[1] + fabs(q[2]);
    o[2] = r[2] + floor(q[0]) + ceil(q[0]);
}

/* Clipping 0.5 10.5, camera = current */
static double depth_of(double z) { return (z - 0.5) / 10; }
static void ref_depth_clip(double u, double v, double o[3])
{
    o[0] = depth_of(4 * u + 1); o[1] = depth_of(10 * v); o[2] = depth_of(1);
}

static void ref_filterstep_box(double u, double v, double o[3])
{
    /* the harness sets no du, dv: the point's filter width is 0 */
    double a = u < 0.5 ? 0 : 1;
    double b = clampd((u + 0.05 - 0.5) / 0.1, 0, 1);
    double c = clampd((v + 0.05 + 0.1 - 0.3) / 0.2, 0, 1);
    double d = clampd((v + 0.1 - 0.6) / 0.1, 0, 1);
    o[0] = a + b; o[1] = c; o[2] = d;
}

static void ref_noise_float_forms(double u, double v, double o[3])
{
    double q[4] = { 3 * u, 3 * v, 0, 2 * v }, x5 = 5 * u, xy[2] = { 3 * u, 3 * v };
    int p4 = 4, p23[2] = { 2, 3 }, p444[3] = { 4, 4, 4 }, p2223[4] = { 2, 2, 2, 3 };
    o[0] = noise1(5 * u) + sl_noise(2, xy) + sl_noise(3, q) + sl_noise(4, q);
    o[1] = sl_pnoise(1, &x5, &p4) + sl_pnoise(2, xy, p23) + sl_pnoise(3, q, p444) +
           sl_pnoise(4, q, p2223);
    double c1 = 4 * u, c2[2] = { 4 * u, 4 * v }, c4[4] = { 3 * u, 3 * v, 0, 4 * v };
    o[2] = sl_cellnoise(1, &c1) + sl_cellnoise(2, c2) + sl_cellnoise(3, q) +
           sl_cellnoise(4, c4);
}

static void ref_noise_triple_forms(double u, double v, double o[3])
{
    double q[4] = { 2 * u, 2 * v, 1, v }, st[2] = { 4 * u, 4 * v }, s7 = 7 * u;
    double c1[3], c2[3], v1[3], v2[3], p[3], w1[3], w2[3];
    int p444[3] = { 4, 4, 4 }, p33[2] = { 3, 3 };
    double q2[3] = { 4 * u, 4 * v, 2 }, st3[2] = { 3 * u, 3 * v };
    sl_vnoise(3, q, c1);
    sl_vnoise(2, st, c2);
    sl_vnoise(4, q, v1);
    sl_vnoise(1, &s7, v2);
    sl_vpnoise(3, q, p444, p);
    sl_vcellnoise(3, q2, w1);
    sl_vpnoise(2, st3, p33, w2);
    o[0] = c1[0] + c2[0] + v1[0] + v2[0];
    o[1] = v1[1] + v2[1] + p[1];
    o[2] = w1[2] + w2[2] + p[2];
}

static double fstep3(double e, double x0, double x1)
{
    double lo = fmin(x0, x1), hi = fmax(x0, x1), w = hi - lo;
    return clampd((hi - e) / (w > 1e-12 ? w : 1e-12), 0, 1);
}
static double fpulse(double a, double b, double x, double w)
{
    return fstep3(a, x - w / 2, x + w / 2) - fstep3(b, x - w / 2, x + w / 2);
}
static void ref_filterstep_pulse(double u, double v, double o[3])
{
    o[0] = fpulse(0.3, 0.7, fmodf_(u * 4, 1), 0.08);
    o[1] = fpulse(0.2, 0.4, v, 0.16);
    o[2] = stepd(0.5, u) - stepd(0.8, u);
}

static void ref_matrix_det_compose(double u, double v, double o[3])
{
    (void)u;
    o[0] = 2 * (1 + v) * 0.5; o[1] = 1; o[2] = 16 * (1 + v);
}

static void ref_matrix_setcomp_loop(double u, double v, double o[3])
{
    o[0] = 1 + u; o[1] = 4; o[2] = 1 + v;
}

static void ref_color_roundtrip(double u, double v, double o[3])
{
    double c[3] = { 0.2 + 0.6 * u, 0.7 - 0.5 * v, 0.3 + 0.2 * u * v }, xyz[3];
    mat3_apply(M_xyz, c, xyz);
    o[0] = c[0] + c[1]; o[1] = c[2] + c[1]; o[2] = xyz[1] + c[2];
}

static void ref_noise_periodic(double u, double v, double o[3])
{
    double x = 3 * u, x4 = 3 * u + 4;
    int p4 = 4, p235[3] = { 2, 3, 5 }, p33[2] = { 3, 3 };
    double q[3] = { 2 * u, 2 * v, 0 }, q2[3] = { 2 * u + 2, 2 * v + 3, 5 };
    double a2[2] = { 2 * u, 2 * v }, b2[2] = { 2 * u + 3, 2 * v - 3 }, c1[3], c2[3];
    sl_vpnoise(2, a2, p33, c1);
    sl_vpnoise(2, b2, p33, c2);
    o[0] = sl_pnoise(1, &x, &p4) - sl_pnoise(1, &x4, &p4);
    o[1] = sl_pnoise(3, q, p235) + sl_pnoise(3, q2, p235);
    o[2] = c1[2] - c2[2];
}

static void ref_spline_octaves(double u, double v, double o[3])
{
    static const double k[5] = { 0, 1 / 16.0, 4 / 16.0, 9 / 16.0, 1 };
    double sum = 0;
    for (int i = 0; i < 3; i++)
        sum += spline_ref("catmull-rom", fmodf_(u * pow(2, i), 1), k, 5) / pow(2, i);
    o[0] = sum; o[1] = spline_ref("linear", v, k, 5); o[2] = spline_ref("constant", u, k, 5);
}

static void ref_message_attribute(double u, double v, double o[3])
{
    (void)v;
    o[0] = 1 + 10 + 0 + 1000 + 10000; o[1] = 0.25 + 3 * sin(u * 4); o[2] = 7 + 0.2 + 1;
}

static void ref_strings_format(double u, double v, double o[3])
{
    o[0] = floor(u * 10) + 10; o[1] = 5 + v; o[2] = 15;
}

/* written for the renderer-wiring session (issue 15): pattern idioms and
 * the math and geometry built-ins they lean on */
static void ref_pattern_bricks(double u, double v, double o[3])
{
    double bw = 0.25 + 0.02, bh = 0.125 + 0.02, ss = u / bw, tt = v / bh;
    if (fmodf_(tt * 0.5, 1) > 0.5) ss += 0.5;
    double sb = floor(ss), tb = floor(tt);
    ss -= sb;
    tt -= tb;
    double w = stepd(0.02 / bw, ss) * stepd(0.02 / bh, tt);
    o[0] = ss; o[1] = tt; o[2] = w + 10 * sb + 100 * tb;
}

static void ref_pattern_stripes(double u, double v, double o[3])
{
    double ss = fmodf_(u * 5, 1), e = smooth(0.4, 0.6, ss);
    double c0[3] = {0.1, 0.2, 0.3}, c1[3] = {0.9, 0.7, 0.5}, c[3];
    for (int k = 0; k < 3; k++) c[k] = c0[k] * (1 - e) + c1[k] * e;
    o[0] = c[0]; o[1] = c[1] + ss; o[2] = c[2] * v;
}

static void ref_math_clamp_mix(double u, double v, double o[3])
{
    double a[3] = {u, v, u * v}, b[3] = {1 - v, u * u, 0.5};
    o[0] = u * 0.7 + v * 0.3 + clampd(2 * u - 0.5, 0, 1);
    o[1] = fmax(a[0], b[0]) - fmin(a[0], b[0]) + (a[1] * 0.75 + b[1] * 0.25);
    o[2] = clampd(a[2], 0.1, 0.4) + fmax(fmax(u, v), 0.6) - fmin(u, v);
}

static void ref_geom_distance_length(double u, double v, double o[3])
{
    double wx = u - 0.5, wy = v - 0.25, len = sqrt(wx * wx + wy * wy + 1);
    o[0] = sqrt(wx * wx + wy * wy);
    o[1] = len + sqrt((u - 1) * (u - 1) + (v - 1) * (v - 1));
    o[2] = 1 / len;
}

static void ref_math_polar(double u, double v, double o[3])
{
    double x = u - 0.5, y = v - 0.6, r = sqrt(x * x + y * y), a = atan2(y, x);
    o[0] = r; o[1] = sin(3 * a); o[2] = cos(a) * r + atan(u + 0.5);
}

static void ref_math_pow_exp_log(double u, double v, double o[3])
{
    o[0] = pow(u + 0.1, 1 / 2.2);
    o[1] = exp(-2 * v) + log(1 + u);
    o[2] = log(v + 2) / log(2) + sqrt(u + v);
}

/* RSL 2 (issue 15): shader classes and resizable arrays */
static void ref_class_displacement(double u, double v, double o[3])
{
    o[0] = sin(3 * u + 0.25); o[1] = sin(3 * v + 0.25) + 0.25; o[2] = 2;
}

static void ref_class_method_order(double u, double v, double o[3])
{
    o[0] = (u * u + 2 * u) * 2; o[1] = (v * v + 2 * v) * 2 + 0.75; o[2] = 2;
}

static double blend124(double x) { return 1 + 2 * x + 4 * x * x; }
static void ref_class_member_array(double u, double v, double o[3])
{
    o[0] = blend124(u) * 0.5; o[1] = 0.25 + v; o[2] = 4 - blend124(v);
}

static void ref_resizable_push_pop(double u, double v, double o[3])
{
    o[0] = u + v; o[1] = u * v + 10; o[2] = 3;
}

static void ref_resizable_resize_loop(double u, double v, double o[3])
{
    double sum = 0;
    for (int i = 0; i < 5; i++) sum += pow(u, i);
    o[0] = sum; o[1] = 1 + u + v; o[2] = 2;
}

static void ref_resizable_colors(double u, double v, double o[3])
{
    bool two = u > 0.5;
    o[0] = u + 0.5; o[1] = two ? 2 : 1; o[2] = two ? v : 1;
}

/* the noise family in every form, and the math the suite lacked */
static void ref_noise_forms_vector(double u, double v, double o[3])
{
    double x5 = 5 * u, xy[2] = { 3 * u, 3 * v }, q[4] = { 2 * u, 2 * v, 1, 2 * v };
    double a[3], b[3], c[3], d[3];
    sl_vnoise(1, &x5, a);
    sl_vnoise(2, xy, b);
    sl_vnoise(3, q, c);
    sl_vnoise(4, q, d);
    o[0] = a[0] + b[1]; o[1] = c[2] + d[0]; o[2] = a[1] - d[2];
}

static void ref_pnoise_forms_color(double u, double v, double o[3])
{
    double x5 = 5 * u, xy[2] = { 3 * u, 3 * v }, q[4] = { 3 * u, 3 * v, 0, 2 * v };
    int p4 = 4, p23[2] = { 2, 3 }, p444[3] = { 4, 4, 4 }, p2223[4] = { 2, 2, 2, 3 };
    double a[3], b[3], c[3], d[3];
    sl_vpnoise(1, &x5, &p4, a);
    sl_vpnoise(2, xy, p23, b);
    sl_vpnoise(3, q, p444, c);
    sl_vpnoise(4, q, p2223, d);
    o[0] = a[0] + b[1]; o[1] = c[2] + d[0]; o[2] = a[2] * d[1];
}

static void ref_cellnoise_forms_point(double u, double v, double o[3])
{
    double x4 = 4 * u, xy[2] = { 4 * u, 4 * v }, q[4] = { 4 * u, 4 * v, 0, 3 * v };
    double a[3], b[3], c[3], d[3];
    sl_vcellnoise(1, &x4, a);
    sl_vcellnoise(2, xy, b);
    sl_vcellnoise(3, q, c);
    sl_vcellnoise(4, q, d);
    o[0] = a[0] + b[1]; o[1] = c[2] + d[0]; o[2] = a[1] + d[2];
}

static void ref_noise_argument_types(double u, double v, double o[3])
{
    double p[3] = { 2 * (2 * u - 1), 2 * (2 * v - 1), 0 }, w[3] = { u, v, 1 };
    double n4[4] = { 3 * v, 3 * u, 0, u };
    o[0] = sl_noise(3, p) + noise1(1.5); o[1] = sl_noise(3, w); o[2] = sl_noise(4, n4);
}

/* the VM's random() (splitmix64 from the seed, 0 here) */
static double splitmix(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1p-53;
}
static void ref_random_sequence(double u, double v, double o[3])
{
    uint64_t st = 0;
    double r[5];
    for (int i = 0; i < 5; i++) r[i] = splitmix(&st);
    o[0] = r[0] + u; o[1] = r[1] + r[3]; o[2] = r[4] * v;
}

static void ref_math_inversesqrt(double u, double v, double o[3])
{
    o[0] = 1 / sqrt(u + 0.5); o[1] = v / sqrt(v * v + 1); o[2] = 0;
}

static void ref_math_trig_inverse(double u, double v, double o[3])
{
    o[0] = tan(u) + atan(v); o[1] = asin(u - 0.5) + acos(v - 0.5);
    o[2] = atan2(v, u) * 180 / M_PI + 90 * u * M_PI / 180;
}

static void ref_math_mod_floor_ceil(double u, double v, double o[3])
{
    o[0] = fmodf_(7 * u, 2) + floor(5 * v); o[1] = ceil(3 * u) - fmodf_(-3 * v, 1);
    o[2] = fmodf_(10 * u, 0.3) * 2;
}

static void ref_math_step_smoothstep(double u, double v, double o[3])
{
    o[0] = stepd(0.5, u) + smooth(0.2, 0.8, v); o[1] = smooth(0, 1, u * v);
    o[2] = stepd(v, u) * 2;
}

static void ref_strings_concat_match(double u, double v, double o[3])
{
    o[0] = 1 + 0 + 4; o[1] = u + (floor(4 * u) <= 1 ? 1 : 0); o[2] = v;
}

static void ref_message_names(double u, double v, double o[3])
{
    (void)u;
    (void)v;
    o[0] = 16 + 32; o[1] = -1 + 0.25; o[2] = 1 + 2;
}

static void ref_geom_transform_matrix(double u, double v, double o[3])
{
    o[0] = 2 * (u + 1) + 3 * v; o[1] = 3 * v + v / 3; o[2] = 1 + 2 * u;
}

static void ref_spline_vector_normal(double u, double v, double o[3])
{
    static const double cr[4][4] = { { -0.5, 1.5, -1.5, 0.5 }, { 1, -2.5, 2, -0.5 },
                                     { -0.5, 0, 0.5, 0 }, { 0, 1, 0, 0 } };
    static const double kv[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 1 } };
    static const double kn[5][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 },
                                     { 1, 1, 1 } };
    double x = clampd(u, 0, 1), y = clampd(v, 0, 1) * 2, seg = fmin(floor(y), 1);
    y -= seg;
    for (int c = 0; c < 3; c++) {
        double val = 0;
        for (int i = 0; i < 4; i++) {
            double coef = 0;
            for (int j = 0; j < 4; j++) coef += cr[i][j] * kv[j][c];
            val += coef * pow(x, 3 - i);
        }
        int k = (int)seg;
        o[c] = val + kn[k + 1][c] + y * (kn[k + 2][c] - kn[k + 1][c]);
    }
}

static void ref_resizable_nested_extern(double u, double v, double o[3])
{
    double kept[3];
    int n = 0;
    double xs[3] = { u, v, 0.5 };
    for (int i = 0; i < 3; i++)
        if (xs[i] > 0.3) kept[n++] = xs[i];
    o[0] = n; o[1] = 0.5; o[2] = kept[0];
}

static void ref_class_accumulate(double u, double v, double o[3])
{
    double sum = 0, amp = 1;
    for (int i = 0; i < 4; i++) {
        sum += amp * sin(pow(2, i) * u);
        amp *= 0.5;
    }
    o[0] = sum; o[1] = amp; o[2] = v;
}

static void ref_voronoi_regular(double u, double v, double o[3])
{
    double x = 3 * u, y = 3 * v, cx = floor(x) + 0.5, cy = floor(y) + 0.5;
    o[0] = sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy)); o[1] = cx; o[2] = cy;
}

static void ref_noises_vsnoise(double u, double v, double o[3])
{
    double p[3] = { 3 * u, 3 * v, 0 }, d[3];
    sl_vnoise(3, p, d);
    for (int k = 0; k < 3; k++) d[k] = 2 * d[k] - 1;
    o[0] = 0.2 * d[0]; o[1] = 0.2 * d[1] + 2 * noise1(4 * v) - 1; o[2] = d[2];
}

/* the rest of RI Spec 3.2's geometric and shading built-ins */
static double dotv(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static double seg_dist(const double a[3], const double b[3], const double q[3])
{
    double v[3], w[3], vv = 0, wv = 0, d2 = 0;
    for (int k = 0; k < 3; k++) {
        v[k] = b[k] - a[k];
        w[k] = q[k] - a[k];
        vv += v[k] * v[k];
        wv += w[k] * v[k];
    }
    double t = vv > 0 ? clampd(wv / vv, 0, 1) : 0;
    for (int k = 0; k < 3; k++) d2 += (w[k] - t * v[k]) * (w[k] - t * v[k]);
    return sqrt(d2);
}
static void ref_geom_ptlined(double u, double v, double o[3])
{
    double a[3] = { 0.3, 0.2, 0 }, b[3] = { 0.6, 0.9, 0 }, c[3] = { 0.2, 0.2, 0 };
    double z[3] = { 0, 0, 0 }, one[3] = { 1, 1, 1 }, q[3] = { u, v, 0 }, q1[3] = { u, v, 1 };
    o[0] = seg_dist(a, b, q); o[1] = seg_dist(c, c, q); o[2] = seg_dist(z, one, q1);
}

static void ref_geom_rotate_point(double u, double v, double o[3])
{
    double P0[3] = { 0.1, 0.2, 0.3 }, ax[3] = { 0.4, 0.8, 1.7 };
    double p[3] = { u - 0.1, v - 0.2, -0.3 }, ang = M_PI / 3 * u;
    normalize3(ax);
    double c = cos(ang), sn = sin(ang), ap = dotv(ax, p);
    double x[3] = { ax[1] * p[2] - ax[2] * p[1], ax[2] * p[0] - ax[0] * p[2],
                    ax[0] * p[1] - ax[1] * p[0] };
    for (int k = 0; k < 3; k++)
        o[k] = P0[k] + p[k] * c + x[k] * sn + ax[k] * ap * (1 - c);
}

static double lobe(const double L[3], const double N[3], const double V[3], double r)
{
    double Ln[3] = { L[0], L[1], L[2] }, Nn[3] = { N[0], N[1], N[2] }, H[3];
    normalize3(Ln);
    normalize3(Nn);
    for (int k = 0; k < 3; k++) H[k] = Ln[k] + V[k];
    normalize3(H);
    double c = dotv(Nn, H);
    return pow(c > 0 ? c : 0, 1 / r);
}
static void ref_shading_specularbrdf(double u, double v, double o[3])
{
    double L[3] = { u - 0.5, v - 0.5, 1 }, N[3] = { 0, 0.2, 1 }, V[3] = { 0, 0, 1 };
    double L2[3] = { 1, 0, -1 }, N2[3] = { 0, 0, 1 };
    o[0] = lobe(L, N, V, 0.2); o[1] = 0; o[2] = lobe(L2, N2, V, 0.5);
}

static void ref_strings_shadername(double u, double v, double o[3])
{
    (void)v;
    o[0] = 1; o[1] = 1; o[2] = u;
}

static void ref_matrix_division(double u, double v, double o[3])
{
    o[0] = u; o[1] = v + 0.5; o[2] = fmin(fmin(u, v), 0.5) + 3;
}

/* ---------------------------------------------------------------------- */
/* the cases                                                               */
/* ---------------------------------------------------------------------- */

/* the suite's camera (test_conformance): perspective, fov 90, clipping 1
 * to 11, screen window [-1.5, 1.5] x [-1, 1], 300 x 200 pixels; "camera"
 * is "current" */
static void ref_space_ndc_raster(double u, double v, double o[3])
{
    double x = 2 * u - 1, y = 2 * v - 1, z = 3 + u, n = 1, f = 11;
    double sx = x / z, sy = y / z, sz = f * (z - n) / (z * (f - n));
    double nx = (sx + 1.5) / 3, ny = (1 - sy) / 2;
    double rx = nx * 300, ry = ny * 200;
    o[0] = rx / 100 + ny;
    o[1] = ry / 100 - nx;
    o[2] = z * sz;                   /* the NDC centre at depth sz is (0, 0, z) */
}

static void ref_params_many(double u, double v, double o[3])
{
    double mixed = (u + (v - u) * u * v) * 0.75, spec = 0.8 / 1.3;
    double w[8] = { 1, 2, 3, 4, 5, 6, 7, 8 };
    double x[8] = { u, v, u * v, u + v, u - v, 2 * u, 2 * v, 1 }, num = 0;
    for (int i = 0; i < 8; i++)
        num += w[i] * x[i];
    double total = 0, last = 0;
    for (int i = 0; i < 38; i++) {
        double a = (i % 2 ? u : v) * (i + 1);
        total += a * (i % 5 + 1);
        last = a;
    }
    o[0] = mixed + spec;
    o[1] = num / 36;
    o[2] = total / 100 + last;
}

static void cellnearest(double x, double y, double *f1, double c[2])
{
    c[0] = floor(x) + 0.5;
    c[1] = floor(y) + 0.5;
    *f1 = sqrt((x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]));
}
static void ref_overload_cellular(double u, double v, double o[3])
{
    double d, c[2], d2, c2[2], d3, c3[2];
    cellnearest(3 * u, 3 * v, &d, c);
    cellnearest(3 * v, 3 * u, &d2, c2);
    cellnearest(2 * u, 2 * v, &d3, c3);
    o[0] = d;
    o[1] = c[0] + c2[1];
    o[2] = c3[1] + d3 * 0.5;
}

static void ref_lineends_mac(double u, double v, double o[3])
{
    o[0] = (0.5 + 0.5 * sin(u * 4)) * smooth(0.2, 0.8, v);
    o[1] = smooth(0.2, 0.8, u);
    o[2] = v;
}

typedef struct conf_case {
    const char *file;
    const char *feature;
    void (*ref)(double u, double v, double out[3]);
    bool no_dual;       /* uses derivatives: dual values differ from float ones */
} conf_case;

#define CASE(name, feature) { #name ".sl", feature, ref_##name, false }
#define CASE_NO_DUAL(name, feature) { #name ".sl", feature, ref_##name, true }
static const conf_case cases[] = {
    CASE(shadow_global_local, "shadowed globals"),
    CASE(shadow_function_params, "shadowed globals"),
    CASE(shadow_shader_param, "shadowed globals"),
    CASE(shadow_builtin_names, "shadowed built-in names"),
    CASE(scope_blocks_for, "block scopes"),
    CASE(nested_filteredabs, "nested functions"),
    CASE(nested_pulsetrain, "extern of enclosing variables"),
    CASE(nested_extern_accumulate, "extern of enclosing variables"),
    CASE(nested_two_levels, "extern of enclosing variables"),
    CASE(nested_in_loop, "nested functions"),
    CASE(nested_hides_file_level, "nested functions"),
    CASE(extern_globals_nested, "extern of enclosing variables"),
    CASE(overload_snoise, "overloading by argument type"),
    CASE(overload_return_type, "overloading by return type"),
    CASE(overload_builtin, "overloads beside built-ins"),
    CASE(overload_output, "overloading by argument type"),
    CASE(overload_conversion_cost, "overloading by argument type"),
    CASE(list_assign, "untyped triples"),
    CASE(list_param_default, "untyped triples"),
    CASE(list_return_arg, "untyped triples"),
    CASE(list_operators, "untyped triples"),
    CASE(list_matrix, "untyped 16-tuples"),
    CASE(patterns_pulses, "helper headers"),
    CASE(noises_fbm, "helper headers"),
    CASE(noises_turbulence, "helper headers"),
    CASE(voronoi_cells, "helper headers"),
    CASE_NO_DUAL(filterwidth_overloads, "helper headers"),
    CASE(array_lookup, "arrays"),
    CASE(array_unsized_param, "arrays"),
    CASE(array_store_loop, "arrays"),
    CASE(array_nested_extern, "arrays"),
    CASE(shadow_output_param, "shadowed globals"),
    CASE(shadow_global_in_nested, "shadowed globals"),
    CASE(nested_sibling_calls, "nested functions"),
    CASE(nested_output_param, "extern of enclosing variables"),
    CASE(overload_nested_local, "overloading by argument type"),
    CASE(overload_triples, "overloading by argument type"),
    CASE(overload_return_noise, "overloading by return type"),
    CASE(list_nested_return, "untyped triples"),
    CASE(list_builtins, "untyped triples"),
    CASE(array_color_ramp, "arrays"),
    CASE(array_sort, "arrays"),
    CASE(array_output_fill, "arrays"),
    CASE(array_points, "arrays"),
    CASE(nested_early_return, "extern of enclosing variables"),
    CASE(overload_arrays, "overloading by argument type"),
    CASE(list_array_init, "untyped triples"),
    CASE(nested_break_continue, "nested functions"),
    CASE(shadow_overload_params, "shadowed globals"),
    CASE(extern_write_chain, "extern of enclosing variables"),
    CASE(array_matrices, "arrays"),
    CASE(nested_shadows_builtin, "shadowed built-in names"),
    CASE(spline_float, "spline"),
    CASE(spline_color_ramp, "spline"),
    CASE(spline_bezier_point, "spline"),
    CASE(spline_bspline, "spline"),
    CASE(spline_hermite, "spline"),
    CASE(spline_linear_constant, "spline"),
    CASE(spline_array, "spline"),
    CASE(spline_unsized_param, "spline"),
    CASE(spline_noise_marble, "spline"),
    CASE(color_hsv, "color spaces"),
    CASE(color_hsl, "color spaces"),
    CASE(color_hue_shift, "color spaces"),
    CASE(color_xyz_yiq, "color spaces"),
    CASE(ptransform_spaces, "space transforms"),
    CASE(matrix_determinant, "matrices"),
    CASE(matrix_build, "matrices"),
    CASE(matrix_comp, "matrices"),
    CASE(geom_refract, "shading geometry"),
    CASE(geom_fresnel, "shading geometry"),
    CASE(geom_faceforward_reflect, "shading geometry"),
    CASE(math_round_sign, "math"),
    CASE(depth_clip, "depth"),
    CASE(filterstep_box, "filterstep"),
    CASE(noise_float_forms, "noise family"),
    CASE(noise_triple_forms, "noise family"),
    CASE(filterstep_pulse, "filterstep"),
    CASE(matrix_det_compose, "matrices"),
    CASE(matrix_setcomp_loop, "matrices"),
    CASE(color_roundtrip, "color spaces"),
    CASE(noise_periodic, "noise family"),
    CASE(spline_octaves, "spline"),
    CASE(message_attribute, "message passing"),
    CASE(strings_format, "strings"),
    CASE(pattern_bricks, "pattern idioms"),
    CASE(pattern_stripes, "pattern idioms"),
    CASE(math_clamp_mix, "math"),
    CASE(geom_distance_length, "shading geometry"),
    CASE(math_polar, "math"),
    CASE(math_pow_exp_log, "math"),
    CASE(class_displacement, "RSL 2 classes"),
    CASE(class_method_order, "RSL 2 classes"),
    CASE(class_member_array, "RSL 2 classes"),
    CASE(resizable_push_pop, "RSL 2 resizable arrays"),
    CASE(resizable_resize_loop, "RSL 2 resizable arrays"),
    CASE(resizable_colors, "RSL 2 resizable arrays"),
    CASE(noise_forms_vector, "noise family"),
    CASE(pnoise_forms_color, "noise family"),
    CASE(cellnoise_forms_point, "noise family"),
    CASE(noise_argument_types, "noise family"),
    CASE(random_sequence, "random"),
    CASE(math_inversesqrt, "math"),
    CASE(math_trig_inverse, "math"),
    CASE(math_mod_floor_ceil, "math"),
    CASE(math_step_smoothstep, "math"),
    CASE(strings_concat_match, "strings"),
    CASE(message_names, "message passing"),
    CASE(geom_transform_matrix, "space transforms"),
    CASE(spline_vector_normal, "spline"),
    CASE(resizable_nested_extern, "RSL 2 resizable arrays"),
    CASE(class_accumulate, "RSL 2 classes"),
    CASE(voronoi_regular, "helper headers"),
    CASE(noises_vsnoise, "helper headers"),
    CASE(geom_ptlined, "shading geometry"),
    CASE(geom_rotate_point, "shading geometry"),
    CASE(shading_specularbrdf, "shading geometry"),
    CASE(strings_shadername, "strings"),
    CASE(matrix_division, "matrices"),
    CASE(space_ndc_raster, "projective spaces (screen, NDC, raster)"),
    CASE(params_many, "functions of many parameters"),
    CASE(overload_cellular, "overloads calling overloads"),
    CASE(lineends_mac, "CR and CR-LF line ends"),
};
#undef CASE
#undef CASE_NO_DUAL

typedef struct conf_error {
    const char *file;
    const char *expected;
} conf_error;

static const conf_error errors[] = {
    { "errors/redefinition.sl",
      "errors/redefinition.sl:5:11: error: redefinition of 's'\n"
      "    float s = 2;\n"
      "          ^\n"
      "errors/redefinition.sl:4:11: note: previous definition is here\n"
      "    float s = 1;\n"
      "          ^\n" },
    { "errors/ambiguous.sl",
      "errors/ambiguous.sl:8:10: error: call to 'pick' is ambiguous\n"
      "    P += pick(P);\n"
      "         ^\n"
      "errors/ambiguous.sl:3:7: note: candidate: float pick(point)\n"
      "float pick(point p) { return xcomp(p); }\n"
      "      ^\n"
      "errors/ambiguous.sl:4:7: note: candidate: color pick(point)\n"
      "color pick(point p) { return color(ycomp(p)); }\n"
      "      ^\n" },
    { "errors/no_extern.sl",
      "errors/no_extern.sl:4:34: error: 'Km' belongs to an enclosing scope; declare it "
      "'extern float Km;' in function 'bump' to use it here\n"
      "    float bump(float x) { return Km * x; }\n"
      "                                 ^\n" },
    { "errors/out_of_scope.sl",
      "errors/out_of_scope.sl:7:10: error: use of undeclared function 'twice'\n"
      "    P += twice(s) * N;\n"
      "         ^\n" },
    { "errors/array_index.sl",
      "errors/array_index.sl:5:12: error: array index 3 is out of range for 'a' (float[3]: "
      "0 to 2)\n"
      "    P += a[3] * N;\n"
      "           ^\n" },
    { "errors/array_string.sl",
      "errors/array_string.sl:4:17: error: arrays of strings are not supported\n"
      "    string names[2];\n"
      "                ^\n" },
    { "errors/extern_missing.sl",
      "errors/extern_missing.sl:4:35: error: 'extern' names no variable 'Kd' of an "
      "enclosing scope\n"
      "    float helper() { extern float Kd; return Kd; }\n"
      "                                  ^\n" },
    { "errors/overload_nomatch.sl",
      "errors/overload_nomatch.sl:7:10: error: no matching function for call to 'w' with "
      "arguments (string)\n"
      "    P += w(\"heavy\") * N;\n"
      "         ^\n"
      "errors/overload_nomatch.sl:2:7: note: candidate: float w(float)\n"
      "float w(float x) { return x; }\n"
      "      ^\n"
      "errors/overload_nomatch.sl:3:7: note: candidate: float w(color)\n"
      "float w(color c) { return comp(c, 0); }\n"
      "      ^\n" },
    { "errors/untyped.sl",
      "errors/untyped.sl:4:15: error: cannot tell the type of this list of 3 values here; "
      "put a type in front, as in 'point (...)'\n"
      "    float d = (1, 0, 0) . (0, 1, 0);\n"
      "              ^\n" },
    { "errors/spline_basis.sl",
      "errors/spline_basis.sl:4:17: error: unknown spline basis 'cardinal' (known: "
      "\"catmull-rom\", \"bezier\", \"b-spline\", \"hermite\", \"linear\", \"constant\")\n"
      "    P += spline(\"cardinal\", s, 0, 1, 2, 3) * N;\n"
      "                ^\n" },
    { "errors/spline_count.sl",
      "errors/spline_count.sl:4:10: error: a 'bezier' spline takes 4, 7, 10, ... knots, "
      "not 5\n"
      "    P += spline(\"bezier\", s, 0, 1, 2, 3, 4) * N;\n"
      "         ^\n" },
    { "errors/color_space.sl",
      "errors/color_space.sl:4:26: error: unknown color space 'cmyk' (known: \"rgb\", "
      "\"hsv\", \"hsl\", \"xyz\", \"XYZ\", \"xyY\", \"YIQ\")\n"
      "    color c = ctransform(\"cmyk\", Cs);\n"
      "                         ^\n" },
    { "errors/format_type.sl",
      "errors/format_type.sl:4:46: error: '%f' in the format string of format() does not "
      "take a 'point'\n"
      "    string label = format(\"height %f at %p\", P, s);\n"
      "                                             ^\n" },
    { "errors/filterstep_param.sl",
      "errors/filterstep_param.sl:4:29: error: unknown filterstep() parameter 'blur' "
      "(known: \"width\" with a float, \"filter\" with a name)\n"
      "    P += filterstep(0.5, s, \"blur\", 0.1) * N;\n"
      "                            ^\n" },
    { "errors/class_two_shaders.sl",
      "errors/class_two_shaders.sl:5:17: error: class 'twokinds' has both a 'surface' and "
      "a 'displacement' method; aafarm compiles a class as one shader: split it into two "
      "classes\n"
      "    public void displacement(output point P; output normal N) { P += N; }\n"
      "                ^\n"
      "errors/class_two_shaders.sl:4:17: note: 'surface' defined here\n"
      "    public void surface(output color Ci, Oi) { Ci = 1; }\n"
      "                ^\n" },
    { "errors/coshader.sl",
      "errors/coshader.sl:5:5: error: 'shader' variables (RSL 2 co-shaders) are not "
      "supported: aafarm compiles each shader on its own: put the co-shader's code in a "
      "function of this shader (or #include it)\n"
      "    shader base = getshader(layer);\n"
      "    ^\n" },
    { "errors/coshader_param.sl",
      "errors/coshader_param.sl:3:29: error: 'shader' parameters (RSL 2 co-shaders) are not "
      "supported: aafarm compiles each shader on its own: put the co-shader's code in a "
      "function of this shader (or #include it)\n"
      "displacement coshader_param(shader layers[] = {}; float Km = 0.1)\n"
      "                            ^\n" },
    { "errors/coshader_getshaders.sl",
      "errors/coshader_getshaders.sl:4:27: error: 'getshaders' (RSL 2 co-shaders) is not "
      "supported: aafarm compiles each shader on its own: put the co-shader's code in a "
      "function of this shader (or #include it)\n"
      "    float n = arraylength(getshaders());\n"
      "                          ^\n" },
    { "errors/resizable_fixed.sl",
      "errors/resizable_fixed.sl:5:5: error: push() takes a resizable array (a local "
      "declared without size or initializer, as 'float a[];') and a value\n"
      "    push(a, s);\n"
      "    ^\n" },
    { "errors/trace_displacement.sl",
      "errors/trace_displacement.sl:4:15: error: trace() cannot be used in a displacement "
      "shader: it runs over ranges of the surface, where a traced ray has no bound (use it "
      "in a surface shader)\n"
      "    color c = trace(P, N);\n"
      "              ^\n" },
    { "errors/shadow_param.sl",
      "errors/shadow_param.sl:6:34: error: unknown shadow() parameter 'bluur' (known: "
      "\"samples\", \"blur\", \"sblur\", \"tblur\", \"bias\", \"width\", \"swidth\", "
      "\"twidth\", \"filter\", \"fill\")\n"
      "        Cl = 1 - shadow(map, Ps, \"bluur\", 0.1);\n"
      "                                 ^\n" },
};

/* ---------------------------------------------------------------------- */
/* surface shaders: illuminance loops                                      */
/* ---------------------------------------------------------------------- */

/* Surface shaders run on the unit sphere with I = (0, 0, 1) under these
 * fixed lights (three distant ones and an ambient one); Ci and Oi are
 * checked. */
static const sl_light_sample surface_lights[] = {
    { { 0.3, 0.2, -1 }, { 1, 0.8, 0.6 }, false, true },
    { { -0.5, 0.1, 0.4 }, { 0.2, 0.3, 1 }, false, true },
    { { 0.6, -0.7, 0.2 }, { 0.5, 0.5, 0.2 }, false, true },
    { { 0, 0, 0 }, { 0.05, 0.05, 0.05 }, true, false },
};
enum { NSURFACE_LIGHTS = sizeof surface_lights / sizeof surface_lights[0] };

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* faceforward(normalize(N), I) with I = (0, 0, 1), Ng = N */
static void facing(const double N[3], double Nf[3])
{
    double Nn[3] = { N[0], N[1], N[2] };
    normalize3(Nn);
    for (int k = 0; k < 3; k++)
        Nf[k] = N[2] < 0 ? Nn[k] : -Nn[k];
}

static void ref_surface_illuminance_diffuse(const double N[3], double Ci[3], double Oi[3])
{
    double Nf[3];
    facing(N, Nf);
    for (int k = 0; k < 3; k++)
        Ci[k] = Oi[k] = 0;
    for (int i = 0; i < NSURFACE_LIGHTS; i++) {
        const sl_light_sample *l = &surface_lights[i];
        if (l->ambient)
            continue;
        double Ln[3] = { l->L[0], l->L[1], l->L[2] };
        normalize3(Ln);
        double d = dot3(Ln, Nf);
        for (int k = 0; k < 3; k++) {
            Ci[k] += d >= 0 ? 0.8 * l->Cl[k] * d : 0;
            Oi[k] += 0.8 * l->Cl[k] * (d > 0 ? d : 0);
        }
    }
}

static void ref_surface_illuminance_specular(const double N[3], double Ci[3], double Oi[3])
{
    double Nf[3], V[3] = { 0, 0, -1 };
    facing(N, Nf);
    for (int k = 0; k < 3; k++)
        Ci[k] = Oi[k] = 0;
    for (int i = 0; i < NSURFACE_LIGHTS; i++) {
        const sl_light_sample *l = &surface_lights[i];
        if (l->ambient)
            continue;
        double Ln[3] = { l->L[0], l->L[1], l->L[2] }, H[3];
        normalize3(Ln);
        for (int k = 0; k < 3; k++)
            H[k] = Ln[k] + V[k];
        normalize3(H);
        double c = dot3(Nf, H), lobe = pow(c > 0 ? c : 0, 4);
        for (int k = 0; k < 3; k++) {
            Ci[k] += dot3(Ln, Nf) >= 0 ? l->Cl[k] * lobe : 0;
            Oi[k] += l->Cl[k] * lobe;       /* specular(): every light */
        }
    }
}

static void ref_surface_illuminance_category(const double N[3], double Ci[3], double Oi[3])
{
    double Nf[3];
    facing(N, Nf);
    for (int k = 0; k < 3; k++)
        Ci[k] = 0;
    for (int i = 0; i < NSURFACE_LIGHTS; i++)
        if (!surface_lights[i].ambient && dot3(surface_lights[i].L, Nf) >= 0)
            for (int k = 0; k < 3; k++)
                Ci[k] += 0.5 * surface_lights[i].Cl[k];
    Oi[0] = 3; Oi[1] = 0; Oi[2] = 0;
}

static void ref_surface_illuminance_helper(const double N[3], double Ci[3], double Oi[3])
{
    double Nf[3];
    facing(N, Nf);
    for (int k = 0; k < 3; k++)
        Ci[k] = Oi[k] = 0;
    for (int i = 0; i < NSURFACE_LIGHTS; i++) {
        const sl_light_sample *l = &surface_lights[i];
        if (l->ambient)
            continue;
        double Ln[3] = { l->L[0], l->L[1], l->L[2] };
        normalize3(Ln);
        double d = dot3(Ln, Nf), w = (d + 0.3) / 1.3;
        for (int k = 0; k < 3; k++) {
            Ci[k] += l->Cl[k] * (w > 0 ? w : 0);
            Oi[k] += -d >= cos(M_PI / 3) ? l->Cl[k] : 0;   /* the cone about -Nf */
        }
    }
}

/* the same loop written as an RSL 2 class */
static void ref_surface_class_matte(const double N[3], double Ci[3], double Oi[3])
{
    ref_surface_illuminance_diffuse(N, Ci, Oi);
}

/* no tracer: trace() black, shadow() 0, so the diffuse loop alone */
static void ref_surface_trace_untraced(const double N[3], double Ci[3], double Oi[3])
{
    ref_surface_illuminance_diffuse(N, Ci, Oi);
    Oi[0] = 1; Oi[1] = 0; Oi[2] = 0;
}

/* specular() against its definition with specularbrdf over every light */
static void ref_surface_specularbrdf(const double N[3], double Ci[3], double Oi[3])
{
    double unused[3];
    ref_surface_illuminance_specular(N, unused, Oi);
    for (int k = 0; k < 3; k++) Ci[k] = Oi[k];
}

typedef struct surface_case {
    const char *file;
    void (*ref)(const double N[3], double Ci[3], double Oi[3]);
} surface_case;

#define SURFACE(name) { #name ".sl", ref_##name }
static const surface_case surface_cases[] = {
    SURFACE(surface_illuminance_diffuse),
    SURFACE(surface_illuminance_specular),
    SURFACE(surface_illuminance_category),
    SURFACE(surface_illuminance_helper),
    SURFACE(surface_class_matte),
    SURFACE(surface_trace_untraced),
    SURFACE(surface_specularbrdf),
};
#undef SURFACE

/* ---------------------------------------------------------------------- */
/* running                                                                 */
/* ---------------------------------------------------------------------- */

/* The warnings a case must give (every other case compiles without any):
 * the parameters of shadow() it accepts and ignores, once per name. */
static const struct { const char *file, *warnings; } expected_warnings[] = {
    { "surface_trace_untraced.sl",
      "surface_trace_untraced.sl:10:40: warning: shadow() parameter 'samples' is accepted "
      "and ignored: shadows are traced rays, sharp, with no map to filter or bias (said "
      "once per shader)\n"
      "    float lit = 1 - shadow(\"nomap\", P, \"samples\", 16, \"blur\", 0.01, \"bias\", "
      "0.05,\n"
      "                                       ^\n"
      "surface_trace_untraced.sl:10:55: warning: shadow() parameter 'blur' is accepted "
      "and ignored: shadows are traced rays, sharp, with no map to filter or bias (said "
      "once per shader)\n"
      "    float lit = 1 - shadow(\"nomap\", P, \"samples\", 16, \"blur\", 0.01, \"bias\", "
      "0.05,\n"
      "                                                      ^\n"
      "surface_trace_untraced.sl:10:69: warning: shadow() parameter 'bias' is accepted "
      "and ignored: shadows are traced rays, sharp, with no map to filter or bias (said "
      "once per shader)\n"
      "    float lit = 1 - shadow(\"nomap\", P, \"samples\", 16, \"blur\", 0.01, \"bias\", "
      "0.05,\n"
      "                                                                    ^\n"
      "surface_trace_untraced.sl:11:28: warning: shadow() parameter 'filter' is accepted "
      "and ignored: shadows are traced rays, sharp, with no map to filter or bias (said "
      "once per shader)\n"
      "                           \"filter\", \"gaussian\", \"width\", 2);\n"
      "                           ^\n"
      "surface_trace_untraced.sl:11:50: warning: shadow() parameter 'width' is accepted "
      "and ignored: shadows are traced rays, sharp, with no map to filter or bias (said "
      "once per shader)\n"
      "                           \"filter\", \"gaussian\", \"width\", 2);\n"
      "                                                 ^\n" },
};

/* Compiled cleanly: no diagnostics but the expected warnings. */
static bool compiled_cleanly(const char *file, const char *diag)
{
    for (size_t k = 0; k < sizeof expected_warnings / sizeof expected_warnings[0]; k++)
        if (strcmp(expected_warnings[k].file, file) == 0)
            return strcmp(diag, expected_warnings[k].warnings) == 0;
    return diag[0] == '\0';
}

/* Reads `name` from the conformance directory (the #include loader). */
static int load_conformance(sl_source_set *set, const char *name, sl_diag *diag, void *arg)
{
    (void)arg;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", AAFARM_CONFORMANCE_DIR, name);
    FILE *f = fopen(path, "rb");
    if (!f)
        return 1;
    fclose(f);
    return sl_source_set_load_file(set, path, name, diag) == 0 ? 0 : -1;
}

static sl_program *compile_file(const char *name, char **diag_out)
{
    sl_source_set *set = sl_source_set_new();
    sl_source_set_set_loader(set, load_conformance, NULL);
    sl_diag *diag = sl_diag_new();
    sl_program *p = NULL;
    if (sl_source_set_get(set, name, diag))
        p = sl_compile(set, name, NULL, NULL, diag);
    *diag_out = sl_diag_to_string(diag);
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return p;
}

typedef struct tally {
    int floats, duals, derivs, ranges, bounded, samples, failures;
} tally;

static bool close_to(double got, double want)
{
    return fabs(got - want) <= 1e-9 * (1 + fabs(want));
}

static bool inside(ia_interval r, double x)
{
    double tol = 1e-9 * (1 + fabs(x));
    return x >= r.lo - tol && x <= r.hi + tol;
}

static bool run_float(sl_vm *vm, const sl_instance *inst, double u, double v, double P[3])
{
    h_globals_float(vm, H_PLANE, u, v);
    if (sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL) != SL_OK) {
        fprintf(stderr, "%s\n", sl_vm_error(vm));
        return false;
    }
    sl_vm_get_float(vm, SL_G_P, P);
    return true;
}

/* P in dual mode at (u, v): what the renderer's hit points take, with the
 * derivatives the range modes bound (float mode's are 0) */
static bool run_dual_P(sl_vm *vm, const sl_instance *inst, double u, double v, double P[3])
{
    h_globals_dual(vm, H_PLANE, u, v);
    if (sl_vm_run(vm, inst, SL_MODE_DUAL, NULL) != SL_OK) {
        fprintf(stderr, "%s\n", sl_vm_error(vm));
        return false;
    }
    sl_dual D[3];
    sl_vm_get_dual(vm, SL_G_P, D);
    for (int k = 0; k < 3; k++)
        P[k] = D[k].v;
    return true;
}

/* Dual mode at (u, v): the values are the float ones, and each derivative
 * matches central differences of float P where those are stable (two step
 * sizes agree; not across a step or a floor). */
static void check_dual(const conf_case *cc, sl_vm *vm, const sl_instance *inst, double u,
                       double v, const double F[3], tally *t)
{
    sl_dual D[3];
    h_globals_dual(vm, H_PLANE, u, v);
    bool ok = sl_vm_run(vm, inst, SL_MODE_DUAL, NULL) == SL_OK;
    t->duals++;
    if (ok) {
        sl_vm_get_dual(vm, SL_G_P, D);
        for (int k = 0; k < 3; k++)
            ok &= close_to(D[k].v, F[k]);
    }
    for (int dir = 0; ok && dir < 2; dir++) {
        double e1[3], e2[3], Pp[3], Pm[3];
        for (int m = 0; ok && m < 2; m++) {
            double h = m ? 2e-5 : 1e-5;
            ok &= run_float(vm, inst, u + (dir ? 0 : h), v + (dir ? h : 0), Pp) &&
                  run_float(vm, inst, u - (dir ? 0 : h), v - (dir ? h : 0), Pm);
            for (int k = 0; k < 3; k++)
                (m ? e2 : e1)[k] = (Pp[k] - Pm[k]) / (2 * h);
        }
        for (int k = 0; ok && k < 3; k++) {
            if (fabs(e1[k] - e2[k]) > 1e-5 * (1 + fabs(e1[k])))
                continue;           /* not smooth here */
            t->derivs++;
            double d = dir ? D[k].dv : D[k].du;
            ok = fabs(d - e1[k]) <= 1e-4 * (1 + fabs(e1[k]));
            if (!ok)
                fprintf(stderr, "%s: d/d%c of P[%d] at (%.17g, %.17g): dual %.17g, "
                                "differences %.17g\n", cc->file, dir ? 'v' : 'u', k, u, v,
                        d, e1[k]);
        }
    }
    if (!ok) {
        t->failures++;
        fprintf(stderr, "%s: dual mode at (u, v) = (%.17g, %.17g) disagrees\n", cc->file,
                u, v);
    }
}

/* Float values at 7x7 points against the reference; dual mode there. */
static void check_float(const conf_case *cc, sl_vm *vm, const sl_instance *inst, tally *t)
{
    for (int i = 0; i < 7; i++) {
        for (int j = 0; j < 7; j++) {
            double u = 0.05 + 0.9 * (i + 0.31) / 7, v = 0.05 + 0.9 * (j + 0.57) / 7;
            double P[3], want[3];
            t->floats++;
            cc->ref(u, v, want);
            bool ok = run_float(vm, inst, u, v, P);
            for (int k = 0; ok && k < 3; k++)
                ok = close_to(P[k], want[k]);
            if (!ok) {
                t->failures++;
                fprintf(stderr, "%s: at (u, v) = (%.17g, %.17g): P = (%.17g, %.17g, %.17g), "
                                "want (%.17g, %.17g, %.17g)\n", cc->file, u, v, P[0], P[1],
                        P[2], want[0], want[1], want[2]);
            } else if (!cc->no_dual) {
                check_dual(cc, vm, inst, u, v, P, t);
            }
        }
    }
}

/* Interval and affine enclosures over random boxes contain float samples. */
static void check_ranges(const conf_case *cc, sl_vm *vm, const sl_instance *inst, tally *t,
                         unsigned long long *rng)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    for (int r = 0; r < 12; r++) {
        double side = ldexp(1, -2 - (int)(h_rand(rng) * 5));
        double u0 = 0.02 + h_rand(rng) * (0.96 - side), v0 = 0.02 + h_rand(rng) * (0.96 - side);
        double u1 = u0 + side, v1 = v0 + side;
        ia_interval I[3], A[3];
        aa_form a[3];
        t->ranges++;
        h_globals_interval(vm, H_PLANE, u0, u1, v0, v1);
        sl_status st = sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL);
        if (st == SL_OK) {
            sl_vm_get_interval(vm, SL_G_P, I);
            h_globals_affine(vm, &ctx, H_PLANE, u0, u1, v0, v1);
            st = sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx);
        }
        if (st != SL_OK) {
            t->failures++;
            fprintf(stderr, "%s: %s\n", cc->file, sl_vm_error(vm));
            continue;
        }
        sl_vm_get_affine(vm, SL_G_P, a);
        bool bounded = true;
        for (int k = 0; k < 3; k++) {
            A[k] = aa_range(&a[k]);
            bounded &= isfinite(A[k].lo) && isfinite(A[k].hi) && isfinite(I[k].lo) &&
                       isfinite(I[k].hi);
        }
        t->bounded += bounded;
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j < 4; j++) {
                double u = u0 + (u1 - u0) * i / 3, v = v0 + (v1 - v0) * j / 3, P[3];
                t->samples++;
                bool ok = run_dual_P(vm, inst, u, v, P);
                for (int k = 0; ok && k < 3; k++)
                    ok = inside(I[k], P[k]) && inside(A[k], P[k]);
                if (!ok) {
                    t->failures++;
                    fprintf(stderr, "%s: box [%g, %g] x [%g, %g]: sample (%g, %g) outside\n",
                            cc->file, u0, u1, v0, v1, u, v);
                }
            }
        }
    }
}

/* A surface shader on the sphere: Ci and Oi in float mode at 7x7 points
 * against the reference; interval and affine enclosures over 12 random
 * boxes contain the float values at 4x4 points of each. */
static void check_surface(const surface_case *sc, sl_vm *vm, const sl_instance *inst,
                          tally *t, unsigned long long *rng)
{
    for (int i = 0; i < 7; i++) {
        for (int j = 0; j < 7; j++) {
            double u = 0.05 + 0.9 * (i + 0.31) / 7, v = 0.05 + 0.9 * (j + 0.57) / 7;
            double P[3], N[3], du[3], dv[3], C[6], want[6];
            h_surface_float(H_SPHERE, u, v, P, N, du, dv);
            sc->ref(N, want, want + 3);
            h_globals_float(vm, H_SPHERE, u, v);
            t->floats++;
            bool ok = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL) == SL_OK;
            if (ok) {
                sl_vm_get_float(vm, SL_G_Ci, C);
                sl_vm_get_float(vm, SL_G_Oi, C + 3);
            }
            for (int k = 0; ok && k < 6; k++)
                ok = close_to(C[k], want[k]);
            if (!ok) {
                t->failures++;
                fprintf(stderr, "%s: at (u, v) = (%.17g, %.17g): Ci, Oi = (%g %g %g, %g %g "
                                "%g), want (%g %g %g, %g %g %g)\n", sc->file, u, v, C[0], C[1],
                        C[2], C[3], C[4], C[5], want[0], want[1], want[2], want[3], want[4],
                        want[5]);
            }
        }
    }
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    for (int r = 0; r < 12; r++) {
        double side = ldexp(1, -2 - (int)(h_rand(rng) * 5));
        double u0 = 0.02 + h_rand(rng) * (0.96 - side), v0 = 0.02 + h_rand(rng) * (0.96 - side);
        double u1 = u0 + side, v1 = v0 + side;
        ia_interval I[6], A[6];
        aa_form a[6];
        t->ranges++;
        h_globals_interval(vm, H_SPHERE, u0, u1, v0, v1);
        sl_status st = sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL);
        if (st == SL_OK) {
            sl_vm_get_interval(vm, SL_G_Ci, I);
            sl_vm_get_interval(vm, SL_G_Oi, I + 3);
            h_globals_affine(vm, &ctx, H_SPHERE, u0, u1, v0, v1);
            st = sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx);
        }
        if (st != SL_OK) {
            t->failures++;
            fprintf(stderr, "%s: %s\n", sc->file, sl_vm_error(vm));
            continue;
        }
        sl_vm_get_affine(vm, SL_G_Ci, a);
        sl_vm_get_affine(vm, SL_G_Oi, a + 3);
        bool bounded = true;
        for (int k = 0; k < 6; k++) {
            A[k] = aa_range(&a[k]);
            bounded &= isfinite(A[k].lo) && isfinite(A[k].hi) && isfinite(I[k].lo) &&
                       isfinite(I[k].hi);
        }
        t->bounded += bounded;
        if (!bounded)
            fprintf(stderr, "%s: box [%g, %g] x [%g, %g]: unbounded\n", sc->file, u0, u1,
                    v0, v1);
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j < 4; j++) {
                double u = u0 + (u1 - u0) * i / 3, v = v0 + (v1 - v0) * j / 3, C[6];
                t->samples++;
                h_globals_float(vm, H_SPHERE, u, v);
                bool ok = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL) == SL_OK;
                if (ok) {
                    sl_vm_get_float(vm, SL_G_Ci, C);
                    sl_vm_get_float(vm, SL_G_Oi, C + 3);
                }
                for (int k = 0; ok && k < 6; k++)
                    ok = inside(I[k], C[k]) && inside(A[k], C[k]);
                if (!ok) {
                    t->failures++;
                    fprintf(stderr, "%s: box [%g, %g] x [%g, %g]: sample (%g, %g) outside\n",
                            sc->file, u0, u1, v0, v1, u, v);
                }
            }
        }
    }
}

/* The same lights from the renderer's callback: float mode agrees with the
 * fixed lights; interval mode cannot bound them and says so. */
static int callback_lights(void *user, const double P[3], sl_light_sample *out, int max)
{
    (void)user;
    (void)P;
    int n = NSURFACE_LIGHTS < max ? NSURFACE_LIGHTS : max;
    memcpy(out, surface_lights, (size_t)n * sizeof *out);
    return n;
}

static void check_light_callback(const sl_instance *inst, sl_vm *fixed, tally *t)
{
    sl_vm *vm = sl_vm_new(NULL);
    sl_vm_set_lights(vm, callback_lights, NULL);
    double a[3], b[3];
    h_globals_float(vm, H_SPHERE, 0.3, 0.7);
    h_globals_float(fixed, H_SPHERE, 0.3, 0.7);
    t->floats++;
    bool ok = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL) == SL_OK &&
              sl_vm_run(fixed, inst, SL_MODE_FLOAT, NULL) == SL_OK;
    if (ok) {
        sl_vm_get_float(vm, SL_G_Ci, a);
        sl_vm_get_float(fixed, SL_G_Ci, b);
        for (int k = 0; k < 3; k++)
            ok &= close_to(a[k], b[k]);
    }
    h_globals_interval(vm, H_SPHERE, 0.3, 0.31, 0.7, 0.71);
    ok &= sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL) == SL_ERR_RUNTIME &&
          strstr(sl_vm_error(vm), "illuminance at") != NULL;
    if (!ok) {
        t->failures++;
        fprintf(stderr, "illuminance with a light callback: %s\n", sl_vm_error(vm));
    }
    sl_vm_destroy(&vm);
}

/* Message passing from the displacement shader to the surface shader run
 * next on the same VM: the outputs captured after the float run are what
 * displacement("name", x) reads; a range run reads them as unbounded. */
static void check_message_passing(sl_vm *vm, tally *t)
{
    char *d1 = NULL, *d2 = NULL;
    sl_program *disp = compile_file("message_height.sl", &d1);
    sl_program *surf = compile_file("surface_message.sl", &d2);
    bool ok = disp && surf && !d1[0] && !d2[0];
    free(d1);
    free(d2);
    sl_instance *di = disp ? sl_instance_new(disp) : NULL;
    sl_instance *si = surf ? sl_instance_new(surf) : NULL;
    for (int k = 0; ok && k < 5; k++) {
        double u = 0.1 + 0.17 * k, v = 0.8 - 0.13 * k, C[3];
        double h = 0.1 * sin(u * 6) * cos(v * 4);
        double want[3] = { u + h, v + 2, h };
        t->floats++;
        h_globals_float(vm, H_PLANE, u, v);
        ok = sl_vm_run(vm, di, SL_MODE_FLOAT, NULL) == SL_OK &&
             sl_vm_capture_outputs(vm, SL_MSG_DISPLACEMENT) == 2;
        h_globals_float(vm, H_SPHERE, u, v);
        ok = ok && sl_vm_run(vm, si, SL_MODE_FLOAT, NULL) == SL_OK;
        if (ok)
            sl_vm_get_float(vm, SL_G_Ci, C);
        for (int i = 0; ok && i < 3; i++)
            ok = close_to(C[i], want[i]);
    }
    if (ok) {                       /* a range run: unbounded, not wrong */
        ia_interval I[3];
        h_globals_interval(vm, H_SPHERE, 0.3, 0.35, 0.3, 0.35);
        ok = sl_vm_run(vm, si, SL_MODE_INTERVAL, NULL) == SL_OK;
        sl_vm_get_interval(vm, SL_G_Ci, I);
        for (int i = 0; ok && i < 3; i++)
            ok = !isfinite(I[i].lo) && !isfinite(I[i].hi);
    }
    if (ok) {                       /* no displacement outputs: the defaults */
        double C[3];
        sl_vm_clear_messages(vm, SL_MSG_DISPLACEMENT);
        h_globals_float(vm, H_SPHERE, 0.5, 0.5);
        ok = sl_vm_run(vm, si, SL_MODE_FLOAT, NULL) == SL_OK;
        sl_vm_get_float(vm, SL_G_Ci, C);
        ok = ok && C[0] == -1 && C[1] == 0 && C[2] == 0;
    }
    if (!ok) {
        t->failures++;
        fprintf(stderr, "message passing from message_height.sl to surface_message.sl fails\n");
    }
    sl_instance_destroy(&di);
    sl_instance_destroy(&si);
    sl_program_destroy(&disp);
    sl_program_destroy(&surf);
}

/* Light shaders (sl_light_eval) at points of the plane against their
 * formulas, and the point light feeding surface_illuminance_diffuse.sl
 * through a light callback. */
typedef struct light_case {
    const char *file;
    const char *param;          /* one parameter set besides the defaults */
    double value[3];
} light_case;

static sl_instance *light_instance(const char *file, tally *t)
{
    char *diag = NULL;
    sl_program *p = compile_file(file, &diag);
    if (!p || diag[0]) {
        t->failures++;
        fprintf(stderr, "%s: does not compile cleanly:\n%s", file, diag);
    }
    free(diag);
    return p ? sl_instance_new(p) : NULL;
}

static void free_light(sl_instance **inst)
{
    if (!*inst)
        return;
    sl_program *p = (sl_program *)sl_instance_program(*inst);
    sl_instance_destroy(inst);
    sl_program_destroy(&p);
}

static void set_param(sl_instance *inst, const char *name, sl_type type, const double *v, int n)
{
    char why[256];
    assert_true(sl_instance_set(inst, name, type, v, n, why, sizeof why));
}

typedef struct light_ctx {
    sl_vm *vm;
    sl_instance *lights[2];
} light_ctx;

static int shader_lights(void *user, const double P[3], sl_light_sample *out, int max)
{
    light_ctx *lc = user;
    int n = 0;
    for (int i = 0; i < 2 && n < max; i++)
        if (sl_light_eval(lc->vm, lc->lights[i], P, &out[n]) == SL_OK)
            n++;
    return n;
}

static void check_light_shaders(tally *t)
{
    sl_vm *lvm = sl_vm_new(NULL);
    sl_instance *point = light_instance("light_point.sl", t);
    sl_instance *spot = light_instance("light_spot.sl", t);
    sl_instance *distant = light_instance("light_distant.sl", t);
    sl_instance *ambient = light_instance("light_ambient.sl", t);
    if (!point || !spot || !distant || !ambient)
        goto done;
    double two = 2, tenth = 0.1, lc[3] = { 1, 0.5, 0.25 }, from[3] = { 0, 0, 2 };
    double origin[3] = { 0, 0, 0 }, dir[3] = { 1, 0, -1 };
    set_param(point, "intensity", SL_TYPE_FLOAT, &two, 1);
    set_param(point, "lightcolor", SL_TYPE_COLOR, lc, 3);
    set_param(point, "from", SL_TYPE_POINT, from, 3);
    set_param(spot, "from", SL_TYPE_POINT, from, 3);
    set_param(spot, "to", SL_TYPE_POINT, origin, 3);
    double cone = M_PI / 9;                      /* 20 degrees */
    set_param(spot, "coneangle", SL_TYPE_FLOAT, &cone, 1);
    set_param(distant, "to", SL_TYPE_POINT, dir, 3);
    set_param(ambient, "intensity", SL_TYPE_FLOAT, &tenth, 1);
    int lit = 0;
    for (int i = 0; i < 7; i++) {
        for (int j = 0; j < 7; j++) {
            double u = 0.05 + 0.9 * (i + 0.31) / 7, v = 0.05 + 0.9 * (j + 0.57) / 7;
            double Ps[3] = { 2 * u - 1, 2 * v - 1, 0 }, want[4][7];
            /* point: L towards "from", Cl = 2 lc / |from - Ps|^2 */
            double Lp[3] = { -Ps[0], -Ps[1], 2 - Ps[2] }, d2 = dot3(Lp, Lp);
            /* spot: axis (0, 0, -1), cone 20 degrees, smooth over the last 5 */
            double Ls[3] = { Ps[0], Ps[1], Ps[2] - 2 }, ca = -Ls[2] / sqrt(dot3(Ls, Ls));
            bool in = ca >= cos(cone);
            double spot_cl = in ? pow(ca, 2) / dot3(Ls, Ls) *
                                  smooth(cos(cone), cos(cone - M_PI / 36), ca) : 0;
            lit += in;
            for (int k = 0; k < 3; k++) {
                want[0][k] = Lp[k];
                want[0][3 + k] = 2 * lc[k] / d2;
                want[1][k] = -Ls[k];
                want[1][3 + k] = spot_cl;
                want[2][k] = -dir[k];
                want[2][3 + k] = 1;
                want[3][3 + k] = 0.1;
            }
            want[0][6] = want[1][6] = want[2][6] = 0;
            want[3][6] = 1;
            sl_instance *insts[4] = { point, spot, distant, ambient };
            for (int l = 0; l < 4; l++) {
                sl_light_sample ls;
                t->floats++;
                bool ok = sl_light_eval(lvm, insts[l], Ps, &ls) == SL_OK;
                for (int k = 0; ok && k < 3; k++)
                    ok = (l == 3 || close_to(ls.L[k], want[l][k])) &&
                         close_to(ls.Cl[k], want[l][3 + k]);
                ok = ok && ls.ambient == (want[l][6] == 1);
                if (!ok) {
                    t->failures++;
                    fprintf(stderr, "light shader %d at Ps = (%g, %g, %g): L (%g %g %g), Cl "
                                    "(%g %g %g)\n", l, Ps[0], Ps[1], Ps[2], ls.L[0], ls.L[1],
                            ls.L[2], ls.Cl[0], ls.Cl[1], ls.Cl[2]);
                }
            }
        }
    }
    if (lit == 0 || lit == 49) {      /* the spot's cone must cut the samples */
        t->failures++;
        fprintf(stderr, "light_spot.sl: %d of 49 points lit\n", lit);
    }
    /* the point and ambient lights through a callback, for the diffuse loop */
    char *diag = NULL;
    sl_program *sp = compile_file("surface_illuminance_diffuse.sl", &diag);
    free(diag);
    if (!sp) {
        t->failures++;
        goto done;
    }
    sl_instance *si = sl_instance_new(sp);
    sl_vm *vm = sl_vm_new(NULL);
    light_ctx ctx = { lvm, { point, ambient } };
    sl_vm_set_lights(vm, shader_lights, &ctx);
    for (int k = 0; k < 5; k++) {
        double u = 0.1 + 0.19 * k, v = 0.7 - 0.11 * k, P[3], N[3], du[3], dv[3], Nf[3], C[3];
        h_surface_float(H_SPHERE, u, v, P, N, du, dv);
        facing(N, Nf);
        double L[3] = { -P[0], -P[1], 2 - P[2] }, d2 = dot3(L, L), Ln[3] = { L[0], L[1], L[2] };
        normalize3(Ln);
        double d = dot3(Ln, Nf);
        h_globals_float(vm, H_SPHERE, u, v);
        t->floats++;
        bool ok = sl_vm_run(vm, si, SL_MODE_FLOAT, NULL) == SL_OK;
        sl_vm_get_float(vm, SL_G_Ci, C);
        for (int c = 0; ok && c < 3; c++)
            ok = close_to(C[c], d >= 0 ? 0.8 * 2 * lc[c] / d2 * d : 0);
        if (!ok) {
            t->failures++;
            fprintf(stderr, "surface_illuminance_diffuse.sl under light_point.sl at (%g, %g): "
                            "%s\n", u, v, sl_vm_error(vm));
        }
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&si);
    sl_program_destroy(&sp);
done:
    free_light(&point);
    free_light(&spot);
    free_light(&distant);
    free_light(&ambient);
    sl_vm_destroy(&lvm);
}

static void print_to_file(void *ctx, const char *text)
{
    fputs(text, ctx);
}

/* printf_rate_limit.sl run 150 times in float mode (and in interval mode,
 * which prints nothing) on a VM of its own whose print callback writes to
 * a file: 100 lines, then one note, and the values are unaffected. */
static void check_printf_limit(tally *t)
{
    char *diag = NULL;
    sl_program *p = compile_file("printf_rate_limit.sl", &diag);
    free(diag);
    if (!p) {
        t->failures++;
        fprintf(stderr, "printf_rate_limit.sl: does not compile\n");
        return;
    }
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    FILE *log = tmpfile();
    assert_non_null(log);
    sl_vm_set_print(vm, print_to_file, log);
    int wrong = 0;
    for (int i = 0; i < 150; i++) {
        double u = (i + 0.5) / 150, v = 1 - u, P[3];
        t->floats++;
        if (!run_float(vm, inst, u, v, P) || !close_to(P[0], u) || !close_to(P[1], v) ||
            P[2] != 1)
            wrong++;
        if (i % 15 == 0) {
            h_globals_interval(vm, H_PLANE, u, u + 0.01, v, v + 0.01);
            wrong += sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL) != SL_OK;
        }
    }
    rewind(log);
    char line[256];
    int lines = 0, notes = 0;
    while (fgets(line, sizeof line, log)) {
        if (strncmp(line, "printf_rate_limit: s = ", 23) == 0)
            lines++;
        else if (strstr(line, "more than 100 printf lines; the rest are not shown"))
            notes++;
        else
            wrong++;
    }
    fclose(log);
    if (wrong || lines != 100 || notes != 1) {
        t->failures++;
        fprintf(stderr, "printf_rate_limit.sl: %d lines and %d notes logged (want 100 and 1), "
                        "%d wrong values or other lines\n", lines, notes, wrong);
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_conformance(void **state)
{
    (void)state;
    tally t = { 0, 0, 0, 0, 0, 0, 0 };
    unsigned long long rng = 0x5eed15ULL;
    sl_vm *vm = sl_vm_new(NULL);
    /* "object" -> "current": scale by 2, then translate by (1, 2, 3) */
    sl_spaces sp;
    for (int k = 0; k < SL_SPACE__COUNT; k++)
        sp.to_current[k] = sp.from_current[k] = mat4_identity();
    sp.to_current[SL_SPACE_OBJECT] = mat4_mul(mat4_translate(1, 2, 3), mat4_scale(2, 2, 2));
    mat4_invert(&sp.to_current[SL_SPACE_OBJECT], &sp.from_current[SL_SPACE_OBJECT]);
    sl_vm_set_spaces(vm, &sp);
    sl_vm_set_clipping(vm, 0.5, 10.5);
    mat4 persp = sl_projection_perspective(90, 1, 11);
    const double window[4] = { -1.5, 1.5, -1, 1 };
    sl_vm_set_projection(vm, &persp, window, 300, 200);
    double bound = 0.25, freq = 3, tint[3] = { 0.1, 0.2, 0.3 };
    assert_true(sl_vm_set_message(vm, SL_MSG_ATTRIBUTE, "displacementbound:sphere",
                                  SL_TYPE_FLOAT, &bound, NULL));
    assert_true(sl_vm_set_message(vm, SL_MSG_OPTION, "user:frequency", SL_TYPE_FLOAT, &freq,
                                  NULL));
    assert_true(sl_vm_set_message(vm, SL_MSG_ATTRIBUTE, "user:tint", SL_TYPE_COLOR, tint, NULL));
    const char *features[64];
    int nfeatures = 0;
    size_t ncases = sizeof cases / sizeof cases[0];
    for (size_t c = 0; c < ncases; c++) {
        const conf_case *cc = &cases[c];
        bool seen = false;
        for (int f = 0; f < nfeatures; f++)
            seen |= strcmp(features[f], cc->feature) == 0;
        if (!seen && nfeatures < 64)
            features[nfeatures++] = cc->feature;
        char *diag = NULL;
        sl_program *p = compile_file(cc->file, &diag);
        if (!p || !compiled_cleanly(cc->file, diag)) {
            t.failures++;
            fprintf(stderr, "%s: does not compile cleanly:\n%s", cc->file, diag);
        }
        free(diag);
        if (!p)
            continue;
        sl_instance *inst = sl_instance_new(p);
        check_float(cc, vm, inst, &t);
        check_ranges(cc, vm, inst, &t, &rng);
        sl_instance_destroy(&inst);
        sl_program_destroy(&p);
    }
    size_t nsurfaces = sizeof surface_cases / sizeof surface_cases[0];
    sl_vm_set_fixed_lights(vm, surface_lights, NSURFACE_LIGHTS);
    if (nfeatures < 64)
        features[nfeatures++] = "illuminance (surface shaders)";
    if (nfeatures < 64)
        features[nfeatures++] = "light shaders (illuminate, solar)";
    for (size_t c = 0; c < nsurfaces; c++) {
        char *diag = NULL;
        sl_program *p = compile_file(surface_cases[c].file, &diag);
        if (!p || !compiled_cleanly(surface_cases[c].file, diag)) {
            t.failures++;
            fprintf(stderr, "%s: does not compile cleanly:\n%s", surface_cases[c].file, diag);
        }
        free(diag);
        if (!p)
            continue;
        sl_instance *inst = sl_instance_new(p);
        check_surface(&surface_cases[c], vm, inst, &t, &rng);
        if (c == 0)
            check_light_callback(inst, vm, &t);
        sl_instance_destroy(&inst);
        sl_program_destroy(&p);
    }
    check_message_passing(vm, &t);
    check_light_shaders(&t);
    check_printf_limit(&t);
    if (nfeatures < 64)
        features[nfeatures++] = "printf's rate limit";
    size_t nerrors = sizeof errors / sizeof errors[0];
    for (size_t e = 0; e < nerrors; e++) {
        char *diag = NULL;
        sl_program *p = compile_file(errors[e].file, &diag);
        if (p || strcmp(diag, errors[e].expected) != 0) {
            t.failures++;
            fprintf(stderr, "%s: --- got:\n%s--- expected:\n%s", errors[e].file, diag,
                    errors[e].expected);
        }
        sl_program_destroy(&p);
        free(diag);
    }
    sl_vm_destroy(&vm);
    printf("conformance: %zu shaders: %zu displacement, %zu surface and 4 light shaders, a "
           "displacement-to-surface message pair, the printf limit and %zu error cases; "
           "features:", ncases + nsurfaces + 4 + 2 + 1 + nerrors, ncases, nsurfaces, nerrors);
    for (int f = 0; f < nfeatures; f++)
        printf("%s %s", f ? "," : "", features[f]);
    printf("\nconformance: %d float checks, %d dual checks (%d derivatives against "
           "differences), %d ranges (interval and affine; %d of them bounded) with %d "
           "samples, %zu diagnostics; %d failures\n", t.floats, t.duals, t.derivs, t.ranges,
           t.bounded, t.samples, nerrors, t.failures);
    assert_int_equal(t.failures, 0);
    assert_int_equal(t.bounded, t.ranges);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_conformance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

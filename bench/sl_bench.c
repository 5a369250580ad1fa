/*
 * sl_bench: evaluations per second of the library shaders (scenes/shaders)
 * in the four modes of the shading-language VM, and the price of the VM
 * against its peer: a hand-written C version of the wave shader in float
 * mode, the same formula compiled by the C compiler.
 *
 *   sl_bench [--quick] [--only NAME] [--affine-only | --mode M] [SHADER_DIR]
 *
 * --only NAME runs one library shader; --affine-only times float and affine
 * only (the ratio the issue 24 aim is about); --mode M (0 float, 1 dual,
 * 2 interval, 3 affine) times one mode alone, for `perf record`.
 *
 * Displacement shaders run on the plane P = (2u-1, 2v-1, 0), surface
 * shaders on the unit sphere, with (u, v) moving every evaluation; the
 * globals are set before each run, as the renderer does. Interval and
 * affine runs cover (u, v) boxes of side 1/64. It prints a table; it never
 * passes or fails on time.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "aa/affine.h"
#include "sl/diag.h"
#include "sl/shader.h"
#include "sl/source.h"

#ifndef AAFARM_SHADER_DIR
#define AAFARM_SHADER_DIR "scenes/shaders"
#endif

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static sl_program *load(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.sl", dir, name);
    sl_source_set *set = sl_source_set_new();
    sl_diag *diag = sl_diag_new();
    sl_program *p = NULL;
    if (sl_source_set_load_file(set, path, NULL, diag) == 0)
        p = sl_compile(set, path, NULL, NULL, diag);
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return p;
}

/* ---- globals of the two base surfaces at (u, v) / over a box ---- */

static void surface_at(bool sphere, double u, double v, double P[3], double N[3])
{
    if (!sphere) {
        P[0] = 2 * u - 1; P[1] = 2 * v - 1; P[2] = 0;
        N[0] = 0; N[1] = 0; N[2] = 1;
        return;
    }
    double th = 2 * M_PI * u, ph = M_PI * v - M_PI / 2;
    P[0] = cos(th) * cos(ph); P[1] = sin(th) * cos(ph); P[2] = sin(ph);
    memcpy(N, P, 3 * sizeof *P);
}

static void set_float(sl_vm *vm, bool sphere, double u, double v)
{
    double P[3], N[3], one[3] = { 1, 1, 1 }, I[3] = { 0, 0, 1 };
    surface_at(sphere, u, v, P, N);
    sl_vm_clear_globals(vm);
    sl_vm_set_float(vm, SL_G_P, P);
    sl_vm_set_float(vm, SL_G_N, N);
    sl_vm_set_float(vm, SL_G_Ng, N);
    sl_vm_set_float(vm, SL_G_I, I);
    sl_vm_set_float(vm, SL_G_u, &u);
    sl_vm_set_float(vm, SL_G_v, &v);
    sl_vm_set_float(vm, SL_G_s, &u);
    sl_vm_set_float(vm, SL_G_t, &v);
    sl_vm_set_float(vm, SL_G_Cs, one);
    sl_vm_set_float(vm, SL_G_Os, one);
}

static void set_dual(sl_vm *vm, bool sphere, double u, double v)
{
    double P[3], N[3], Pu[3], Pv[3], h = 1e-7, a[3], b[3];
    surface_at(sphere, u, v, P, N);
    surface_at(sphere, u + h, v, a, b);
    for (int i = 0; i < 3; i++)
        Pu[i] = (a[i] - P[i]) / h;
    surface_at(sphere, u, v + h, a, b);
    for (int i = 0; i < 3; i++)
        Pv[i] = (a[i] - P[i]) / h;
    sl_dual dP[3], dN[3], du = { u, 1, 0 }, dv = { v, 0, 1 }, one[3], I[3];
    for (int i = 0; i < 3; i++) {
        dP[i] = (sl_dual){ P[i], Pu[i], Pv[i] };
        dN[i] = sphere ? dP[i] : (sl_dual){ N[i], 0, 0 };
        one[i] = (sl_dual){ 1, 0, 0 };
        I[i] = (sl_dual){ i == 2, 0, 0 };
    }
    sl_vm_clear_globals(vm);
    sl_vm_set_dual(vm, SL_G_P, dP);
    sl_vm_set_dual(vm, SL_G_N, dN);
    sl_vm_set_dual(vm, SL_G_Ng, dN);
    sl_vm_set_dual(vm, SL_G_I, I);
    sl_vm_set_dual(vm, SL_G_u, &du);
    sl_vm_set_dual(vm, SL_G_v, &dv);
    sl_vm_set_dual(vm, SL_G_s, &du);
    sl_vm_set_dual(vm, SL_G_t, &dv);
    sl_vm_set_dual(vm, SL_G_Cs, one);
    sl_vm_set_dual(vm, SL_G_Os, one);
}

static void set_interval(sl_vm *vm, bool sphere, double u0, double u1, double v0, double v1)
{
    ia_interval U = ia_make(u0, u1), V = ia_make(v0, v1), P[3], N[3];
    ia_interval one[3] = { ia_point(1), ia_point(1), ia_point(1) };
    ia_interval I[3] = { ia_point(0), ia_point(0), ia_point(1) };
    if (!sphere) {
        P[0] = ia_add_s(ia_mul_s(U, 2), -1);
        P[1] = ia_add_s(ia_mul_s(V, 2), -1);
        P[2] = ia_point(0);
        N[0] = ia_point(0); N[1] = ia_point(0); N[2] = ia_point(1);
    } else {
        ia_interval th = ia_mul_s(U, 2 * M_PI), ph = ia_add_s(ia_mul_s(V, M_PI), -M_PI / 2);
        P[0] = ia_mul(ia_cos(th), ia_cos(ph));
        P[1] = ia_mul(ia_sin(th), ia_cos(ph));
        P[2] = ia_sin(ph);
        memcpy(N, P, sizeof P);
    }
    sl_vm_clear_globals(vm);
    sl_vm_set_interval(vm, SL_G_P, P);
    sl_vm_set_interval(vm, SL_G_N, N);
    sl_vm_set_interval(vm, SL_G_Ng, N);
    sl_vm_set_interval(vm, SL_G_I, I);
    sl_vm_set_interval(vm, SL_G_u, &U);
    sl_vm_set_interval(vm, SL_G_v, &V);
    sl_vm_set_interval(vm, SL_G_s, &U);
    sl_vm_set_interval(vm, SL_G_t, &V);
    sl_vm_set_interval(vm, SL_G_Cs, one);
    sl_vm_set_interval(vm, SL_G_Os, one);
}

static void set_affine(sl_vm *vm, aa_context *ctx, bool sphere, double u0, double u1,
                       double v0, double v1)
{
    aa_form U, V, P[3], N[3], one[3], I[3];
    aa_context_reset(ctx);
    aa_input(ctx, &U, u0, u1);
    aa_input(ctx, &V, v0, v1);
    if (!sphere) {
        aa_lincomb(ctx, &P[0], 2, &U, 0, NULL, -1);
        aa_lincomb(ctx, &P[1], 2, &V, 0, NULL, -1);
        aa_const(&P[2], 0);
        aa_const(&N[0], 0); aa_const(&N[1], 0); aa_const(&N[2], 1);
    } else {
        aa_form th, ph, ct, st, cp;
        aa_mul_s(ctx, &th, &U, 2 * M_PI);
        aa_lincomb(ctx, &ph, M_PI, &V, 0, NULL, -M_PI / 2);
        aa_cos(ctx, &ct, &th);
        aa_sin(ctx, &st, &th);
        aa_cos(ctx, &cp, &ph);
        aa_mul(ctx, &P[0], &ct, &cp);
        aa_mul(ctx, &P[1], &st, &cp);
        aa_sin(ctx, &P[2], &ph);
        memcpy(N, P, sizeof P);
    }
    for (int i = 0; i < 3; i++) {
        aa_const(&one[i], 1);
        aa_const(&I[i], i == 2);
    }
    sl_vm_clear_globals(vm);
    sl_vm_set_affine(vm, SL_G_P, P);
    sl_vm_set_affine(vm, SL_G_N, N);
    sl_vm_set_affine(vm, SL_G_Ng, N);
    sl_vm_set_affine(vm, SL_G_I, I);
    sl_vm_set_affine(vm, SL_G_u, &U);
    sl_vm_set_affine(vm, SL_G_v, &V);
    sl_vm_set_affine(vm, SL_G_s, &U);
    sl_vm_set_affine(vm, SL_G_t, &V);
    sl_vm_set_affine(vm, SL_G_Cs, one);
    sl_vm_set_affine(vm, SL_G_Os, one);
}

/* ---- measuring ---- */

typedef struct result {
    double per_second;
    long instructions;
} result;

static volatile double sink;

/* Runs `inst` in `mode` for about `seconds`; evaluations per second. */
static result measure(sl_vm *vm, const sl_instance *inst, sl_mode mode, bool sphere,
                      double seconds)
{
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    result r = { 0, 0 };
    long n = 0;
    double start = now(), elapsed = 0;
    const double w = 1.0 / 64;
    unsigned k = 0;
    do {
        for (int batch = 0; batch < 64; batch++, k++) {
            double u = ((k * 37) % 61) / 64.0 + w / 2, v = ((k * 53) % 59) / 64.0 + w / 2;
            switch (mode) {
            case SL_MODE_FLOAT: set_float(vm, sphere, u, v); break;
            case SL_MODE_DUAL: set_dual(vm, sphere, u, v); break;
            case SL_MODE_INTERVAL: set_interval(vm, sphere, u - w / 2, u + w / 2, v - w / 2, v + w / 2); break;
            case SL_MODE_AFFINE: set_affine(vm, &ctx, sphere, u - w / 2, u + w / 2, v - w / 2, v + w / 2); break;
            }
            if (sl_vm_run(vm, inst, mode, &ctx) != SL_OK) {
                fprintf(stderr, "%s\n", sl_vm_error(vm));
                return r;
            }
            r.instructions = sl_vm_instructions(vm);
            n++;
        }
        elapsed = now() - start;
    } while (elapsed < seconds);
    r.per_second = (double)n / elapsed;
    return r;
}

/* The peer: wave.sl written by hand in C (default parameters). */
static void wave_c(double u, double v, double P[3], double N[3])
{
    const double Km = 0.1, frequency = 4, decay = 2, phase = 0, sc = 0.5, tc = 0.5;
    double ds = u - sc, dt = v - tc;
    double r = sqrt(ds * ds + dt * dt);
    double h = Km * exp(-decay * r) * sin(2 * M_PI * frequency * r + phase);
    double l = 1.0 / sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    for (int i = 0; i < 3; i++)
        P[i] += h * N[i] * l;
}

static double measure_peer(double seconds)
{
    long n = 0;
    double start = now(), elapsed;
    unsigned k = 0;
    do {
        for (int batch = 0; batch < 4096; batch++, k++) {
            double u = ((k * 37) % 61) / 64.0, v = ((k * 53) % 59) / 64.0;
            double P[3], N[3];
            surface_at(false, u, v, P, N);
            wave_c(u, v, P, N);
            sink = P[2];
            n++;
        }
        elapsed = now() - start;
    } while (elapsed < seconds);
    return (double)n / elapsed;
}

int main(int argc, char **argv)
{
    bool quick = false, affine_only = false;
    int only_mode = -1;
    const char *dir = AAFARM_SHADER_DIR, *only = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = true;
        else if (strcmp(argv[i], "--affine-only") == 0)
            affine_only = true;
        else if (strcmp(argv[i], "--mode") == 0 && i + 1 < argc)
            only_mode = atoi(argv[++i]);
        else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (strcmp(argv[i], "--help") == 0) {
            printf("usage: sl_bench [--quick] [--only NAME] [--affine-only | --mode 0-3] [SHADER_DIR]\n");
            return 0;
        } else
            dir = argv[i];
    }
    double seconds = quick ? 0.05 : 0.5;
    static const char *const shaders[] = {
        "wave", "nail", "ufo", "threads", "dented", "lumpy",
        "matte", "plastic", "metal", "wood", "granite",
    };
    static const char *const modes[] = { "float", "dual", "interval", "affine" };
    sl_light_sample lights[2] = {
        { { 0, 0, 0 }, { 0.2, 0.2, 0.2 }, true, false },
        { { 1, 2, -2 }, { 0.8, 0.7, 0.6 }, false, true },
    };
    printf("sl_bench: evaluations per second (thousands) and instructions per evaluation\n"
           "(displacement shaders on the plane, surface shaders on the sphere; interval and\n"
           "affine over (u,v) boxes of side 1/64, AA capacity %d)\n\n", AA_DEFAULT_CAPACITY);
    printf("%-9s %6s", "shader", "instr");
    for (int m = 0; m < 4; m++)
        printf(" %10s", modes[m]);
    printf("  %s\n", "affine/float cost");
    double wave_float = 0;
    for (size_t s = 0; s < sizeof shaders / sizeof shaders[0]; s++) {
        if (only && strcmp(only, shaders[s]) != 0)
            continue;
        sl_program *p = load(dir, shaders[s]);
        if (!p) {
            fprintf(stderr, "sl_bench: cannot compile %s\n", shaders[s]);
            return 1;
        }
        bool sphere = sl_program_kind(p) == SL_SHADER_SURFACE;
        sl_instance *inst = sl_instance_new(p);
        sl_vm *vm = sl_vm_new(NULL);
        sl_vm_set_fixed_lights(vm, lights, 2);
        result r[4];
        for (int m = 0; m < 4; m++)
            r[m] = (affine_only && m != 0 && m != 3) || (only_mode >= 0 && m != only_mode)
                       ? (result){ 0, 0 }
                       : measure(vm, inst, (sl_mode)m, sphere, seconds);
        printf("%-9s %6ld", shaders[s], r[0].instructions);
        for (int m = 0; m < 4; m++)
            printf(" %10.1f", r[m].per_second / 1e3);
        if (r[0].per_second > 0 && r[3].per_second > 0)
            printf("  %.1fx\n", r[0].per_second / r[3].per_second);
        else
            printf("\n");
        if (strcmp(shaders[s], "wave") == 0)
            wave_float = r[0].per_second;
        sl_vm_destroy(&vm);
        sl_instance_destroy(&inst);
        sl_program_destroy(&p);
    }
    if (wave_float == 0)
        return 0;
    double peer = measure_peer(seconds);
    printf("\npeer: wave written in C, float: %.1f thousand evaluations per second;\n"
           "the VM's float mode runs wave at %.3f of that speed (%.1fx slower)\n",
           peer / 1e3, wave_float / peer, peer / wave_float);
    printf("(the VM's times include setting the globals, as the renderer does; the\n"
           "peer computes the same surface point and displacement in straight C)\n");
    return 0;
}

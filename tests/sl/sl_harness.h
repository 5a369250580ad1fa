/*
 * sl_harness.h: helpers shared by the shading-language tests: compile a
 * source held in memory or a library shader from scenes/shaders, set up
 * the two base surfaces of the bound tests (the plane P = (2u-1, 2v-1, 0)
 * and the unit sphere with RenderMan's parameterisation) in all four
 * arithmetics, and run a program.
 *
 * Everything is static inline so that each test includes what it uses.
 */
#ifndef SL_HARNESS_H
#define SL_HARNESS_H

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "sl/diag.h"
#include "sl/shader.h"
#include "sl/source.h"

#ifndef AAFARM_SHADER_DIR
#define AAFARM_SHADER_DIR "scenes/shaders"
#endif

/* Compiles `text` as file `name`; NULL on errors. *diag_out (if not NULL)
 * receives the rendered diagnostics (caller frees). */
static inline sl_program *h_compile_named(const char *name, const char *text, char **diag_out)
{
    sl_source_set *set = sl_source_set_new();
    sl_diag *diag = sl_diag_new();
    sl_source_set_add(set, name, text, strlen(text));
    sl_program *p = sl_compile(set, name, NULL, NULL, diag);
    if (diag_out)
        *diag_out = sl_diag_to_string(diag);
    else if (!p)
        sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return p;
}

static inline sl_program *h_compile(const char *text) { return h_compile_named("t.sl", text, NULL); }

/* One shader's test set-up: the program compiled from text, an instance
 * with its defaults, a VM and an affine context of the default capacity
 * (h_session_close frees them) */
typedef struct h_session {
    sl_program *p;
    sl_instance *inst;
    sl_vm *vm;
    aa_context ctx;
} h_session;

static inline void h_session_open(h_session *h, const char *text)
{
    h->p = h_compile(text);
    assert_non_null(h->p);
    h->inst = sl_instance_new(h->p);
    h->vm = sl_vm_new(NULL);
    aa_context_init(&h->ctx, AA_DEFAULT_CAPACITY);
}

static inline void h_session_close(h_session *h)
{
    sl_vm_destroy(&h->vm);
    sl_instance_destroy(&h->inst);
    sl_program_destroy(&h->p);
}

/* The first instruction of opcode op at or after pc `from`, or -1 (the
 * tests that read the code include sl/bytecode.h before the harness) */
#ifdef SL_BYTECODE_H
static inline int h_find_op(const sl_program *p, int op, int from)
{
    for (int pc = from; pc < p->ncode; pc++)
        if (p->code[pc].op == op)
            return pc;
    return -1;
}
#endif

/* Compiles scenes/shaders/<name>.sl from disk. */
static inline sl_program *h_compile_library(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.sl", AAFARM_SHADER_DIR, name);
    sl_source_set *set = sl_source_set_new();
    sl_diag *diag = sl_diag_new();
    sl_program *p = NULL;
    if (sl_source_set_load_file(set, path, "lib.sl", diag) == 0)
        p = sl_compile(set, "lib.sl", NULL, NULL, diag);
    if (!p)
        sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    sl_source_set_destroy(&set);
    return p;
}

/* ---- base surfaces ---- */

typedef enum { H_PLANE, H_SPHERE } h_surface;

/* Float: P, N (unit), dPdu, dPdv at (u, v). */
static inline void h_surface_float(h_surface s, double u, double v, double P[3], double N[3],
                                   double dPdu[3], double dPdv[3])
{
    if (s == H_PLANE) {
        P[0] = 2 * u - 1; P[1] = 2 * v - 1; P[2] = 0;
        N[0] = 0; N[1] = 0; N[2] = 1;
        dPdu[0] = 2; dPdu[1] = 0; dPdu[2] = 0;
        dPdv[0] = 0; dPdv[1] = 2; dPdv[2] = 0;
        return;
    }
    /* RenderMan sphere, radius 1: theta = 2 pi u, phi = -pi/2 + pi v */
    double th = 2 * M_PI * u, ph = M_PI * v - M_PI / 2;
    P[0] = cos(th) * cos(ph); P[1] = sin(th) * cos(ph); P[2] = sin(ph);
    N[0] = P[0]; N[1] = P[1]; N[2] = P[2];
    dPdu[0] = -2 * M_PI * sin(th) * cos(ph); dPdu[1] = 2 * M_PI * cos(th) * cos(ph); dPdu[2] = 0;
    dPdv[0] = -M_PI * cos(th) * sin(ph); dPdv[1] = -M_PI * sin(th) * sin(ph);
    dPdv[2] = M_PI * cos(ph);
}

/* Sets the float globals of a displacement run at (u, v). */
static inline void h_globals_float(sl_vm *vm, h_surface s, double u, double v)
{
    double P[3], N[3], du[3], dv[3];
    h_surface_float(s, u, v, P, N, du, dv);
    sl_vm_clear_globals(vm);
    sl_vm_set_float(vm, SL_G_P, P);
    sl_vm_set_float(vm, SL_G_N, N);
    sl_vm_set_float(vm, SL_G_Ng, N);
    sl_vm_set_float(vm, SL_G_dPdu, du);
    sl_vm_set_float(vm, SL_G_dPdv, dv);
    sl_vm_set_float(vm, SL_G_u, &u);
    sl_vm_set_float(vm, SL_G_v, &v);
    sl_vm_set_float(vm, SL_G_s, &u);
    sl_vm_set_float(vm, SL_G_t, &v);
    double one[3] = { 1, 1, 1 }, I[3] = { 0, 0, 1 };
    sl_vm_set_float(vm, SL_G_Cs, one);
    sl_vm_set_float(vm, SL_G_Os, one);
    sl_vm_set_float(vm, SL_G_I, I);
}

/* Dual globals: derivatives with respect to u and v. */
static inline void h_globals_dual(sl_vm *vm, h_surface s, double u, double v)
{
    double P[3], N[3], du[3], dv[3];
    h_surface_float(s, u, v, P, N, du, dv);
    sl_dual Pd[3], Nd[3], ud = { u, 1, 0 }, vd = { v, 0, 1 };
    for (int i = 0; i < 3; i++) {
        Pd[i].v = P[i]; Pd[i].du = du[i]; Pd[i].dv = dv[i];
        Nd[i].v = N[i];
        /* sphere: N = P; plane: constant */
        Nd[i].du = s == H_SPHERE ? du[i] : 0;
        Nd[i].dv = s == H_SPHERE ? dv[i] : 0;
    }
    sl_vm_clear_globals(vm);
    sl_vm_set_dual(vm, SL_G_P, Pd);
    sl_vm_set_dual(vm, SL_G_N, Nd);
    sl_vm_set_dual(vm, SL_G_Ng, Nd);
    sl_vm_set_dual(vm, SL_G_u, &ud);
    sl_vm_set_dual(vm, SL_G_v, &vd);
    sl_vm_set_dual(vm, SL_G_s, &ud);
    sl_vm_set_dual(vm, SL_G_t, &vd);
    sl_dual one[3] = { { 1, 0, 0 }, { 1, 0, 0 }, { 1, 0, 0 } };
    sl_dual I[3] = { { 0, 0, 0 }, { 0, 0, 0 }, { 1, 0, 0 } };
    sl_vm_set_dual(vm, SL_G_Cs, one);
    sl_vm_set_dual(vm, SL_G_Os, one);
    sl_vm_set_dual(vm, SL_G_I, I);
}

/* Bounds of the globals' d/du and d/dv over the box, for range runs of
 * shaders that take derivatives (the same formulas in IA; the sphere's N
 * is its P). */
static inline void h_derivs(sl_vm *vm, h_surface s, double u0, double u1, double v0,
                            double v1)
{
    ia_interval Pu[3], Pv[3], zero[3], one = ia_point(1), U = ia_make(u0, u1),
                                           V = ia_make(v0, v1);
    for (int i = 0; i < 3; i++)
        zero[i] = ia_point(0);
    if (s == H_PLANE) {
        Pu[0] = ia_point(2); Pu[1] = ia_point(0); Pu[2] = ia_point(0);
        Pv[0] = ia_point(0); Pv[1] = ia_point(2); Pv[2] = ia_point(0);
    } else {
        ia_interval th = ia_mul_s(U, 2 * M_PI);
        ia_interval ph = ia_add_s(ia_mul_s(V, M_PI), -M_PI / 2);
        ia_interval cp = ia_cos(ph), sp = ia_sin(ph), ct = ia_cos(th), st = ia_sin(th);
        Pu[0] = ia_mul_s(ia_neg(ia_mul(st, cp)), 2 * M_PI);
        Pu[1] = ia_mul_s(ia_mul(ct, cp), 2 * M_PI);
        Pu[2] = ia_point(0);
        Pv[0] = ia_mul_s(ia_neg(ia_mul(ct, sp)), M_PI);
        Pv[1] = ia_mul_s(ia_neg(ia_mul(st, sp)), M_PI);
        Pv[2] = ia_mul_s(cp, M_PI);
    }
    sl_vm_set_derivs(vm, SL_G_P, Pu, Pv);
    sl_vm_set_derivs(vm, SL_G_N, s == H_PLANE ? zero : Pu, s == H_PLANE ? zero : Pv);
    sl_vm_set_derivs(vm, SL_G_Ng, s == H_PLANE ? zero : Pu, s == H_PLANE ? zero : Pv);
    sl_vm_set_derivs(vm, SL_G_u, &one, zero);
    sl_vm_set_derivs(vm, SL_G_s, &one, zero);
    sl_vm_set_derivs(vm, SL_G_v, zero, &one);
    sl_vm_set_derivs(vm, SL_G_t, zero, &one);
    sl_vm_set_derivs(vm, SL_G_I, zero, zero);
    sl_vm_set_derivs(vm, SL_G_Cs, zero, zero);
    sl_vm_set_derivs(vm, SL_G_Os, zero, zero);
}

/* Affine globals over [u0,u1] x [v0,v1]: u and v are the first two noise
 * symbols of ctx (reset here). */
static inline void h_globals_affine(sl_vm *vm, aa_context *ctx, h_surface s, double u0,
                                    double u1, double v0, double v1)
{
    aa_form U, V, P[3], N[3];
    aa_context_reset(ctx);
    aa_input(ctx, &U, u0, u1);
    aa_input(ctx, &V, v0, v1);
    if (s == H_PLANE) {
        aa_lincomb(ctx, &P[0], 2, &U, 0, NULL, -1);
        aa_lincomb(ctx, &P[1], 2, &V, 0, NULL, -1);
        aa_const(&P[2], 0);
        aa_const(&N[0], 0);
        aa_const(&N[1], 0);
        aa_const(&N[2], 1);
    } else {
        aa_form th, ph, ct, st, cp, sp;
        aa_mul_s(ctx, &th, &U, 2 * M_PI);
        aa_lincomb(ctx, &ph, M_PI, &V, 0, NULL, -M_PI / 2);
        aa_cos(ctx, &ct, &th);
        aa_sin(ctx, &st, &th);
        aa_cos(ctx, &cp, &ph);
        aa_sin(ctx, &sp, &ph);
        aa_mul(ctx, &P[0], &ct, &cp);
        aa_mul(ctx, &P[1], &st, &cp);
        P[2] = sp;
        N[0] = P[0];
        N[1] = P[1];
        N[2] = P[2];
    }
    aa_form one[3], I[3];
    for (int i = 0; i < 3; i++) {
        aa_const(&one[i], 1);
        aa_const(&I[i], i == 2 ? 1 : 0);
    }
    sl_vm_clear_globals(vm);
    sl_vm_set_affine(vm, SL_G_I, I);
    sl_vm_set_affine(vm, SL_G_P, P);
    sl_vm_set_affine(vm, SL_G_N, N);
    sl_vm_set_affine(vm, SL_G_Ng, N);
    sl_vm_set_affine(vm, SL_G_u, &U);
    sl_vm_set_affine(vm, SL_G_v, &V);
    sl_vm_set_affine(vm, SL_G_s, &U);
    sl_vm_set_affine(vm, SL_G_t, &V);
    sl_vm_set_affine(vm, SL_G_Cs, one);
    sl_vm_set_affine(vm, SL_G_Os, one);
    h_derivs(vm, s, u0, u1, v0, v1);
}

/* Interval globals over the box, from the same formulas in IA. */
static inline void h_globals_interval(sl_vm *vm, h_surface s, double u0, double u1,
                                      double v0, double v1)
{
    ia_interval U = ia_make(u0, u1), V = ia_make(v0, v1), P[3], N[3];
    if (s == H_PLANE) {
        P[0] = ia_add_s(ia_mul_s(U, 2), -1);
        P[1] = ia_add_s(ia_mul_s(V, 2), -1);
        P[2] = ia_point(0);
        N[0] = ia_point(0);
        N[1] = ia_point(0);
        N[2] = ia_point(1);
    } else {
        ia_interval th = ia_mul_s(U, 2 * M_PI);
        ia_interval ph = ia_add_s(ia_mul_s(V, M_PI), -M_PI / 2);
        ia_interval cp = ia_cos(ph);
        P[0] = ia_mul(ia_cos(th), cp);
        P[1] = ia_mul(ia_sin(th), cp);
        P[2] = ia_sin(ph);
        N[0] = P[0];
        N[1] = P[1];
        N[2] = P[2];
    }
    ia_interval one[3] = { ia_point(1), ia_point(1), ia_point(1) };
    ia_interval I[3] = { ia_point(0), ia_point(0), ia_point(1) };
    sl_vm_clear_globals(vm);
    sl_vm_set_interval(vm, SL_G_I, I);
    sl_vm_set_interval(vm, SL_G_P, P);
    sl_vm_set_interval(vm, SL_G_N, N);
    sl_vm_set_interval(vm, SL_G_Ng, N);
    sl_vm_set_interval(vm, SL_G_u, &U);
    sl_vm_set_interval(vm, SL_G_v, &V);
    sl_vm_set_interval(vm, SL_G_s, &U);
    sl_vm_set_interval(vm, SL_G_t, &V);
    sl_vm_set_interval(vm, SL_G_Cs, one);
    sl_vm_set_interval(vm, SL_G_Os, one);
    h_derivs(vm, s, u0, u1, v0, v1);
}

/* ---- small random numbers (xorshift64*), fixed seed ---- */
static inline double h_rand(unsigned long long *state)
{
    unsigned long long x = *state;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    *state = x;
    return (double)((x * 0x2545F4914F6CDD1DULL) >> 11) * 0x1p-53;
}

/* Box k of a sequence of (u, v) boxes of sides about 0.3 (k < 10), 0.03
 * (k < 25) and 0.002 at random places, from *seed */
static inline void h_box(unsigned long long *seed, int k, double box[4])
{
    double w = k < 10 ? 0.3 : k < 25 ? 0.03 : 0.002;
    double u0 = 0.05 + 0.85 * h_rand(seed), v0 = 0.05 + 0.85 * h_rand(seed);
    box[0] = u0;
    box[1] = u0 + w * (0.5 + h_rand(seed));
    box[2] = v0;
    box[3] = v0 + w * (0.5 + h_rand(seed));
}

/* Whether two affine forms are the same bits: centre, error, hull, flags
 * and the coefficients of the symbols they use */
static inline bool h_same_form(const aa_form *a, const aa_form *b)
{
    if (a->n != b->n || a->flags != b->flags)
        return false;
    if (memcmp(&a->x0, &b->x0, sizeof a->x0) || memcmp(&a->err, &b->err, sizeof a->err) ||
        memcmp(&a->lo, &b->lo, sizeof a->lo) || memcmp(&a->hi, &b->hi, sizeof a->hi))
        return false;
    return memcmp(a->c, b->c, (size_t)a->n * sizeof a->c[0]) == 0;
}

/* dir/name compiled (as file `name`); NULL on errors, silently (a corpus
 * shader that needs an include path) */
static inline sl_program *h_compile_file(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    static char text[1 << 17];
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = '\0';
    char *diag = NULL;
    sl_program *p = h_compile_named(name, text, &diag);
    free(diag);
    return p;
}

/* The next shader of an open directory of them (dir, for the paths) that
 * compiles, its file name in *name (valid until the next readdir); NULL at
 * the end. Files that are not .sl, and shaders that do not compile alone
 * (a corpus shader that needs an include path), are passed over. */
static inline sl_program *h_next_program(DIR *d, const char *dir, const char **name)
{
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n < 4 || strcmp(e->d_name + n - 3, ".sl") != 0)
            continue;
        sl_program *p = h_compile_file(dir, e->d_name);
        if (p) {
            *name = e->d_name;
            return p;
        }
    }
    return NULL;
}

#endif

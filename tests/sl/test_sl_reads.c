/*
 * tests/sl/test_sl_reads.c: the bytecode analysis sl_program_reads_global
 * (common/sl/bytecode.c), on which the renderer relies to skip the tangent
 * transforms of a box (common/trace/world.c: box_skip_tangents): a program
 * it says never names dPdu (or dPdv) must compute the same P, Ci and Oi
 * whatever dPdu holds. Checked on every library shader and every shader of
 * the conformance suite, at a few points of two base surfaces, with dPdu
 * and dPdv set to the surface's and to unrelated values; and a few small
 * programs whose answer is known (s, t, u, v and N read without dPdu: not
 * named; dPdu read directly, through a copy, a function or texture-style
 * argument blocks: named).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl_harness.h"

#ifndef AAFARM_CONFORMANCE_DIR
#define AAFARM_CONFORMANCE_DIR "tests/shaders/conformance"
#endif

/* P, Ci, Oi after a float run at (u, v) with dPdu, dPdv replaced by
 * `tangent` scaled (0: the surface's own); false when the run fails. */
static bool run(const sl_program *p, h_surface s, double u, double v, double tangent,
                double out[9])
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    h_globals_float(vm, s, u, v);
    if (tangent != 0.0) {
        double a[3] = { tangent, -3 * tangent, 0.5 }, b[3] = { 7.0, tangent, -tangent };
        sl_vm_set_float(vm, SL_G_dPdu, a);
        sl_vm_set_float(vm, SL_G_dPdv, b);
    }
    bool ok = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL) == SL_OK;
    if (ok) {
        sl_vm_get_float(vm, SL_G_P, out);
        sl_vm_get_float(vm, SL_G_Ci, out + 3);
        sl_vm_get_float(vm, SL_G_Oi, out + 6);
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    return ok;
}

static bool same(const double a[9], const double b[9])
{
    for (int i = 0; i < 9; i++)
        if (!(a[i] == b[i]) && !(isnan(a[i]) && isnan(b[i])))
            return false;
    return true;
}

typedef struct tally {
    int programs, skipped, blind, checked;
} tally;

/* A program said not to name the tangents computes the same with any. */
static void check_program(const char *file, const sl_program *p, tally *t)
{
    t->programs++;
    bool reads = sl_program_reads_global(p, SL_G_dPdu) || sl_program_reads_global(p, SL_G_dPdv);
    if (reads) {
        t->skipped++;
        return;
    }
    t->blind++;
    static const double at[4][2] = { { 0.3, 0.6 }, { 0.71, 0.13 }, { 0.5, 0.5 }, { 0.05, 0.92 } };
    for (int si = 0; si < 2; si++)
        for (int k = 0; k < 4; k++) {
            double ref[9], alt[9];
            h_surface s = si ? H_SPHERE : H_PLANE;
            if (!run(p, s, at[k][0], at[k][1], 0.0, ref)) continue;
            bool ok = run(p, s, at[k][0], at[k][1], 11.0, alt);
            if (!ok || !same(ref, alt))
                fail_msg("%s: sl_program_reads_global says dPdu/dPdv are never named, but "
                         "other tangents change its result at (%g, %g)", file, at[k][0],
                         at[k][1]);
            t->checked++;
        }
}

static void check_folder(const char *dir, tally *t)
{
    DIR *d = opendir(dir);
    if (!d) fail_msg("cannot open %s", dir);
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n < 4 || strcmp(e->d_name + n - 3, ".sl") != 0) continue;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        FILE *f = fopen(path, "rb");
        if (!f) continue;
        char *text = NULL;
        size_t len = 0;
        FILE *m = open_memstream(&text, &len);
        char buf[4096];
        size_t got;
        while ((got = fread(buf, 1, sizeof buf, f)) > 0) fwrite(buf, 1, got, m);
        fclose(f);
        fclose(m);
        char *diag = NULL;
        sl_program *p = h_compile_named(path, text, &diag);
        if (p) check_program(e->d_name, p, t);
        sl_program_destroy(&p);
        free(diag);
        free(text);
    }
    closedir(d);
}

static void test_library_and_conformance(void **state)
{
    (void)state;
    tally t = { 0 };
    check_folder(AAFARM_SHADER_DIR, &t);
    check_folder(AAFARM_CONFORMANCE_DIR, &t);
    printf("reads: %d programs; %d may name dPdu/dPdv, %d never do: %d runs with other "
           "tangents gave the same P, Ci, Oi\n", t.programs, t.skipped, t.blind, t.checked);
    assert_true(t.programs > 100);
    assert_true(t.blind > 20);      /* the analysis is not trivially "always" */
    assert_true(t.checked > 100);
}

static bool names_tangent(const char *src)
{
    sl_program *p = h_compile(src);
    assert_non_null(p);
    bool r = sl_program_reads_global(p, SL_G_dPdu) || sl_program_reads_global(p, SL_G_dPdv);
    sl_program_destroy(&p);
    return r;
}

static void test_known_answers(void **state)
{
    (void)state;
    /* neighbours of dPdu in the globals' slots, without dPdu */
    assert_false(names_tangent("displacement d() { P += N * (s + t + u + v + du + dv); }"));
    assert_false(names_tangent("displacement d() { P += normalize(N) * length(I) * 0; }"));
    assert_false(names_tangent("displacement d(float Km = 1) { point q = P; "
                               "P = q + Km * sin(10 * s) * normalize(N); }"));
    /* named: directly, through a copy, in a function, as an argument */
    assert_true(names_tangent("displacement d() { P += 0.1 * normalize(dPdu); }"));
    assert_true(names_tangent("displacement d() { vector a = dPdv; P += 0.1 * a; }"));
    assert_true(names_tangent("float f(vector x) { return length(x); }\n"
                              "displacement d() { P += N * f(dPdu); }"));
    assert_true(names_tangent("displacement d() { P += N * length(dPdu ^ dPdv); }"));
    assert_true(names_tangent("displacement d() { vector a[2] = { dPdu, dPdv }; "
                              "P += N * length(a[1]); }"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_answers),
        cmocka_unit_test(test_library_and_conformance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

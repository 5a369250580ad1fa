/*
 * test_sl_varying.c: varying globals and parameters (sl_vm_set_varying_*,
 * the primitive variables of common/trace/primvar.c): a polynomial of the
 * globals u, v, evaluated by the VM in the run's arithmetic.
 *   - float: the value of a bicubic polynomial at (u, v); a varying global
 *     s; after sl_vm_clear_globals the parameter is the instance's again;
 *     a polynomial of the wrong size leaves the parameter alone;
 *   - dual: the derivatives d/du, d/dv;
 *   - interval and affine over a (u,v) box: the range holds every sample
 *     of a 9 x 9 grid, and a linear polynomial's affine range is exact;
 *   - a shader that takes derivatives (Du of the parameter): the range of
 *     Du holds the true d/du at the samples.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "sl_harness.h"

static const char *SRC =
    "surface poly(float k = 7)\n"
    "{\n"
    "    Ci = color(k, s, 0);\n"
    "    Oi = 1;\n"
    "}\n";

static const char *DSRC =
    "surface dpoly(float k = 7)\n"
    "{\n"
    "    Ci = color(k, Du(k), Dv(k));\n"
    "    Oi = 1;\n"
    "}\n";

/* k = 1 + 2u + 3v - 4uv + 5u^2 + 0.5 u^3 v^3; s = 0.25 + u */
static void coefs(double k[16][3], double s[16][3])
{
    memset(k, 0, sizeof(double[16][3]));
    memset(s, 0, sizeof(double[16][3]));
    k[0][0] = 1, k[1][0] = 2, k[4][0] = 3, k[5][0] = -4, k[2][0] = 5, k[15][0] = 0.5;
    s[0][0] = 0.25, s[1][0] = 1;
}

static double kval(double u, double v)
{
    return 1 + 2 * u + 3 * v - 4 * u * v + 5 * u * u + 0.5 * u * u * u * v * v * v;
}
static double kdu(double u, double v) { return 2 - 4 * v + 10 * u + 1.5 * u * u * v * v * v; }
static double kdv(double u, double v) { return 3 - 4 * u + 1.5 * u * u * u * v * v; }

static void set_varying(sl_vm *vm, const sl_program *p)
{
    double k[16][3], s[16][3];
    coefs(k, s);
    assert_true(sl_vm_set_varying_param(vm, sl_program_find_param(p, "k"), 1, k));
    assert_true(sl_vm_set_varying_global(vm, SL_G_s, s));
}

static void test_float_and_dual(void **state)
{
    (void)state;
    sl_program *p = h_compile(SRC);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    double u = 0.3, v = 0.6, Ci[3];
    sl_vm_clear_globals(vm);
    sl_vm_set_float(vm, SL_G_u, &u);
    sl_vm_set_float(vm, SL_G_v, &v);
    set_varying(vm, p);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    assert_true(fabs(Ci[0] - kval(u, v)) < 1e-12);
    assert_true(fabs(Ci[1] - (0.25 + u)) < 1e-15);
    /* the wrong size: the parameter keeps the instance's value */
    double k3[16][3] = {{1, 2, 3}};
    sl_vm_clear_globals(vm);
    sl_vm_set_float(vm, SL_G_u, &u);
    assert_true(sl_vm_set_varying_param(vm, sl_program_find_param(p, "k"), 3, k3));
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    assert_true(Ci[0] == 7);
    /* cleared: the default again, s = 0 */
    sl_vm_clear_globals(vm);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    assert_true(Ci[0] == 7 && Ci[1] == 0);
    /* dual: derivatives */
    sl_dual du = {u, 1, 0}, dv = {v, 0, 1}, D[3];
    sl_vm_clear_globals(vm);
    sl_vm_set_dual(vm, SL_G_u, &du);
    sl_vm_set_dual(vm, SL_G_v, &dv);
    set_varying(vm, p);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
    sl_vm_get_dual(vm, SL_G_Ci, D);
    assert_true(fabs(D[0].v - kval(u, v)) < 1e-12);
    assert_true(fabs(D[0].du - kdu(u, v)) < 1e-12);
    assert_true(fabs(D[0].dv - kdv(u, v)) < 1e-12);
    assert_true(fabs(D[1].du - 1) < 1e-15 && D[1].dv == 0);
    /* too many */
    sl_vm_clear_globals(vm);
    for (int i = 0; i < SL_VM_MAX_VARYING; i++)
        assert_true(sl_vm_set_varying_global(vm, SL_G_t, k3));
    assert_false(sl_vm_set_varying_global(vm, SL_G_t, k3));
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_ranges(void **state)
{
    (void)state;
    const char *srcs[2] = {SRC, DSRC};
    for (int which = 0; which < 2; which++) {
        sl_program *p = h_compile(srcs[which]);
        assert_non_null(p);
        sl_instance *inst = sl_instance_new(p);
        sl_vm *vm = sl_vm_new(NULL);
        double u0 = 0.2, u1 = 0.45, v0 = 0.5, v1 = 0.8;
        for (int mode = 0; mode < 2; mode++) {
            ia_interval r[3], dr = ia_point(0);
            aa_context ctx;
            aa_context_init(&ctx, 16);
            sl_vm_clear_globals(vm);
            if (mode == 0) {
                ia_interval iu = ia_make(u0, u1), iv = ia_make(v0, v1);
                sl_vm_set_interval(vm, SL_G_u, &iu);
                sl_vm_set_interval(vm, SL_G_v, &iv);
            } else {
                aa_form au, av;
                aa_input(&ctx, &au, u0, u1);
                aa_input(&ctx, &av, v0, v1);
                sl_vm_set_affine(vm, SL_G_u, &au);
                sl_vm_set_affine(vm, SL_G_v, &av);
            }
            ia_interval one = ia_point(1), zero = ia_point(0);
            sl_vm_set_derivs(vm, SL_G_u, &one, &zero);
            sl_vm_set_derivs(vm, SL_G_v, &zero, &one);
            set_varying(vm, p);
            assert_int_equal(sl_vm_run(vm, inst, mode ? SL_MODE_AFFINE : SL_MODE_INTERVAL,
                                       mode ? &ctx : NULL), SL_OK);
            if (mode == 0) {
                sl_vm_get_interval(vm, SL_G_Ci, r);
            } else {
                aa_form f[3];
                sl_vm_get_affine(vm, SL_G_Ci, f);
                for (int c = 0; c < 3; c++) r[c] = aa_range(&f[c]);
            }
            dr = r[1];
            for (int j = 0; j <= 8; j++)
                for (int i = 0; i <= 8; i++) {
                    double u = u0 + (u1 - u0) * i / 8, v = v0 + (v1 - v0) * j / 8;
                    assert_true(r[0].lo <= kval(u, v) && kval(u, v) <= r[0].hi);
                    if (which == 0)
                        assert_true(dr.lo <= 0.25 + u && 0.25 + u <= dr.hi);
                    else
                        assert_true(dr.lo <= kdu(u, v) && kdu(u, v) <= dr.hi);
                }
            /* s is linear: its affine range is exact */
            if (which == 0 && mode == 1)
                assert_true(fabs(dr.lo - (0.25 + u0)) < 1e-12 && fabs(dr.hi - (0.25 + u1)) < 1e-12);
        }
        sl_vm_destroy(&vm);
        sl_instance_destroy(&inst);
        sl_program_destroy(&p);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_float_and_dual),
        cmocka_unit_test(test_ranges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_sl_rays.c: trace() and shadow() in the VM (RI Spec 3.2 §15.6,
 * §15.7), against a stand-in tracer that records what it was asked: the
 * ray's origin and direction reach it as the shader computed them, the
 * colour comes back (dual: derivatives 0); shadow() aims at the light of
 * the last illuminate (Ps - L, tmax 1) or solar (-L, to infinity) in a
 * light shader and at the illuminance loop's current light (L; infinity
 * for a directional sample) in a surface shader; interval and affine runs
 * read trace() as unbounded and shadow() as [0, 1] with a tracer, 0
 * without one.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "sl_harness.h"

typedef struct asked {
    int traces, shadows;
    double P[3], D[3], tmax;
    char map[64];
} asked;

static void fake_trace(void *user, const double P[3], const double R[3], double Ci[3])
{
    asked *a = user;
    a->traces++;
    for (int k = 0; k < 3; k++) {
        a->P[k] = P[k];
        a->D[k] = R[k];
        Ci[k] = P[k] + 10 * R[k];
    }
}

/* blocked when the light is towards +x */
static double fake_shadow(void *user, const char *map, const double P[3], const double D[3],
                          double tmax)
{
    asked *a = user;
    a->shadows++;
    snprintf(a->map, sizeof a->map, "%s", map);
    for (int k = 0; k < 3; k++) {
        a->P[k] = P[k];
        a->D[k] = D[k];
    }
    a->tmax = tmax;
    return D[0] > 0 ? 1.0 : 0.0;
}

static const char *MIRROR =
    "surface mirror()\n"
    "{\n"
    "    Ci = trace(P + vector(0, 0, 1), reflect(I, normalize(N)));\n"
    "    Oi = 1;\n"
    "}\n";

static void test_trace_reaches_the_tracer_and_returns_its_colour(void **state)
{
    (void)state;
    sl_program *p = h_compile(MIRROR);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    asked a = {0};
    sl_tracer tr = {.trace = fake_trace, .shadow = fake_shadow, .user = &a};
    sl_vm_set_tracer(vm, &tr);
    double u = 0.3, v = 0.6, P[3], N[3], du[3], dv[3], Ci[3];
    h_surface_float(H_PLANE, u, v, P, N, du, dv);
    h_globals_float(vm, H_PLANE, u, v);
    double I[3] = {0.2, -0.1, 1};
    sl_vm_set_float(vm, SL_G_I, I);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    /* N = (0, 0, 1): reflect(I, N) = (0.2, -0.1, -1) */
    double R[3] = {0.2, -0.1, -1};
    assert_int_equal(a.traces, 1);
    for (int k = 0; k < 3; k++) {
        assert_true(fabs(a.P[k] - (P[k] + (k == 2))) < 1e-15);
        assert_true(fabs(a.D[k] - R[k]) < 1e-15);
        assert_true(fabs(Ci[k] - (a.P[k] + 10 * R[k])) < 1e-15);
    }
    /* dual: the same colour, derivatives 0 */
    h_globals_dual(vm, H_PLANE, u, v);
    sl_dual Id[3] = {{0.2, 0, 0}, {-0.1, 0, 0}, {1, 0, 0}}, Cd[3];
    sl_vm_set_dual(vm, SL_G_I, Id);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
    sl_vm_get_dual(vm, SL_G_Ci, Cd);
    for (int k = 0; k < 3; k++) {
        assert_true(fabs(Cd[k].v - Ci[k]) < 1e-15);
        assert_true(Cd[k].du == 0 && Cd[k].dv == 0);
    }
    assert_int_equal(a.traces, 2);
    /* over a range: unbounded with a tracer (never called), 0 without */
    ia_interval Ii[3];
    h_globals_interval(vm, H_PLANE, 0.25, 0.5, 0.5, 0.75);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL), SL_OK);
    sl_vm_get_interval(vm, SL_G_Ci, Ii);
    assert_true(isinf(Ii[0].lo) && isinf(Ii[0].hi));
    assert_int_equal(a.traces, 2);
    sl_vm_set_tracer(vm, NULL);
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    aa_form Ca[3];
    h_globals_affine(vm, &ctx, H_PLANE, 0.25, 0.5, 0.5, 0.75);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx), SL_OK);
    sl_vm_get_affine(vm, SL_G_Ci, Ca);
    for (int k = 0; k < 3; k++) {
        ia_interval r = aa_range(&Ca[k]);
        assert_true(r.lo == 0 && r.hi == 0);
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static const char *SPOT =
    "light spot(point from = point(1, 2, 3); string map = \"spot.shd\")\n"
    "{\n"
    "    illuminate(from)\n"
    "        Cl = 1 - shadow(map, Ps, \"blur\", 0.02);\n"
    "}\n";
static const char *SUN =
    "light sun(vector dir = vector(-0.5, 0, 1))\n"
    "{\n"
    "    solar(dir, 0)\n"
    "        Cl = 1 - shadow(\"sun.shd\", Ps);\n"
    "}\n";

static void light_at(const char *src, const double Ps[3], asked *a, sl_light_sample *out)
{
    sl_program *p = h_compile(src);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    sl_tracer tr = {.trace = fake_trace, .shadow = fake_shadow, .user = a};
    sl_vm_set_tracer(vm, &tr);
    assert_int_equal(sl_light_eval(vm, inst, Ps, out), SL_OK);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_shadow_in_light_shaders_aims_at_the_light(void **state)
{
    (void)state;
    double Ps[3] = {0.5, 0.25, 0};
    asked a = {0};
    sl_light_sample s;
    /* illuminate: from Ps to the light at (1, 2, 3), which is +x: blocked */
    light_at(SPOT, Ps, &a, &s);
    assert_int_equal(a.shadows, 1);
    assert_string_equal(a.map, "spot.shd");
    assert_true(a.tmax == 1.0);
    for (int k = 0; k < 3; k++) {
        double from[3] = {1, 2, 3};
        assert_true(fabs(a.D[k] - (from[k] - Ps[k])) < 1e-15);
        assert_true(fabs(a.P[k] - Ps[k]) < 1e-15);
        assert_true(s.Cl[k] == 0);
    }
    /* solar: towards -dir = (0.5, 0, -1), to infinity */
    memset(&a, 0, sizeof a);
    light_at(SUN, Ps, &a, &s);
    assert_int_equal(a.shadows, 1);
    assert_true(isinf(a.tmax));
    assert_true(a.D[0] == 0.5 && a.D[1] == 0 && a.D[2] == -1);
    assert_true(s.Cl[0] == 0);
}

static const char *SHADOWED =
    "surface shadowed()\n"
    "{\n"
    "    color C = 0;\n"
    "    illuminance(P)\n"
    "        C += Cl * (1 - shadow(\"m\", P));\n"
    "    Ci = C;\n"
    "    Oi = shadow(\"m\", P);\n"
    "}\n";

static void test_shadow_in_illuminance_uses_the_current_light(void **state)
{
    (void)state;
    sl_program *p = h_compile(SHADOWED);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    asked a = {0};
    sl_tracer tr = {.trace = fake_trace, .shadow = fake_shadow, .user = &a};
    sl_vm_set_tracer(vm, &tr);
    /* a local light towards +x (blocked), a distant one towards -x (lit) */
    sl_light_sample lights[2] = {
        {{2, 0, 1}, {1, 0, 0}, false, false},
        {{-1, 0, 1}, {0, 1, 0}, false, true},
    };
    sl_vm_set_fixed_lights(vm, lights, 2);
    h_globals_float(vm, H_PLANE, 0.5, 0.5);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_OK);
    double Ci[3], Oi[3];
    sl_vm_get_float(vm, SL_G_Ci, Ci);
    sl_vm_get_float(vm, SL_G_Oi, Oi);
    /* the first light blocked, the second lit; outside the loop no light */
    assert_true(Ci[0] == 0 && Ci[1] == 1 && Ci[2] == 0);
    assert_true(Oi[0] == 0);
    assert_int_equal(a.shadows, 2);
    assert_true(isinf(a.tmax) && a.D[0] == -1);     /* the last: the distant light */
    /* over a range: [0, 1] with a tracer */
    ia_interval Ii[3];
    h_globals_interval(vm, H_PLANE, 0.25, 0.5, 0.5, 0.75);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL), SL_OK);
    sl_vm_get_interval(vm, SL_G_Ci, Ii);
    assert_true(Ii[0].lo <= 0 && Ii[0].hi >= 1 && Ii[1].lo <= 0 && Ii[1].hi >= 1);
    assert_true(isfinite(Ii[0].lo) && isfinite(Ii[0].hi));
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_trace_reaches_the_tracer_and_returns_its_colour),
        cmocka_unit_test(test_shadow_in_light_shaders_aims_at_the_light),
        cmocka_unit_test(test_shadow_in_illuminance_uses_the_current_light),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

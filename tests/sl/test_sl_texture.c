/*
 * tests/sl/test_sl_texture.c: texture(), environment(), bump() and
 * textureinfo() in the shading language (issue 16; docs/textures.md).
 *
 *   compile      the forms that compile, and clear errors for the ones that
 *                do not (unknown parameter, wrong count, bad wrap mode, a
 *                channel index outside a lookup, shadow())
 *   float        texture("h", s, t) on the plane equals a bilinear lookup
 *                written here from scratch; a huge blur gives the mean of
 *                all texels; color lookups read channels c..c+2 and the
 *                fill value past the last; the four-corner form of a point
 *                equals the two-coordinate form
 *   dual         d/du of a lookup matches a central difference
 *   containment  displacement shaders with texture() (wrap seams, blur,
 *                the four-corner form with derivative footprints, color
 *                channels, mixtures with noise, environment(), bump()):
 *                float samples of random (u, v) boxes on the plane and the
 *                sphere lie inside the interval and affine enclosures of P;
 *                0 violations, counts printed; affine is no wider than
 *                interval on average
 *   textureinfo  resolution, channels, type; 0 for a missing texture
 *   errors       a lookup of a missing texture stops the run with a
 *                message naming it
 *   names        sl_instance_texture_names finds constant and parameter
 *                names
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl_harness.h"
#include "tex/tex.h"

static tex_cache *cache;
static float hpx[13 * 9], rgbpx[8 * 8 * 3];

static int setup(void **state)
{
    (void)state;
    cache = tex_cache_new(0);
    unsigned long long rs = 7;
    for (int k = 0; k < 13 * 9; k++)
        hpx[k] = (float)(h_rand(&rs) * 2 - 0.5);
    for (int k = 0; k < 8 * 8 * 3; k++)
        rgbpx[k] = (float)h_rand(&rs);
    tex_cache_put(cache, "h.tx", tex_from_pixels(hpx, 13, 9, 1, "h.tx"));
    tex_cache_put(cache, "rgb.tx", tex_from_pixels(rgbpx, 8, 8, 3, "rgb.tx"));
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    tex_cache_destroy(&cache);
    return 0;
}

static double texel(int i, int j)
{
    i = ((i % 13) + 13) % 13;
    j = ((j % 9) + 9) % 9;
    return hpx[j * 13 + i];
}

/* the independent lookup: bilinear, periodic, texel centres at (i+1/2)/W */
static double bilinear(double s, double t)
{
    double x = s * 13 - 0.5, y = t * 9 - 0.5, fi = floor(x), fj = floor(y);
    double a = x - fi, b = y - fj;
    int i = (int)fi, j = (int)fj;
    return (1 - a) * (1 - b) * texel(i, j) + a * (1 - b) * texel(i + 1, j) +
           (1 - a) * b * texel(i, j + 1) + a * b * texel(i + 1, j + 1);
}

static sl_program *compile_body(const char *body, char **diag)
{
    char src[4096];
    snprintf(src, sizeof src, "displacement t(string map = \"h.tx\"; float k = 1;) { %s }",
             body);
    return h_compile_named("t.sl", src, diag);
}

static void expect_compile_error(const char *body, const char *words)
{
    char *diag = NULL;
    sl_program *p = compile_body(body, &diag);
    if (p || !diag || !strstr(diag, words))
        fail_msg("'%s': wanted an error with '%s', got %s", body, words, diag ? diag : "none");
    free(diag);
}

static void test_compile(void **state)
{
    (void)state;
    static const char *const good[] = {
        "float h = texture(\"h.tx\", s, t);",
        "float h = texture(map[0], s, t, \"blur\", 0.1, \"swrap\", \"clamp\");",
        "float h = texture(map);",
        "color c = texture(\"rgb.tx\"[1], s, t, \"fill\", 0.5, \"filter\", \"gaussian\");",
        "float h = texture(map, s, t, s + 0.1, t, s, t + 0.1, s + 0.1, t + 0.1, \"width\", 2);",
        "color c = environment(\"rgb.tx\", normalize(N), \"blur\", 0.01);",
        "normal n = N + bump(map, N, dPdu, dPdv);",
        "float r[2]; float n; string ty; float ok = textureinfo(map, \"resolution\", r) + "
        "textureinfo(map, \"channels\", n) + textureinfo(map, \"type\", ty);",
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        char *diag = NULL;
        sl_program *p = compile_body(good[i], &diag);
        if (!p)
            fail_msg("'%s' does not compile: %s", good[i], diag ? diag : "");
        free(diag);
        sl_program_destroy(&p);
    }
    expect_compile_error("float h = texture(map, s, t, \"sharpness\", 1);",
                         "unknown texture() parameter 'sharpness'");
    expect_compile_error("float h = texture(map, s);", "got 1 value");
    expect_compile_error("float h = texture(map, s, t, \"wrap\", \"mirror\");",
                         "unknown wrap mode 'mirror'");
    expect_compile_error("float h = texture(map, s, t, \"filter\", map);",
                         "takes a constant string");
    expect_compile_error("string x = \"h.tx\"[1];", "only allowed on the texture name");
    expect_compile_error("float h = texture(1, s, t);", "must be a string");
    expect_compile_error("float r; float ok = textureinfo(map, \"resolution\", r);",
                         "of type 'float[2]'");
    expect_compile_error("float h = shadow(map, P);", "cannot be used in a displacement shader");
}

/* Runs a displacement body in float mode at (u, v) on the plane: P. */
static void run_float_body(const char *body, double u, double v, double P[3])
{
    sl_program *p = compile_body(body, NULL);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    sl_vm_set_textures(vm, cache);
    h_globals_float(vm, H_PLANE, u, v);
    sl_status st = sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL);
    if (st != SL_OK)
        fail_msg("%s", sl_vm_error(vm));
    sl_vm_get_float(vm, SL_G_P, P);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

/* The optional parameters as shader libraries pass them: the ones a
 * lookup has no use for ("samples", "filter", "lerp"; "width" outside the
 * four-corner form) compile with one warning per name and function in a
 * shader; the used ones ("blur", "fill", "width" with four corners) with
 * none; and the ignored ones change nothing. */
static void test_optional_parameters(void **state)
{
    (void)state;
    char *diag = NULL;
    sl_program *p = compile_body(
        "float a = texture(map, s, t, \"samples\", 16, \"filter\", \"gaussian\", "
        "\"blur\", 0.01);\n"
        "float b = texture(map, s, t, \"samples\", 4, \"width\", 2, \"lerp\", 1);\n"
        "color c = environment(\"rgb.tx\", N, \"samples\", 4, \"fill\", 0);\n"
        "float d = texture(map, s, t, s, t, s, t, s, t, \"width\", 2);\n"
        "P = point(a, b, comp(c, 0) + d);", &diag);
    assert_non_null(p);
    static const char *const want[] = {
        "t.sl:1:82: warning: texture() parameter 'samples' is accepted and ignored: aafarm "
        "filters each lookup one way, over the footprint it bounds (docs/textures.md) (said "
        "once per shader)\n",
        "t.sl:1:97: warning: texture() parameter 'filter'",
        "t.sl:2:44: warning: texture() parameter 'width' is accepted and ignored: only the "
        "four-corner form of texture() has a footprint to widen (use \"blur\")",
        "t.sl:2:56: warning: texture() parameter 'lerp'",
        "t.sl:3:36: warning: environment() parameter 'samples'",
    };
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++)
        if (!strstr(diag, want[k]))
            fail_msg("wanted '%s' in:\n%s", want[k], diag);
    int warnings = 0;
    for (const char *q = diag; (q = strstr(q, "warning: ")) != NULL; q++)
        warnings++;
    assert_int_equal(warnings, 5);
    free(diag);
    sl_program_destroy(&p);
    double P[3], Q[3];
    run_float_body("P = point(0, 0, texture(map, s, t, \"samples\", 16, \"filter\", "
                   "\"gaussian\", \"lerp\", 1));", 0.3, 0.6, P);
    run_float_body("P = point(0, 0, texture(map, s, t));", 0.3, 0.6, Q);
    assert_true(P[2] == Q[2]);
}

static void test_float(void **state)
{
    (void)state;
    unsigned long long rs = 99;
    for (int k = 0; k < 200; k++) {
        double u = h_rand(&rs), v = h_rand(&rs), P[3];
        run_float_body("P = point(0, 0, texture(map, s * 3 - 1, t * 2 + 0.3));", u, v, P);
        double want = bilinear(u * 3 - 1, v * 2 + 0.3);
        if (fabs(P[2] - want) > 1e-9)
            fail_msg("texture at (%g, %g) = %.17g, bilinear %.17g", u, v, P[2], want);
        run_float_body("P = point(0, 0, texture(map, s, t, s, t, s, t, s, t));", u, v, P);
        assert_true(fabs(P[2] - bilinear(u, v)) < 1e-9);
    }
    double mean = 0, P[3];
    for (int k = 0; k < 13 * 9; k++)
        mean += hpx[k] / (13.0 * 9.0);
    run_float_body("P = point(0, 0, texture(map, s, t, \"blur\", 1000));", 0.3, 0.6, P);
    assert_true(fabs(P[2] - mean) < 1e-6);
    run_float_body("color c = texture(\"rgb.tx\"[1], s, t, \"fill\", 0.25);"
                   "P = point(comp(c, 0), comp(c, 1), comp(c, 2));",
                   (2 + 0.5) / 8, (5 + 0.5) / 8, P);
    assert_true(fabs(P[0] - rgbpx[(5 * 8 + 2) * 3 + 1]) < 1e-6);
    assert_true(fabs(P[1] - rgbpx[(5 * 8 + 2) * 3 + 2]) < 1e-6);
    assert_true(P[2] == 0.25);
}

static void test_dual(void **state)
{
    (void)state;
    sl_program *p = compile_body("P += N * texture(map, s * 2, t) * k;", NULL);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    sl_vm_set_textures(vm, cache);
    unsigned long long rs = 5;
    for (int k = 0; k < 100; k++) {
        double u = 0.05 + 0.9 * h_rand(&rs), v = 0.05 + 0.9 * h_rand(&rs), h = 1e-6;
        sl_dual Pd[3];
        h_globals_dual(vm, H_PLANE, u, v);
        assert_int_equal(sl_vm_run(vm, inst, SL_MODE_DUAL, NULL), SL_OK);
        sl_vm_get_dual(vm, SL_G_P, Pd);
        double a = bilinear(2 * (u + h), v), b = bilinear(2 * (u - h), v);
        double fd = (a - b) / (2 * h);
        /* a kink between the samples makes the difference differ: skip those */
        double x = 2 * u * 13 - 0.5;
        if (fabs(x - floor(x + 0.5)) < 1e-3)
            continue;
        if (fabs(Pd[2].du - fd) > 1e-4 * (1 + fabs(fd)))
            fail_msg("d/du at (%g, %g): dual %.12g, difference %.12g", u, v, Pd[2].du, fd);
    }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static bool inside(ia_interval r, double x)
{
    double tol = 1e-9 * (1 + fabs(x));
    return x >= r.lo - tol && x <= r.hi + tol;
}

static const char *const shaders[] = {
    /* wrap seams: s from -1 to 2 */
    "P += N * texture(map, s * 3 - 1, t) * 0.2;",
    "P += N * texture(map, s * 3 - 1, t * 2, \"wrap\", \"clamp\") * 0.2;",
    "P += N * texture(map, s * 3 - 1, t * 2 - 0.5, \"swrap\", \"black\", \"twrap\", "
    "\"periodic\") * 0.2;",
    /* blur, constant and varying */
    "P += N * texture(map, s, t, \"blur\", 0.05) * 0.2;",
    "P += N * texture(map, s, t, \"sblur\", s * 0.3, \"tblur\", 0.01) * 0.2;",
    /* the four-corner form with a filter width from derivatives */
    "float ds = Du(s) * du, dt = Dv(t) * dv;"
    "P += N * texture(map, s, t, s + ds, t, s, t + dt, s + ds, t + dt, \"width\", 40) * 0.2;",
    /* color channels and fill */
    "color c = texture(\"rgb.tx\"[1], s * 2, t, \"fill\", 0.5);"
    "P += N * (comp(c, 0) - comp(c, 2)) * 0.2;",
    /* mixtures with noise, layered maps */
    "float h = texture(map, s + 0.3 * noise(P * 3), t) * 0.5 + "
    "0.5 * texture(map[0], s * 4, t * 4, \"blur\", 0.02);"
    "P += N * h * 0.2 + 0.05 * noise(P * 5);",
    /* a texture lookup steering a branch */
    "float h = texture(map, s, t); if (h > 0.5) P += N * (h - 0.5); else P -= N * 0.1 * h;",
    /* environment() on a lat-long map */
    "color c = environment(\"rgb.tx\", N + vector(0.2, 0, 0)); P += N * comp(c, 1) * 0.2;",
    /* bump(): the normal's change, used as an offset */
    "P += bump(map, N, vector(2, 0, 0), vector(0, 2, 0)) * 0.001;",
    /* textureinfo steering a scale */
    "float r[2]; float ok = textureinfo(map, \"resolution\", r);"
    "P += N * texture(map, s, t) * ok * r[0] / 13;",
};

static void test_containment(void **state)
{
    (void)state;
    long checked = 0, bad = 0;
    double wa = 0, wi = 0;
    unsigned long long rs = 1234;
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    for (size_t n = 0; n < sizeof shaders / sizeof shaders[0]; n++) {
        sl_program *p = compile_body(shaders[n], NULL);
        if (!p)
            fail_msg("shader %zu does not compile", n);
        sl_instance *inst = sl_instance_new(p);
        sl_vm *vm = sl_vm_new(NULL);
        sl_vm_set_textures(vm, cache);
        for (int box = 0; box < 120; box++) {
            h_surface surf = box % 2 ? H_SPHERE : H_PLANE;
            double size = box % 3 == 0 ? 0.002 : box % 3 == 1 ? 0.03 : 0.3;
            double u0 = h_rand(&rs) * (1 - size), v0 = 0.02 + h_rand(&rs) * (0.96 - size);
            double u1 = u0 + size * h_rand(&rs), v1 = v0 + size * h_rand(&rs);
            ia_interval ia[3], am[3];
            aa_form af[3];
            h_globals_interval(vm, surf, u0, u1, v0, v1);
            if (sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL) != SL_OK)
                fail_msg("shader %zu interval: %s", n, sl_vm_error(vm));
            sl_vm_get_interval(vm, SL_G_P, ia);
            h_globals_affine(vm, &ctx, surf, u0, u1, v0, v1);
            if (sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx) != SL_OK)
                fail_msg("shader %zu affine: %s", n, sl_vm_error(vm));
            sl_vm_get_affine(vm, SL_G_P, af);
            for (int i = 0; i < 3; i++) {
                am[i] = aa_range(&af[i]);
                wa += am[i].hi - am[i].lo;
                wi += ia[i].hi - ia[i].lo;
            }
            for (int q = 0; q < 36; q++) {
                double u = u0 + (u1 - u0) * (q < 4 ? (q & 1) : h_rand(&rs));
                double v = v0 + (v1 - v0) * (q < 4 ? (q >> 1) : h_rand(&rs));
                double P[3];
                h_globals_float(vm, surf, u, v);
                if (sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL) != SL_OK)
                    fail_msg("shader %zu float: %s", n, sl_vm_error(vm));
                sl_vm_get_float(vm, SL_G_P, P);
                for (int i = 0; i < 3; i++) {
                    checked++;
                    if (!inside(ia[i], P[i]) || !inside(am[i], P[i])) {
                        if (bad++ < 10)
                            fprintf(stderr, "shader %zu (%s) at (%.17g, %.17g) box [%g, %g] x "
                                    "[%g, %g]: P[%d] = %.17g, interval [%.17g, %.17g], affine "
                                    "[%.17g, %.17g]\n", n, surf == H_PLANE ? "plane" : "sphere",
                                    u, v, u0, u1, v0, v1, i, P[i], ia[i].lo, ia[i].hi,
                                    am[i].lo, am[i].hi);
                    }
                }
            }
        }
        sl_vm_destroy(&vm);
        sl_instance_destroy(&inst);
        sl_program_destroy(&p);
    }
    printf("texture containment: %ld values checked, %ld violations; affine/interval width "
           "%.3f\n", checked, bad, wa / wi);
    assert_int_equal(bad, 0);
    assert_true(wa <= wi);
}

static void test_textureinfo(void **state)
{
    (void)state;
    double P[3];
    run_float_body("float r[2]; float n = 0, l = 0; string ty = \"\";"
                   "float ok = textureinfo(map, \"resolution\", r) + textureinfo(\"rgb.tx\", "
                   "\"channels\", n) + textureinfo(map, \"type\", ty);"
                   "P = point(ok * 1000 + r[0] * 10 + r[1], n, ty == \"texture\" ? 1 : 0);",
                   0.5, 0.5, P);
    assert_true(P[0] == 3000 + 130 + 9 && P[1] == 3 && P[2] == 1);
    run_float_body("float n = -1; P = point(textureinfo(\"nothere.tx\", \"channels\", n), n, 0);",
                   0.5, 0.5, P);
    assert_true(P[0] == 0 && P[1] == -1);
}

static void test_missing_texture(void **state)
{
    (void)state;
    sl_program *p = compile_body("P += N * texture(\"nothere.tx\", s, t);", NULL);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    sl_vm_set_textures(vm, cache);
    h_globals_float(vm, H_PLANE, 0.5, 0.5);
    assert_int_equal(sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL), SL_ERR_RUNTIME);
    const char *err = sl_vm_error(vm);
    if (!strstr(err, "nothere.tx") || !strstr(err, "t.sl:1:"))
        fail_msg("message: %s", err);
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_names(void **state)
{
    (void)state;
    sl_program *p = compile_body("P += N * (texture(map, s, t) + texture(\"rgb.tx\", s, t) + "
                                 "texture(map[0], t, s));", NULL);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    const char *names[8];
    int n = sl_instance_texture_names(inst, names, 8);
    assert_int_equal(n, 2);
    assert_true((strcmp(names[0], "h.tx") == 0 && strcmp(names[1], "rgb.tx") == 0) ||
                (strcmp(names[1], "h.tx") == 0 && strcmp(names[0], "rgb.tx") == 0));
    assert_true(sl_instance_set_string(inst, "map", "other.tx", NULL, 0));
    n = sl_instance_texture_names(inst, names, 8);
    assert_int_equal(n, 2);
    assert_true(strcmp(names[0], "other.tx") == 0 || strcmp(names[1], "other.tx") == 0);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_compile),
        cmocka_unit_test(test_optional_parameters),
        cmocka_unit_test(test_float),
        cmocka_unit_test(test_dual),
        cmocka_unit_test(test_containment),
        cmocka_unit_test(test_textureinfo),
        cmocka_unit_test(test_missing_texture),
        cmocka_unit_test(test_names),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

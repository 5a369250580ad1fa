/*
 * tests/sl/test_sl_box_plan.c: box runs (sl_vm_set_box_runs, box_plan.c)
 * leave out of a displacement's affine run only what cannot reach P.
 *
 *   same P      on random boxes of the plane and the sphere, P of a box
 *               run equals P of the full derivative-carrying run form for
 *               form (centre, coefficients, error, hull, flags) for
 *               shaders that take derivatives: a height map's filter width
 *               from Du/Dv then calculatenormal, branches on the range,
 *               an early return, Deriv and area, the library's
 *               displacement shaders; the corpus's the same, or (P merged
 *               after calculatenormal: other noise symbols) enclosing the
 *               float P at 5 x 5 points of every box
 *   the plan    a terrain-like shader leaves calculatenormal and N out
 *               (SL_BOX_DEAD) and runs the normalize chain without
 *               derivatives (SL_BOX_VALUE), keeps the derivative chain of
 *               the filter width (SL_BOX_RUN); in a loop the same, and
 *               what a later iteration reads stays live in an earlier one
 *   lookups     heightmap.sl's two lookups of a map (in a texture cache)
 *               run without derivative bounds (SL_BOX_VALUE), and P is the
 *               full run's form for form
 *   intervals   interval runs (P alone) and slope runs (P and its slope
 *               bounds, sl_vm_run_slopes: the hit proofs') with the box
 *               and slope plans give the full runs' P (its values) and
 *               slope bounds (values and flags) bit for bit, for every
 *               library and corpus displacement shader
 *               on random boxes of the plane and the sphere; the slope plan
 *               leaves a terrain's calculatenormal out
 *   unread      the globals box_plan.c says no box run reads
 *               (sl_program_box_reads: on a height map the tangents and
 *               P's derivative bounds) can be unbounded without changing
 *               P, on all the shaders above; a shader that reads Du(P) and
 *               dPdv is said to
 */
#include <dirent.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/bytecode.h"
#include "sl_harness.h"
#include "tex/tex.h"

static tex_cache *g_textures;      /* the maps of the runs below (NULL: none) */

#ifndef AAFARM_CORPUS_DIR
#define AAFARM_CORPUS_DIR "tests/shaders/corpus"
#endif

/* P of one affine run over the box, box runs on or off */
static sl_status run_P(sl_vm *vm, const sl_instance *inst, aa_context *ctx, h_surface s,
                       const double box[4], bool box_runs, aa_form P[3])
{
    sl_vm_set_box_runs(vm, box_runs);
    h_globals_affine(vm, ctx, s, box[0], box[1], box[2], box[3]);
    sl_status st = sl_vm_run(vm, inst, SL_MODE_AFFINE, ctx);
    if (st == SL_OK)
        sl_vm_get_affine(vm, SL_G_P, P);
    return st;
}

/* Globals that no box run reads (sl_program_box_reads) spoiled: their
 * values unbounded, their derivative bounds the whole line */
static void spoil_unread(sl_vm *vm, const sl_program *p)
{
    for (int g = 0; g < SL_G__COUNT; g++) {
        int n = sl_global_size((sl_global)g);
        assert_true(n >= 1 && n <= 3);
        aa_form f[3];
        ia_interval e[3];
        for (int k = 0; k < 3; k++) {
            aa_unbounded(&f[k], AA_UNBOUNDED);
            e[k] = ia_entire();
        }
        if (!sl_program_box_reads(p, (sl_global)g, false))
            sl_vm_set_affine(vm, (sl_global)g, f);
        if (!sl_program_box_reads(p, (sl_global)g, true))
            sl_vm_set_derivs(vm, (sl_global)g, e, e);
    }
}

/* The boxes (of 2 x 40) whose box-run P changes when the globals no box
 * run reads are spoiled: what the renderer leaves out of its binding
 * (box_runs_skip_tangents) must not reach P */
static int spoiled_differing(const sl_program *p, const char *what)
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    if (g_textures)
        sl_vm_set_textures(vm, g_textures);
    sl_vm_set_box_runs(vm, true);
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    unsigned long long seed = 0x51ull;
    int bad = 0;
    for (int si = 0; si < 2; si++)
        for (int k = 0; k < 40; k++) {
            double box[4];
            h_box(&seed, k, box);
            aa_form P[2][3];
            sl_status st[2];
            for (int spoil = 0; spoil < 2; spoil++) {
                h_globals_affine(vm, &ctx, si ? H_SPHERE : H_PLANE, box[0], box[1], box[2],
                                 box[3]);
                if (spoil)
                    spoil_unread(vm, p);
                st[spoil] = sl_vm_run(vm, inst, SL_MODE_AFFINE, &ctx);
                sl_vm_get_affine(vm, SL_G_P, P[spoil]);
            }
            bool same = st[0] == st[1];
            for (int i = 0; i < 3 && same && st[0] == SL_OK; i++)
                same = h_same_form(&P[0][i], &P[1][i]);
            if (!same && bad < 3) {
                ia_interval a = aa_range(&P[0][0]), b = aa_range(&P[1][0]);
                fprintf(stderr, "%s: unread globals spoiled, box [%g %g]x[%g %g]: P.x "
                        "[%.17g, %.17g], was [%.17g, %.17g]\n", what, box[0], box[1], box[2],
                        box[3], b.lo, b.hi, a.lo, a.hi);
            }
            bad += !same;
        }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    return bad;
}

/* float P at 5 x 5 points of the box (edges included) inside the box
 * run's P (the float run's rounding: 1e-9, as test_sl_bounds) */
static bool contains_samples(sl_vm *vm, const sl_instance *inst, h_surface s,
                             const double box[4], const aa_form P[3])
{
    for (int a = 0; a <= 4; a++)
        for (int b = 0; b <= 4; b++) {
            double u = box[0] + (box[1] - box[0]) * a / 4, v = box[2] + (box[3] - box[2]) * b / 4;
            double f[3];
            h_globals_float(vm, s, u, v);
            if (sl_vm_run(vm, inst, SL_MODE_FLOAT, NULL) != SL_OK)
                continue;
            sl_vm_get_float(vm, SL_G_P, f);
            for (int i = 0; i < 3; i++) {
                ia_interval r = aa_range(&P[i]);
                double tol = 1e-9 * (1 + fabs(f[i]));
                if (!(f[i] >= r.lo - tol && f[i] <= r.hi + tol))
                    return false;
            }
        }
    return true;
}

/* The number of boxes (of 2 x 40) whose P differs between box and full
 * runs (when !exact: only those where the box run's P misses a float
 * sample; *renamed counts the others); -1 when the shader fails to run
 * the same way in both. */
static int differing_as(sl_program *p, const char *what, bool exact, int *renamed)
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    if (g_textures)
        sl_vm_set_textures(vm, g_textures);
    aa_context ctx;
    aa_context_init(&ctx, AA_DEFAULT_CAPACITY);
    unsigned long long seed = 0x5eedull;
    int bad = 0;
    for (int si = 0; si < 2; si++) {
        h_surface s = si == 0 ? H_PLANE : H_SPHERE;
        for (int k = 0; k < 40; k++) {
            double box[4];
            h_box(&seed, k, box);
            aa_form full[3], cut[3];
            sl_status a = run_P(vm, inst, &ctx, s, box, false, full);
            sl_status b = run_P(vm, inst, &ctx, s, box, true, cut);
            if (a != b) {
                fprintf(stderr, "%s: status %d full, %d box run\n", what, (int)a, (int)b);
                bad = -1;
                goto done;
            }
            if (a != SL_OK)
                continue;
            bool same = true;
            for (int i = 0; i < 3; i++)
                same = same && h_same_form(&full[i], &cut[i]);
            if (!same && !exact && contains_samples(vm, inst, s, box, cut)) {
                ++*renamed;
                continue;
            }
            if (!same && bad < 3) {
                ia_interval f = aa_range(&full[0]), c = aa_range(&cut[0]);
                fprintf(stderr, "%s (%s) box [%g %g]x[%g %g]: P.x full [%.17g, %.17g], box run "
                        "[%.17g, %.17g]\n", what, s == H_PLANE ? "plane" : "sphere", box[0],
                        box[1], box[2], box[3], f.lo, f.hi, c.lo, c.hi);
            }
            bad += !same;
        }
    }
done:
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    return bad;
}

static int differing(sl_program *p, const char *what)
{
    int renamed = 0;
    return differing_as(p, what, true, &renamed);
}

static void check_source(const char *src)
{
    sl_program *p = h_compile(src);
    assert_non_null(p);
    assert_true(sl_program_takes_derivatives(p));
    assert_int_equal(differing(p, src), 0);
    assert_int_equal(spoiled_differing(p, src), 0);
    sl_program_destroy(&p);
}

/* a height field as heightmap.sl writes it, with a function instead of the
 * map: the filter width from Du/Dv, the normal from calculatenormal */
static const char TERRAIN[] =
    "displacement t(float Km = 0.3, blur = 1) {\n"
    "  float ss = s * 2, tt = t * 2;\n"
    "  float fw = max(abs(Du(ss) * du) + abs(Dv(ss) * dv),\n"
    "                 abs(Du(tt) * du) + abs(Dv(tt) * dv));\n"
    "  float h = sin(ss * 5 + blur * fw) * cos(tt * 3) + 0.2 * clamp(ss - tt, -0.5, 0.5);\n"
    "  P += Km * h * normalize(N);\n"
    "  N = calculatenormal(P);\n"
    "}\n";

static void test_same_P(void **state)
{
    (void)state;
    check_source(TERRAIN);
    /* branches undecided over the range, merged */
    check_source("displacement t() {\n"
                 "  float h = Du(s * s) * 0.1;\n"
                 "  if (s > 0.5) h = h * 2 + sqrt(t + 1); else h = -h / (t + 1);\n"
                 "  vector d = normalize(N);\n"
                 "  P += h * d;\n"
                 "  N = calculatenormal(P);\n"
                 "}\n");
    /* an early return from a function, Deriv and area */
    check_source("float f(float x) { if (x > 0.6) return x * x; return -x; }\n"
                 "displacement t() {\n"
                 "  float a = area(P), g = Deriv(s * t, s);\n"
                 "  float h = f(s) * 0.1 + min(a, 1) * 0.01 + g * 0.05;\n"
                 "  P += h * normalize(N);\n"
                 "  N = calculatenormal(P);\n"
                 "}\n");
    /* the derivative of a result that is written again before P */
    check_source("displacement t() {\n"
                 "  float x = s * 3;\n"
                 "  float d = Du(x);\n"
                 "  x = d * t;\n"
                 "  P += point(x * 0.01, abs(Dv(x)) * 0.01, 0);\n"
                 "  N = calculatenormal(P);\n"
                 "}\n");
}

/* Calls check on every displacement shader of the library (those below)
 * and of the corpus (corpus true); returns how many it was called on. */
static int each_displacement(void (*check)(sl_program *p, const char *name, bool corpus))
{
    int n = 0;
    static const char *const lib[] = { "heightmap", "dented", "wave", "nail", "threads", "ufo" };
    for (size_t i = 0; i < sizeof lib / sizeof lib[0]; i++) {
        sl_program *p = h_compile_library(lib[i]);
        if (!p)
            continue;
        if (sl_program_kind(p) == SL_SHADER_DISPLACEMENT) {
            check(p, lib[i], false);
            n++;
        }
        sl_program_destroy(&p);
    }
    DIR *d = opendir(AAFARM_CORPUS_DIR);
    assert_non_null(d);
    const char *name;
    sl_program *p;
    while ((p = h_next_program(d, AAFARM_CORPUS_DIR, &name))) {
        if (sl_program_kind(p) == SL_SHADER_DISPLACEMENT) {
            check(p, name, true);
            n++;
        }
        sl_program_destroy(&p);
    }
    closedir(d);
    return n;
}

static int g_checked;            /* the shaders a check below looked at */

static void check_box_runs(sl_program *p, const char *name, bool corpus)
{
    if (!sl_program_takes_derivatives(p))
        return;
    g_checked++;
    if (!corpus) {
        assert_int_equal(differing(p, name), 0);
        assert_int_equal(spoiled_differing(p, name), 0);
        return;
    }
    /* a shader that merges P after calculatenormal (a return after it,
     * an undecided branch around it) may give P other noise symbols:
     * calculatenormal no longer takes its three (box_plan.c); P then
     * still holds every sample */
    int renamed = 0;
    int bad = differing_as(p, name, false, &renamed);
    if (bad != -1) {      /* a texture shader without its maps fails both ways */
        assert_int_equal(bad, 0);
        assert_int_equal(spoiled_differing(p, name), 0);
    }
    if (renamed)
        fprintf(stderr, "%s: %d boxes with P on other symbols, samples inside\n", name, renamed);
}

static void test_library_and_corpus(void **state)
{
    (void)state;
    g_checked = 0;
    each_displacement(check_box_runs);
    fprintf(stderr, "%d library and corpus shaders that take derivatives\n", g_checked);
    assert_true(g_checked >= 3);
}

static void test_plan(void **state)
{
    (void)state;
    sl_program *p = h_compile(TERRAIN);
    assert_non_null(p);
    assert_non_null(p->box_plan);
    int cn = h_find_op(p, SL_OP_CALCNORMAL, 0), inv = h_find_op(p, SL_OP_INVSQRT, 0);
    int du = h_find_op(p, SL_OP_DU, 0);
    assert_true(cn >= 0 && inv >= 0 && du >= 0);
    assert_int_equal(p->box_plan[cn], SL_BOX_DEAD);       /* only N reads it */
    assert_int_equal(p->box_plan[inv], SL_BOX_VALUE);     /* normalize(N) */
    /* ss = s * 2, whose derivative Du reads */
    int mul = h_find_op(p, SL_OP_MUL, 0);
    assert_true(mul >= 0 && mul < du);
    assert_int_equal(p->box_plan[mul], SL_BOX_RUN);
    /* what its box runs read of the globals: s and t with their
     * derivative bounds (the filter width), N's value (normalize), P's
     * value; not the tangents, nor P's derivative bounds (calculatenormal
     * alone read them) */
    assert_true(sl_program_box_reads(p, SL_G_s, true) && sl_program_box_reads(p, SL_G_t, true));
    assert_true(sl_program_box_reads(p, SL_G_N, false) && sl_program_box_reads(p, SL_G_P, false));
    assert_false(sl_program_box_reads(p, SL_G_dPdu, false));
    assert_false(sl_program_box_reads(p, SL_G_dPdv, false));
    assert_false(sl_program_box_reads(p, SL_G_P, true));
    assert_false(sl_program_box_reads(p, SL_G_I, true));
    assert_false(sl_program_box_reads(p, SL_G_N, true));
    sl_program_destroy(&p);

    /* Du(P) and a tangent reach P: read */
    p = h_compile("displacement t() { P += Du(P) * 0.01 + dPdv * 0.01;"
                  " N = calculatenormal(P); }");
    assert_non_null(p);
    assert_non_null(p->box_plan);
    assert_true(sl_program_box_reads(p, SL_G_P, true));
    assert_true(sl_program_box_reads(p, SL_G_dPdv, false));
    assert_false(sl_program_box_reads(p, SL_G_dPdu, false));
    sl_program_destroy(&p);

    p = h_compile("displacement t() { float h = 0; for (float i = 0; i < 3; i += 1)"
                  " h += Du(s * i); P += h * normalize(N); N = calculatenormal(P); }");
    assert_non_null(p);
    /* a loop: the liveness passes until nothing grows (box_plan.c); in
     * the loop s * i keeps its derivative (Du reads it), the sum h its
     * value alone; calculatenormal is left out */
    assert_non_null(p->box_plan);
    cn = h_find_op(p, SL_OP_CALCNORMAL, 0);
    du = h_find_op(p, SL_OP_DU, 0);
    int lt = h_find_op(p, SL_OP_LOOP_TEST, 0);
    mul = h_find_op(p, SL_OP_MUL, lt);
    int add = h_find_op(p, SL_OP_ADD, du);
    assert_true(cn >= 0 && du >= 0 && lt >= 0 && mul > lt && mul < du && add > du);
    assert_int_equal(p->box_plan[cn], SL_BOX_DEAD);
    assert_int_equal(p->box_plan[mul], SL_BOX_RUN);
    assert_int_equal(p->box_plan[add], SL_BOX_VALUE);
    assert_false(sl_program_box_reads(p, SL_G_dPdu, false));
    assert_false(sl_program_box_reads(p, SL_G_P, true));
    assert_true(sl_program_box_reads(p, SL_G_s, true));
    sl_program_destroy(&p);

    /* what a later iteration reads is live in an earlier one: x feeds P
     * only through y, read in the next pass round the loop */
    p = h_compile("displacement t() { float x = 0, y = 0, w = Du(s);"
                  " for (float i = 0; i < 3; i += 1) { y += x; x = s * t; }"
                  " P += (y + w) * normalize(N); N = calculatenormal(P); }");
    assert_non_null(p);
    assert_non_null(p->box_plan);
    lt = h_find_op(p, SL_OP_LOOP_TEST, 0);
    mul = h_find_op(p, SL_OP_MUL, lt);
    assert_true(lt >= 0 && mul > lt);
    assert_int_equal(p->box_plan[mul], SL_BOX_VALUE);         /* x = s * t */
    sl_program_destroy(&p);
}

/* heightmap.sl (scenes/shaders) with its map named: the main lookup and
 * the detail layer, both blurred by the filter width */
static const char LOOKUPS[] =
    "displacement t(float Km = 0.3, detail = 0.15, detailrepeat = 6, blur = 1) {\n"
    "  float ss = s, tt = t;\n"
    "  float fw = max(abs(Du(ss) * du) + abs(Dv(ss) * dv),\n"
    "                 abs(Du(tt) * du) + abs(Dv(tt) * dv));\n"
    "  float h = texture(\"h.tx\"[0], ss, tt, \"blur\", blur * fw);\n"
    "  h += detail * texture(\"h.tx\"[0], ss * detailrepeat, tt * detailrepeat,\n"
    "                        \"blur\", blur * fw * detailrepeat);\n"
    "  P += Km * h * normalize(N);\n"
    "  N = calculatenormal(P);\n"
    "}\n";

/* the same bits (and, with flags, the same flags) */
static bool same_interval(ia_interval a, ia_interval b, bool flags)
{
    return memcmp(&a.lo, &b.lo, sizeof a.lo) == 0 && memcmp(&a.hi, &b.hi, sizeof a.hi) == 0 &&
           (!flags || a.flags == b.flags);
}

/* The boxes (of 2 x 30) where an interval run's P (slopes: a slope run's
 * P and P's slope bounds) differs with the plans (box runs) and without */
static int interval_differing(const sl_program *p, const char *what, bool slopes)
{
    sl_instance *inst = sl_instance_new(p);
    sl_vm *vm = sl_vm_new(NULL);
    if (g_textures)
        sl_vm_set_textures(vm, g_textures);
    unsigned long long seed = 0x1a7ull;
    int bad = 0;
    for (int si = 0; si < 2; si++)
        for (int k = 0; k < 30; k++) {
            double box[4];
            h_box(&seed, k, box);
            ia_interval P[2][3], Pu[2][3], Pv[2][3];
            sl_status st[2];
            for (int plan = 0; plan < 2; plan++) {
                sl_vm_set_box_runs(vm, plan);
                h_globals_interval(vm, si ? H_SPHERE : H_PLANE, box[0], box[1], box[2], box[3]);
                st[plan] = slopes ? sl_vm_run_slopes(vm, inst)
                                  : sl_vm_run(vm, inst, SL_MODE_INTERVAL, NULL);
                sl_vm_get_interval(vm, SL_G_P, P[plan]);
                if (slopes)
                    sl_vm_get_slopes(vm, SL_G_P, Pu[plan], Pv[plan]);
            }
            bool same = st[0] == st[1];
            /* a box run's flags may differ after an undecided merge
             * (box_plan.c; the renderer reads the values of its interval
             * runs for P alone), a slope run's may not */
            for (int i = 0; i < 3 && same && st[0] == SL_OK; i++)
                same = same_interval(P[0][i], P[1][i], slopes) &&
                       (!slopes || (same_interval(Pu[0][i], Pu[1][i], true) &&
                                    same_interval(Pv[0][i], Pv[1][i], true)));
            if (!same && bad < 3)
                fprintf(stderr, "%s: %s run, box [%g %g]x[%g %g]: P.x [%.17g, %.17g] with the "
                        "plan, [%.17g, %.17g] without; dP.x/du [%.17g, %.17g], [%.17g, %.17g]\n",
                        what, slopes ? "slope" : "interval", box[0], box[1], box[2], box[3],
                        P[1][0].lo, P[1][0].hi, P[0][0].lo, P[0][0].hi, Pu[1][0].lo,
                        Pu[1][0].hi, Pu[0][0].lo, Pu[0][0].hi);
            bad += !same;
        }
    sl_vm_destroy(&vm);
    sl_instance_destroy(&inst);
    return bad;
}

static void check_interval_runs(sl_program *p, const char *name, bool corpus)
{
    (void)corpus;
    assert_int_equal(interval_differing(p, name, false), 0);
    assert_int_equal(interval_differing(p, name, true), 0);
}

static void test_interval_and_slope_runs(void **state)
{
    (void)state;
    sl_program *t = h_compile(TERRAIN);
    assert_non_null(t);
    assert_non_null(t->slope_plan);
    int cn = h_find_op(t, SL_OP_CALCNORMAL, 0);
    assert_true(cn >= 0);
    assert_int_equal(t->slope_plan[cn], SL_BOX_DEAD);          /* only N reads it */
    assert_int_equal(interval_differing(t, "terrain", false), 0);
    assert_int_equal(interval_differing(t, "terrain", true), 0);
    sl_program_destroy(&t);
    int checked = each_displacement(check_interval_runs);
    fprintf(stderr, "%d library and corpus shaders: interval and slope runs\n", checked);
    assert_true(checked >= 40);
}

static void test_lookups(void **state)
{
    (void)state;
    enum { W = 64 };
    static float px[W * W];
    unsigned long long rs = 11;
    for (int k = 0; k < W * W; k++)
        px[k] = (float)(h_rand(&rs) - 0.5);
    g_textures = tex_cache_new(0);
    assert_true(tex_cache_put(g_textures, "h.tx", tex_from_pixels(px, W, W, 1, "h.tx")));
    sl_program *p = h_compile(LOOKUPS);
    assert_non_null(p);
    assert_non_null(p->box_plan);
    int n = 0;
    for (int pc = h_find_op(p, SL_OP_TEXTURE, 0); pc >= 0; pc = h_find_op(p, SL_OP_TEXTURE, pc + 1)) {
        assert_int_equal(p->box_plan[pc], SL_BOX_VALUE);
        n++;
    }
    assert_int_equal(n, 2);
    assert_int_equal(differing(p, "lookups"), 0);
    assert_int_equal(spoiled_differing(p, "lookups"), 0);
    sl_program_destroy(&p);
    tex_cache_destroy(&g_textures);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_P),
        cmocka_unit_test(test_library_and_corpus),
        cmocka_unit_test(test_plan),
        cmocka_unit_test(test_lookups),
        cmocka_unit_test(test_interval_and_slope_runs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

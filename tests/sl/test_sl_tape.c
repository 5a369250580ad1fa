/*
 * tests/sl/test_sl_tape.c: tape pruning of box runs (tape_plan.c,
 * sl_vm_set_tape, issue 24): the decisions a node's box run proves, taken
 * by its children's runs, leave their P an enclosure of the surface.
 *
 *   sites      a clamped fBm's max and min are tape sites, normalize's
 *              clamps (nothing dead either way) are not; deciding the max
 *              for its lower bound leaves every noise of the fBm dead; a
 *              step decided 0 makes its product with a noise 0 and the
 *              noise dead (constants through arithmetic), decided 1 the
 *              product the noise
 *   children   for shaders with min, max, clamp, step, smoothstep masks
 *              and branches on noise, plain and derivative-carrying, on
 *              the plane and the sphere: a parent box's recorded run
 *              gives a tape; each child (the four quarters, two random
 *              boxes inside) run with the tape's plan gives P holding the
 *              float P at 5 x 5 points, and a tape that keeps the
 *              parent's decisions; enough parents decide something
 *   loops      a site whose executions in a loop choose differently is
 *              left undecided (a decision from the first one alone would
 *              drop the second's noise: the children's samples fall out)
 */
#include <stddef.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/bytecode.h"
#include "sl_harness.h"

/* P at 5 x 5 points of the box (edges included), by the dual mode (Du and
 * Dv as the range runs' derivatives have them), inside P's ranges (the
 * point run's rounding: 1e-9, as test_sl_bounds); the number of points
 * outside */
static int outside(sl_vm *vm, const sl_instance *inst, h_surface s, const double box[4],
                   const aa_form P[3])
{
    int bad = 0;
    for (int a = 0; a <= 4; a++)
        for (int b = 0; b <= 4; b++) {
            double u = box[0] + (box[1] - box[0]) * a / 4, v = box[2] + (box[3] - box[2]) * b / 4;
            double f[3];
            sl_dual d[3];
            h_globals_dual(vm, s, u, v);       /* the point with its derivatives */
            if (sl_vm_run(vm, inst, SL_MODE_DUAL, NULL) != SL_OK)
                continue;
            sl_vm_get_dual(vm, SL_G_P, d);
            for (int i = 0; i < 3; i++)
                f[i] = d[i].v;
            for (int i = 0; i < 3; i++) {
                ia_interval r = aa_range(&P[i]);
                double tol = 1e-9 * (1 + fabs(f[i]));
                if (!(f[i] >= r.lo - tol && f[i] <= r.hi + tol)) {
                    bad++;
                    break;
                }
            }
        }
    return bad;
}

/* One recorded box run over box with the plan of tape (NULL plan: none);
 * its P and the tape it proved */
static sl_status run_box(sl_vm *vm, const sl_instance *inst, aa_context *ctx, h_surface s,
                         const double box[4], const uint8_t *plan, uint32_t tape, aa_form P[3],
                         uint32_t *out)
{
    sl_vm_set_box_runs(vm, true);
    sl_vm_set_tape(vm, plan, tape, true);
    h_globals_affine(vm, ctx, s, box[0], box[1], box[2], box[3]);
    sl_status st = sl_vm_run(vm, inst, SL_MODE_AFFINE, ctx);
    if (st == SL_OK)
        sl_vm_get_affine(vm, SL_G_P, P);
    *out = sl_vm_tape(vm);
    sl_vm_set_tape(vm, NULL, 0, false);
    return st;
}

typedef struct tally {
    int parents, decided, children, bad;
} tally;

/* Parents of 2 x 40 boxes (h_box: sides 0.3, 0.03 and 0.002) on plane
 * and sphere; each decided parent's six children run with its tape */
static tally check_children(const char *src)
{
    tally t = {0, 0, 0, 0};
    h_session h;
    h_session_open(&h, src);
    const sl_program *p = h.p;
    const sl_instance *inst = h.inst;
    sl_vm *vm = h.vm;
    unsigned long long seed = 0x7a9eull;
    for (int si = 0; si < 2; si++) {
        h_surface s = si == 0 ? H_PLANE : H_SPHERE;
        for (int k = 0; k < 40; k++) {
            double box[4];
            h_box(&seed, k, box);
            aa_form P[3];
            uint32_t tape;
            if (run_box(vm, inst, &h.ctx, s, box, NULL, 0, P, &tape) != SL_OK)
                continue;
            t.parents++;
            if (tape == 0)
                continue;
            t.decided++;
            uint8_t *plan = sl_program_tape_plan(p, tape);
            assert_non_null(plan);
            double um = 0.5 * (box[0] + box[1]), vm_ = 0.5 * (box[2] + box[3]);
            double kids[6][4] = {
                {box[0], um, box[2], vm_}, {um, box[1], box[2], vm_},
                {box[0], um, vm_, box[3]}, {um, box[1], vm_, box[3]},
            };
            for (int j = 4; j < 6; j++) {
                double a = h_rand(&seed), b = h_rand(&seed), c = h_rand(&seed),
                       d = h_rand(&seed);
                double u0 = box[0] + (box[1] - box[0]) * fmin(a, b);
                double u1 = box[0] + (box[1] - box[0]) * fmax(a, b);
                double v0 = box[2] + (box[3] - box[2]) * fmin(c, d);
                double v1 = box[2] + (box[3] - box[2]) * fmax(c, d);
                kids[j][0] = u0, kids[j][1] = u1, kids[j][2] = v0, kids[j][3] = v1;
            }
            for (int j = 0; j < 6; j++) {
                aa_form Q[3];
                uint32_t kt;
                if (run_box(vm, inst, &h.ctx, s, kids[j], plan, tape, Q, &kt) != SL_OK)
                    continue;
                t.children++;
                assert_int_equal(kt & tape, tape);      /* the parent's decisions kept */
                int bad = outside(vm, inst, s, kids[j], Q);
                if (bad && t.bad < 3)
                    fprintf(stderr, "%s\n  child [%g %g]x[%g %g] of tape %#x: %d samples "
                            "outside\n", src, kids[j][0], kids[j][1], kids[j][2], kids[j][3],
                            (unsigned)tape, bad);
                t.bad += bad;
            }
            free(plan);
        }
    }
    h_session_close(&h);
    fprintf(stderr, "%d parents, %d decided, %d children, %d samples outside\n", t.parents,
            t.decided, t.children, t.bad);
    return t;
}

/* mesa_clamp (tests/shaders/corpus) written out: fBm clamped */
#define FBM4                                                                  \
    "  float h = 0, a = 1, i; point pp = transform(\"shader\", P) * 3;\n"     \
    "  for (i = 0; i < 4; i += 1) { h += a * (2 * noise(pp) - 1); a *= 0.5; pp *= 2; }\n"
static const char MESA[] =
    "displacement t(float Km = 0.05, lo = -0.05, hi = 0.05) {\n" FBM4
    "  h = min(max(h, lo), hi);\n"
    "  P += Km * h * normalize(N);\n"
    "  N = calculatenormal(P);\n"
    "}\n";

static int site_index(const sl_program *p, int pc)
{
    for (int i = 0; i < p->ntape_sites; i++)
        if (p->tape_site[i] == pc)
            return i;
    return -1;
}

static void test_sites(void **state)
{
    (void)state;
    sl_program *p = h_compile(MESA);
    assert_non_null(p);
    int mx = h_find_op(p, SL_OP_MAX, 0), mn = h_find_op(p, SL_OP_MIN, 0);
    assert_true(mx >= 0 && mn > mx);
    int smx = site_index(p, mx), smn = site_index(p, mn);
    assert_true(smx >= 0 && smn >= 0);
    /* normalize(N)'s clamps to [-1, 1]: nothing dies either way */
    for (int pc = h_find_op(p, SL_OP_CLAMP, 0); pc >= 0; pc = h_find_op(p, SL_OP_CLAMP, pc + 1))
        assert_int_equal(site_index(p, pc), -1);
    /* the max decided for lo: the fBm's noises are dead, P's sum is not */
    uint8_t *plan = sl_program_tape_plan(p, 2u << (SL_TAPE_BITS * smx));
    assert_non_null(plan);
    assert_int_equal(plan[mx], SL_BOX_TAKE_C);
    int noises = 0;
    for (int pc = h_find_op(p, SL_OP_NOISE, 0); pc >= 0; pc = h_find_op(p, SL_OP_NOISE, pc + 1)) {
        assert_int_equal(plan[pc], SL_BOX_DEAD);
        noises++;
    }
    assert_true(noises >= 1);
    assert_int_not_equal(plan[mn], SL_BOX_DEAD);
    free(plan);
    /* undecided: no plan */
    assert_null(sl_program_tape_plan(p, 0));
    sl_program_destroy(&p);

    /* constants through arithmetic: a step decided 0 makes its product
     * with a noise 0, and the noise dead; decided 1, the product is the
     * noise */
    p = h_compile("displacement t() { point q = transform(\"shader\", P) * 3;\n"
                  "  float h = 0.2 * noise(q) + step(0.5, t) * noise(q * 9);\n"
                  "  P += 0.05 * h * normalize(N); N = calculatenormal(P); }");
    assert_non_null(p);
    int st = h_find_op(p, SL_OP_STEP, 0), sst = site_index(p, st);
    int n1 = h_find_op(p, SL_OP_NOISE, 0), n2 = h_find_op(p, SL_OP_NOISE, n1 + 1);
    assert_true(st >= 0 && sst >= 0 && n1 >= 0 && n2 > n1);
    int mul = h_find_op(p, SL_OP_MUL, n2);                  /* step * noise */
    int add = h_find_op(p, SL_OP_ADD, mul);                 /* 0.2 * noise + that */
    assert_true(mul > n2 && add > mul);
    plan = sl_program_tape_plan(p, 1u << (SL_TAPE_BITS * sst));       /* step: 0 */
    assert_non_null(plan);
    assert_int_equal(plan[add], SL_BOX_TAKE_B);             /* the sum: its first term */
    assert_int_equal(plan[mul], SL_BOX_DEAD);               /* the product 0, unread */
    assert_int_equal(plan[n2], SL_BOX_DEAD);
    assert_int_equal(plan[st], SL_BOX_DEAD);
    assert_int_not_equal(plan[n1], SL_BOX_DEAD);
    free(plan);
    plan = sl_program_tape_plan(p, 2u << (SL_TAPE_BITS * sst));       /* step: 1 */
    assert_non_null(plan);
    assert_int_equal(plan[mul], SL_BOX_TAKE_C);
    assert_int_not_equal(plan[n2], SL_BOX_DEAD);
    assert_int_equal(plan[st], SL_BOX_DEAD);
    free(plan);
    sl_program_destroy(&p);

    /* a program without a choice that kills anything has no site */
    p = h_compile("displacement t() { P += 0.1 * noise(P) * normalize(N); }");
    assert_non_null(p);
    assert_int_equal(p->ntape_sites, 0);
    assert_null(p->tape_site_of);
    sl_program_destroy(&p);
}

static void test_children(void **state)
{
    (void)state;
    static const char *const shaders[] = {
        MESA,
        /* the same carrying derivatives (a filter width before P) */
        "displacement t(float Km = 0.05, lo = -0.05, hi = 0.05) {\n" FBM4
        "  float fw = abs(Du(s)) + abs(Dv(t));\n"
        "  h = clamp(h, lo, hi) + 0.01 * fw;\n"
        "  P += Km * h * normalize(N);\n"
        "  N = calculatenormal(P);\n"
        "}\n",
        /* the larger of two noises */
        "displacement t() {\n"
        "  point q = transform(\"shader\", P) * 4;\n"
        "  float a = noise(q) + 2 * s, b = noise(q * 3 + 7) + 2 * t;\n"
        "  P += 0.05 * max(a, b) * normalize(N);\n"
        "  N = calculatenormal(P);\n"
        "}\n",
        /* a mask: two layers mixed by a saturating smoothstep of s */
        "displacement t() {\n"
        "  point q = transform(\"shader\", P) * 5;\n"
        "  float rock = noise(q), sand = 0.3 * noise(q * 8);\n"
        "  float m = smoothstep(0.45, 0.55, s);\n"
        "  P += 0.05 * mix(rock, sand, m) * normalize(N);\n"
        "  N = calculatenormal(P);\n"
        "}\n",
        /* a branch on noise, a step of t */
        "displacement t() {\n"
        "  point q = transform(\"shader\", P) * 3;\n"
        "  float h = 0;\n"
        "  if (noise(q) + 2 * s > 1.5) h = noise(q * 4); else h = -0.5 * noise(q * 2);\n"
        "  h += step(0.5, t) * noise(q * 9);\n"
        "  P += 0.05 * h * normalize(N);\n"
        "  N = calculatenormal(P);\n"
        "}\n",
    };
    for (size_t i = 0; i < sizeof shaders / sizeof shaders[0]; i++) {
        tally t = check_children(shaders[i]);
        assert_int_equal(t.bad, 0);
        assert_true(t.decided >= 5);           /* the test sees decisions */
        assert_true(t.children >= 6 * t.decided - 6);
    }
}

static void test_loops(void **state)
{
    (void)state;
    /* max(noise - 1.5, 0) is 0 in the first iteration, the noise in the
     * second: the site's executions disagree in every box */
    static const char LOOP[] =
        "displacement t() {\n"
        "  point q = transform(\"shader\", P) * 4;\n"
        "  float h = 0, i;\n"
        "  for (i = 0; i < 2; i += 1) h += max(noise(q * (i + 1)) + 2 * i - 1.5, 0);\n"
        "  P += 0.05 * h * normalize(N);\n"
        "  N = calculatenormal(P);\n"
        "}\n";
    h_session h;
    h_session_open(&h, LOOP);
    int mx = h_find_op(h.p, SL_OP_MAX, 0);
    int site = site_index(h.p, mx);
    assert_true(site >= 0);
    unsigned long long seed = 0x100bull;
    for (int k = 0; k < 25; k++) {
        double box[4];
        h_box(&seed, k, box);
        aa_form P[3];
        uint32_t tape;
        assert_int_equal(run_box(h.vm, h.inst, &h.ctx, H_PLANE, box, NULL, 0, P, &tape), SL_OK);
        assert_int_equal(tape >> (SL_TAPE_BITS * site) & 3u, 0);
    }
    h_session_close(&h);
    tally t = check_children(LOOP);
    assert_int_equal(t.bad, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sites),
        cmocka_unit_test(test_children),
        cmocka_unit_test(test_loops),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

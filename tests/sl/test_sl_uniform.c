/*
 * tests/sl/test_sl_uniform.c: the uniform memo of the affine VMs
 * (vm_uniform.inc) changes no bit of any result, and answers what it
 * should.
 *
 *   same forms   every library and corpus shader, on random boxes of the
 *                plane and the sphere, box runs on and off, contexts of 8
 *                and of 3 noise symbols: P and N of a VM with the memo
 *                equal those of a VM without it, form for form (centre,
 *                coefficients, error, hull, flags), and the runs' statuses
 *   context      an operation on symbol-free operands that folds its
 *                error where the context is spent and takes a symbol where
 *                it is not (Du of a range) gives what a VM without the
 *                memo gives, in boxes where a branch has or has not taken
 *                the last symbol
 *   instances    one program, two instances of different parameters, one
 *                VM: each run equals the memo-less run
 *   derivatives  Du of a varying value whose derivative bounds vary by box
 *   answers      a height map's filter width and normalize(N) on the plane
 *                (every operation of them uniform) come from the memo from
 *                the second box on; with the memo off, none do
 */
#include <dirent.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "sl/bytecode.h"
#include "sl_harness.h"

#ifndef AAFARM_CORPUS_DIR
#define AAFARM_CORPUS_DIR "tests/shaders/corpus"
#endif

static int g_prints;              /* mismatches printed since the last reset */

typedef struct run_pair {
    sl_vm *on, *off;              /* the memo on, off */
    aa_context ctx_on, ctx_off;
} run_pair;

static void pair_init(run_pair *r, int capacity)
{
    r->on = sl_vm_new(NULL);
    r->off = sl_vm_new(NULL);
    sl_vm_set_uniform_memo(r->off, false);
    aa_context_init(&r->ctx_on, capacity);
    aa_context_init(&r->ctx_off, capacity);
}

static void pair_free(run_pair *r)
{
    sl_vm_destroy(&r->on);
    sl_vm_destroy(&r->off);
}

/* One box in both VMs; true when their statuses, P and N and the
 * contexts' counts agree */
static bool same_run(run_pair *r, const sl_instance *inst, h_surface s, const double box[4],
                     bool box_runs, const char *what)
{
    sl_status st[2];
    aa_form P[2][3], N[2][3];
    for (int k = 0; k < 2; k++) {
        sl_vm *vm = k ? r->off : r->on;
        aa_context *ctx = k ? &r->ctx_off : &r->ctx_on;
        sl_vm_set_box_runs(vm, box_runs);
        h_globals_affine(vm, ctx, s, box[0], box[1], box[2], box[3]);
        st[k] = sl_vm_run(vm, inst, SL_MODE_AFFINE, ctx);
        sl_vm_get_affine(vm, SL_G_P, P[k]);
        sl_vm_get_affine(vm, SL_G_N, N[k]);
    }
    bool same = st[0] == st[1] && r->ctx_on.used == r->ctx_off.used &&
                r->ctx_on.folded == r->ctx_off.folded;
    for (int i = 0; i < 3 && same && st[0] == SL_OK; i++)
        same = h_same_form(&P[0][i], &P[1][i]) && h_same_form(&N[0][i], &N[1][i]);
    if (!same && g_prints++ < 3) {
        ia_interval a = aa_range(&P[0][0]), b = aa_range(&P[1][0]);
        fprintf(stderr, "%s (%s, box runs %d) box [%g %g]x[%g %g]: status %d / %d, used %d / "
                "%d, P.x [%.17g, %.17g] with the memo, [%.17g, %.17g] without\n", what,
                s == H_PLANE ? "plane" : "sphere", (int)box_runs, box[0], box[1], box[2],
                box[3], (int)st[0], (int)st[1], r->ctx_on.used, r->ctx_off.used, a.lo, a.hi,
                b.lo, b.hi);
    }
    return same;
}

/* The boxes of p whose runs differ with and without the memo (2 surfaces x
 * 40 boxes, a box run every third); *hits: the memo's answers */
static int differing(const sl_program *p, const char *what, int capacity, long *hits)
{
    sl_instance *inst = sl_instance_new(p);
    run_pair r;
    pair_init(&r, capacity);
    unsigned long long seed = 0x0c0ffee5ull;
    int bad = 0;
    g_prints = 0;
    for (int si = 0; si < 2; si++)
        for (int k = 0; k < 40; k++) {
            double box[4];
            h_box(&seed, k, box);
            bad += !same_run(&r, inst, si ? H_SPHERE : H_PLANE, box, k % 3 == 2, what);
        }
    assert_int_equal(sl_vm_uniform_hits(r.off), 0);
    *hits += sl_vm_uniform_hits(r.on);
    pair_free(&r);
    sl_instance_destroy(&inst);
    return bad;
}

static void test_same_forms(void **state)
{
    (void)state;
    static const char *const dirs[] = { AAFARM_SHADER_DIR, AAFARM_CORPUS_DIR };
    int checked = 0, bad = 0;
    long hits = 0;
    for (size_t di = 0; di < 2; di++) {
        DIR *d = opendir(dirs[di]);
        assert_non_null(d);
        const char *name;
        sl_program *p;
        while ((p = h_next_program(d, dirs[di], &name))) {
            bad += differing(p, name, AA_DEFAULT_CAPACITY, &hits);
            bad += differing(p, name, 3, &hits);
            checked++;
            sl_program_destroy(&p);
        }
        closedir(d);
    }
    fprintf(stderr, "%d library and corpus shaders, %ld answers from the memo\n", checked, hits);
    assert_true(checked >= 40);
    assert_true(hits > 0);
    assert_int_equal(bad, 0);
}

/* Du(s * (k + 0.1)) is the same range (k + 0.1 rounded) in every box:
 * a fresh symbol where the context has one left, err where it has none;
 * the branch takes the third symbol of a 3-symbol context (u, v, sin's)
 * in boxes right of s = 0.5 only */
static const char CONTEXT[] =
    "displacement t(float k = 0.3) {\n"
    "  float h = 0;\n"
    "  if (s > 0.5) h = sin(s * 3);\n"
    "  float c = Du(s * (k + 0.1)) * 0.2;\n"
    "  P += (h * 0.1 + c) * normalize(N);\n"
    "  N = calculatenormal(P);\n"
    "}\n";

static void test_context(void **state)
{
    (void)state;
    sl_program *p = h_compile(CONTEXT);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    run_pair r;
    pair_init(&r, 3);
    unsigned long long seed = 0x5eedull;
    int bad = 0;
    for (int k = 0; k < 60; k++) {
        /* boxes right of 0.5, left of it, and across it, in turn */
        double u0 = k % 3 == 0 ? 0.55 + 0.3 * h_rand(&seed) : k % 3 == 1 ? 0.05 + 0.3 * h_rand(&seed)
                                                                        : 0.45;
        double v0 = 0.1 + 0.8 * h_rand(&seed);
        double box[4] = { u0, u0 + 0.04, v0, v0 + 0.04 };
        bad += !same_run(&r, inst, H_PLANE, box, false, "context");
    }
    assert_int_equal(bad, 0);
    assert_true(sl_vm_uniform_hits(r.on) > 0);
    pair_free(&r);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

static void test_instances(void **state)
{
    (void)state;
    sl_program *p = h_compile("displacement t(float Km = 0.1, freq = 4) {\n"
                  "  float w = abs(Du(s * freq) * du) + abs(Dv(t * freq) * dv);\n"
                  "  float a = Km / (1 + w), b = clamp(Km * freq, 0, 0.5);\n"
                  "  P += (a * sin(s * freq) + b) * normalize(N);\n"
                  "  N = calculatenormal(P);\n"
                  "}\n");
    assert_non_null(p);
    sl_instance *inst[2] = { sl_instance_new(p), sl_instance_new(p) };
    char err[256];
    const double km = 0.25, freq = 7;
    assert_true(sl_instance_set(inst[1], "Km", SL_TYPE_FLOAT, &km, 1, err, sizeof err));
    assert_true(sl_instance_set(inst[1], "freq", SL_TYPE_FLOAT, &freq, 1, err, sizeof err));
    run_pair r;
    pair_init(&r, AA_DEFAULT_CAPACITY);
    unsigned long long seed = 0xabcdefull;
    int bad = 0;
    for (int k = 0; k < 80; k++) {
        double box[4];
        h_box(&seed, k % 40, box);
        /* two runs of one instance, then one of the other */
        bad += !same_run(&r, inst[(k % 3) == 2], k & 1 ? H_SPHERE : H_PLANE, box, k % 5 == 0,
                         "instances");
    }
    assert_int_equal(bad, 0);
    assert_true(sl_vm_uniform_hits(r.on) > 80);
    pair_free(&r);
    sl_instance_destroy(&inst[0]);
    sl_instance_destroy(&inst[1]);
    sl_program_destroy(&p);
}

static void test_derivatives(void **state)
{
    (void)state;
    /* Du(s * s) = 2 s: its bounds differ from box to box while the value
     * of k * 3 does not */
    sl_program *p = h_compile("displacement t(float k = 0.5) {\n"
                              "  float d = Du(s * s) * (k * 3);\n"
                              "  float e = Dv(t * k);\n"
                              "  P += (d * 0.01 + e * 0.02) * normalize(N);\n"
                              "  N = calculatenormal(P);\n"
                              "}\n");
    assert_non_null(p);
    long hits = 0;
    assert_int_equal(differing(p, "derivatives", AA_DEFAULT_CAPACITY, &hits), 0);
    assert_true(hits > 0);
    sl_program_destroy(&p);
}

/* heightmap.sl's filter width without the map, then its normalize(N) */
static const char WIDTH[] =
    "displacement t(float Km = 0.3, repeat = 4, blur = 1) {\n"
    "  float ss = s * repeat, tt = t * repeat;\n"
    "  float fw = max(abs(Du(ss) * du) + abs(Dv(ss) * dv),\n"
    "                 abs(Du(tt) * du) + abs(Dv(tt) * dv));\n"
    "  float h = sin(ss + blur * fw) * 0.1;\n"
    "  P += Km * h * normalize(N);\n"
    "  N = calculatenormal(P);\n"
    "}\n";

static void test_answers(void **state)
{
    (void)state;
    sl_program *p = h_compile(WIDTH);
    assert_non_null(p);
    sl_instance *inst = sl_instance_new(p);
    /* the uniform operations: Du/Dv (4), their products with du/dv (4),
     * abs (4), the sums (2), max, blur * fw; N.N (5), invsqrt, N * (3),
     * the clamps (3) */
    int uniform_ops = 0;
    for (int pc = 0; pc < p->ncode; pc++) {
        int op = p->code[pc].op;
        uniform_ops += op == SL_OP_DU || op == SL_OP_DV || op == SL_OP_ABS ||
                       op == SL_OP_MAX || op == SL_OP_INVSQRT || op == SL_OP_CLAMP;
    }
    assert_true(uniform_ops >= 13);
    run_pair r;
    pair_init(&r, AA_DEFAULT_CAPACITY);
    unsigned long long seed = 0x77ull;
    long before = 0;
    for (int k = 0; k < 30; k++) {
        double box[4];
        h_box(&seed, k, box);
        assert_true(same_run(&r, inst, H_PLANE, box, k & 1, "width"));
        long now = sl_vm_uniform_hits(r.on);
        /* the first box of each flavour (box runs on, off) fills the memo */
        if (k >= 2)
            assert_true(now - before >= uniform_ops);
        before = now;
    }
    assert_int_equal(sl_vm_uniform_hits(r.off), 0);
    pair_free(&r);
    sl_instance_destroy(&inst);
    sl_program_destroy(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_forms),
        cmocka_unit_test(test_context),
        cmocka_unit_test(test_instances),
        cmocka_unit_test(test_derivatives),
        cmocka_unit_test(test_answers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

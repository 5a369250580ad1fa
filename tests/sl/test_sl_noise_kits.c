/*
 * test_sl_noise_kits.c: the interval jets of noise's bounds (noise_bound.c)
 * run on a two-lane vector kit where the compiler has vector extensions
 * and on the scalar kit elsewhere (sl/noise_interval.h): both must give
 * the same bits, so that an image never depends on the compiler that built
 * the worker. This test is linked with a second copy of noise_bound.c
 * built with -DNOISE_IV_SCALAR (its functions renamed kits_scalar_*,
 * tests/sl/CMakeLists.txt) and compares the two on 40,000 random boxes in
 * 1 to 4 dimensions, a third of them on a lattice plane (the point axes)
 * and a third straddling one by a sliver, for each of the three box
 * methods: interval, affine (centre, every coefficient, error, hull) and
 * gradient results of noise, pnoise and the vector noise. 0 differences.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "aa/affine.h"
#include "sl/noise.h"
#include "sl/noise_interval.h"
#include "test_rng.h"

/* the scalar copy (tests/sl/CMakeLists.txt renames its functions) */
ia_interval kits_scalar_sl_noise_ia(int dim, const ia_interval *p);
ia_interval kits_scalar_sl_pnoise_ia(int dim, const ia_interval *p, const int *period);
void kits_scalar_sl_vnoise_ia(int dim, const ia_interval *p, ia_interval out[3]);
bool kits_scalar_sl_noise_gradient_ia(int dim, const ia_interval *p, const int *period,
                                      int component, ia_interval *value, ia_interval *grad);
void kits_scalar_sl_noise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p);
void kits_scalar_sl_vnoise_aa(aa_context *ctx, aa_form out[3], int dim, const aa_form *p);
void kits_scalar_sl_noise_set_box_method(int method);

enum { BOXES = 40000 };

static bool same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static long differ_iv(ia_interval a, ia_interval b)
{
    return !same_bits(a.lo, b.lo) || !same_bits(a.hi, b.hi);
}

static long differ_aa(const aa_form *a, const aa_form *b)
{
    if (a->n != b->n || a->flags != b->flags) return 1;
    long d = !same_bits(a->x0, b->x0) || !same_bits(a->err, b->err) ||
             !same_bits(a->lo, b->lo) || !same_bits(a->hi, b->hi);
    for (int j = 0; j < a->n; j++) d |= !same_bits(a->c[j], b->c[j]);
    return d;
}

static void test_vector_and_scalar_kits_agree(void **state)
{
    (void)state;
    printf("noise kits: the library's is %s\n",
           NOISE_IV_VECTOR ? "the vector kit" : "the scalar kit (this test compares it with itself)");
    long differ = 0, results = 0;
    for (int m = 0; m < 3; m++) {
        sl_noise_set_box_method(m);
        kits_scalar_sl_noise_set_box_method(m);
        uint64_t rng = 0x5eed0000ull + (uint64_t)m;
        for (int i = 0; i < BOXES; i++) {
            int dim = 1 + i % 4, kind = (i / 4) % 3;
            double w = pow(10.0, -4.0 + 4.3 * test_rng_unit(&rng));
            ia_interval P[4];
            aa_form in[4];
            aa_context c1, c2;
            aa_context_init(&c1, 8);
            for (int k = 0; k < dim; k++) {
                double a = floor(-50 + 100 * test_rng_unit(&rng)) + test_rng_unit(&rng);
                double b = a + w * (0.3 + 0.7 * test_rng_unit(&rng));
                if (kind == 1 && k == 1 % dim) {          /* on a lattice plane */
                    a = floor(a);
                    b = a + (test_rng_unit(&rng) < 0.5 ? 0.0 : 1e-12 * test_rng_unit(&rng));
                }
                if (kind == 2 && k == 0) {                /* a sliver over one */
                    a = floor(a) - 1e-13 * test_rng_unit(&rng);
                    b = floor(b) + 1e-13 * test_rng_unit(&rng);
                    if (b < a) b = a;
                }
                P[k] = ia_make(a, b);
                aa_input(&c1, &in[k], a, b);
            }
            c2 = c1;
            int period[4] = {3, 5, 7, 11};
            differ += differ_iv(sl_noise_ia(dim, P), kits_scalar_sl_noise_ia(dim, P));
            differ += differ_iv(sl_pnoise_ia(dim, P, period),
                                kits_scalar_sl_pnoise_ia(dim, P, period));
            ia_interval v1[3], v2[3];
            sl_vnoise_ia(dim, P, v1);
            kits_scalar_sl_vnoise_ia(dim, P, v2);
            for (int c = 0; c < 3; c++) differ += differ_iv(v1[c], v2[c]);
            ia_interval g1v, g2v, g1[4], g2[4];
            bool k1 = sl_noise_gradient_ia(dim, P, NULL, -1, &g1v, g1);
            bool k2 = kits_scalar_sl_noise_gradient_ia(dim, P, NULL, -1, &g2v, g2);
            differ += k1 != k2;
            if (k1 && k2) {
                differ += differ_iv(g1v, g2v);
                for (int k = 0; k < dim; k++) differ += differ_iv(g1[k], g2[k]);
            }
            aa_form o1, o2, w1[3], w2[3];
            sl_noise_aa(&c1, &o1, dim, in);
            kits_scalar_sl_noise_aa(&c2, &o2, dim, in);
            differ += differ_aa(&o1, &o2);
            sl_vnoise_aa(&c1, w1, dim, in);
            kits_scalar_sl_vnoise_aa(&c2, w2, dim, in);
            for (int c = 0; c < 3; c++) differ += differ_aa(&w1[c], &w2[c]);
            results += 12;
        }
    }
    sl_noise_set_box_method(SL_NOISE_BOX_AUTO);
    printf("noise kits: %ld results over %d boxes x 3 methods, %ld differ\n", results, BOXES,
           differ);
    assert_int_equal(differ, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_vector_and_scalar_kits_agree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * tests/sl/test_sl_noise_bits.c: noise's results keep their bits.
 *
 * Changes that only make noise cheaper (issue 24: the float jet, the Taylor
 * model, the interval jets) must give the same bits as before. This test
 * evaluates a fixed set of inputs, drawn from a fixed-seed generator:
 * boxes in 1D-4D of sides 1e-6 .. 0.6 (one cell, two cells, next to lattice
 * planes, ground-plane slivers), through each box method (auto, Taylor,
 * jets), in affine mode (sl_noise_aa, sl_pnoise_aa: the whole form),
 * interval mode (sl_noise_ia) and the gradient bounds
 * (sl_noise_gradient_ia, scalar and vector channels), and points through the float functions
 * (sl_noise, sl_noise_grad), and folds every result's bits into an FNV-1a
 * digest, compared with the digest of main at 1819638 (recorded by running
 * this file against that commit's libraries).
 *
 * A change that alters noise's results on purpose (tighter or looser, but
 * sound) updates NOISE_BITS_DIGEST and says in its commit why, with the
 * pixel count against the reference images (docs/noise.md); the digest of
 * each group is printed on failure to tell which part changed.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "aa/affine.h"
#include "aa/interval.h"
#include "sl/noise.h"
#include "test_rng.h"

/* main 1819638, before issue 24's session 17 (same-bits changes since),
 * but for session 26's roundings bounded a priori (the Taylor model's
 * value part, the fade and t(1 - t) at the interval jets' piece ends, the
 * box's reach and hull in noise_aa): the affine, interval and gradient
 * results differ from before in their last bits (the rule that picks the
 * interval jets compares them); the mean width over 500,000 boxes of
 * 10^-4 to 0.3 cells is the same to 9 digits (docs/benchmarks.md,
 * "Session 26"); and the float gradient (sl_noise_grad) by the float jet's
 * nested interpolations instead of the product form: within 6.7e-16 of
 * before at 1,000,000 random points, the value's bits unchanged */
#define NOISE_BITS_DIGEST_AFFINE 0x9925d10f24c4c006ull
#define NOISE_BITS_DIGEST_INTERVAL 0x976ea5ec99c77e72ull
#define NOISE_BITS_DIGEST_GRADIENT 0xd4b3e451695ee406ull
#define NOISE_BITS_DIGEST_FLOAT 0xc4c7d15d8df54251ull

#define NBOXES 1500

static uint64_t fold(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) {
        h ^= b[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

static uint64_t fold_d(uint64_t h, double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    return fold(h, &bits, sizeof bits);
}

static uint64_t fold_form(uint64_t h, const aa_form *f)
{
    h = fold_d(h, f->x0);
    h = fold_d(h, f->err);
    h = fold_d(h, f->lo);
    h = fold_d(h, f->hi);
    h = fold(h, &f->n, sizeof f->n);
    h = fold(h, &f->flags, sizeof f->flags);
    for (int i = 0; i < f->n; i++)
        h = fold_d(h, f->c[i]);
    return h;
}

/* one box: lower corner and sides by kind */
static void draw_box(uint64_t *rng, int dim, int kind, double lo[4], double hi[4])
{
    static const double sides[6] = { 1e-6, 1e-4, 1e-3, 0.02, 0.1, 0.6 };
    double w = sides[test_rng_int(rng, 6)];
    for (int k = 0; k < dim; k++) {
        double a = 40.0 * test_rng_unit(rng) - 20.0;
        if (kind == 1)                      /* across a lattice plane */
            a = floor(a) + 1.0 - 0.5 * w * test_rng_unit(rng);
        if (kind == 2 && k == 1) {          /* a ground-plane sliver */
            lo[k] = -0x1p-40;
            hi[k] = 0x1p-40;
            continue;
        }
        lo[k] = a;
        hi[k] = a + w * (0.25 + 0.75 * test_rng_unit(rng));
    }
}

typedef struct digests {
    uint64_t affine, interval, gradient, flt;
} digests;

static digests run(void)
{
    static const int methods[3] = { SL_NOISE_BOX_AUTO, SL_NOISE_BOX_TAYLOR,
                                    SL_NOISE_BOX_JETS };
    static const int period[4] = { 3, 5, 4, 7 };
    digests d = { 0xcbf29ce484222325ull, 0xcbf29ce484222325ull,
                  0xcbf29ce484222325ull, 0xcbf29ce484222325ull };
    aa_context ctx;
    aa_context_init(&ctx, AA_MAX_SYMBOLS);
    for (int m = 0; m < 3; m++) {
        sl_noise_set_box_method(methods[m]);
        uint64_t rng = 0x5e55107ull + (uint64_t)m;
        for (int i = 0; i < NBOXES; i++) {
            int dim = 1 + i % 4, kind = (i / 4) % 3;
            double lo[4], hi[4];
            draw_box(&rng, dim, kind, lo, hi);
            aa_form in[4], out;
            ia_interval box[4];
            aa_context_reset(&ctx);
            for (int k = 0; k < dim; k++) {
                aa_input(&ctx, &in[k], lo[k], hi[k]);
                box[k] = ia_make(lo[k], hi[k]);
            }
            sl_noise_aa(&ctx, &out, dim, in);
            d.affine = fold_form(d.affine, &out);
            sl_pnoise_aa(&ctx, &out, dim, in, period);
            d.affine = fold_form(d.affine, &out);
            ia_interval r = sl_noise_ia(dim, box);
            d.interval = fold_d(fold_d(d.interval, r.lo), r.hi);
            for (int ch = -1; ch < 3; ch++) {      /* noise, vnoise's channels */
                ia_interval v, g[4];
                bool ok = sl_noise_gradient_ia(dim, box, ch == 1 ? period : NULL, ch,
                                               &v, g);
                d.gradient = fold(d.gradient, &ok, 1);
                if (!ok)
                    continue;
                d.gradient = fold_d(fold_d(d.gradient, v.lo), v.hi);
                for (int k = 0; k < dim; k++)
                    d.gradient = fold_d(fold_d(d.gradient, g[k].lo), g[k].hi);
            }
            if (m == 0) {
                double p[4], grad[4];
                for (int k = 0; k < dim; k++)
                    p[k] = lo[k] + (hi[k] - lo[k]) * test_rng_unit(&rng);
                d.flt = fold_d(d.flt, sl_noise(dim, p));
                d.flt = fold_d(d.flt, sl_noise_grad(dim, p, NULL, grad));
                for (int k = 0; k < dim; k++)
                    d.flt = fold_d(d.flt, grad[k]);
            }
        }
    }
    sl_noise_set_box_method(SL_NOISE_BOX_AUTO);
    return d;
}

static void test_same_bits(void **state)
{
    (void)state;
    digests d = run();
    printf("noise bits: affine 0x%016llx interval 0x%016llx gradient 0x%016llx "
           "float 0x%016llx\n", (unsigned long long)d.affine,
           (unsigned long long)d.interval, (unsigned long long)d.gradient,
           (unsigned long long)d.flt);
    assert_true(d.affine == NOISE_BITS_DIGEST_AFFINE);
    assert_true(d.interval == NOISE_BITS_DIGEST_INTERVAL);
    assert_true(d.gradient == NOISE_BITS_DIGEST_GRADIENT);
    assert_true(d.flt == NOISE_BITS_DIGEST_FLOAT);
}

/* the same inputs twice give the same digests (nothing depends on state
 * left behind: the box method is restored, no static caches) */
static void test_repeatable(void **state)
{
    (void)state;
    digests a = run(), b = run();
    assert_true(a.affine == b.affine && a.interval == b.interval &&
                a.gradient == b.gradient && a.flt == b.flt);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_bits),
        cmocka_unit_test(test_repeatable),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

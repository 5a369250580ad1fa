/*
 * cellnoise_bound.c: proven bounds of cellnoise over a box, the interval
 * and affine modes (the interface: noise.h; the point function: noise.c).
 *
 * cellnoise is constant on each unit cell of the integer lattice, so its
 * range over a box is the hull of the values of the cells the box meets:
 * exact, by enumeration, up to CELLNOISE_MAX_CELLS cells; beyond, the
 * global range. A box inside one cell gives a constant (in affine mode a
 * form with no noise symbol); one across a lattice plane is marked
 * AA_DISCONTINUOUS, since the value jumps there.
 */
#include "sl/noise.h"
#include "sl/noise_internal.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

/* Cellnoise enumerates at most this many cells of a box. */
#define CELLNOISE_MAX_CELLS 64

/* ---- interval mode ---- */

#define CELL_MAX_VALUE (1.0 - 0x1p-24)

/* Range of cellnoise over [lo, hi] per axis; sets *many when the box
 * meets more than one cell. */
static ia_interval cell_range(int dim, const double *lo, const double *hi,
                              unsigned channel, bool *many)
{
    int64_t a[4], n[4];
    int64_t total = 1;
    *many = true;
    for (int k = 0; k < dim; k++) {
        if (!(lo[k] <= hi[k]) || !(lo[k] > -0x1p62) || !(hi[k] < 0x1p62))
            return ia_make(0.0, CELL_MAX_VALUE);
        a[k] = lat_floor(lo[k]);
        n[k] = lat_floor(hi[k]) - a[k] + 1;
        if (n[k] > CELLNOISE_MAX_CELLS)
            return ia_make(0.0, CELL_MAX_VALUE);
        total *= n[k];
        if (total > CELLNOISE_MAX_CELLS)
            return ia_make(0.0, CELL_MAX_VALUE);
    }
    *many = total > 1;
    uint32_t seed = channel_seed(channel);
    double vlo = 1.0, vhi = 0.0;
    for (int64_t t = 0; t < total; t++) {
        int64_t cell[4], rest = t;
        for (int k = 0; k < dim; k++) {
            cell[k] = a[k] + rest % n[k];
            rest /= n[k];
        }
        double v = cell_value(dim, cell, seed);
        if (v < vlo) vlo = v;
        if (v > vhi) vhi = v;
    }
    return ia_make(vlo, vhi);
}

static ia_interval cellnoise_ia(int dim, const ia_interval *p, unsigned channel)
{
    if (!dim_ok(dim))
        return ia_make(0.0, 1.0);
    double lo[4], hi[4];
    unsigned flags = 0;
    for (int k = 0; k < dim; k++) {
        flags |= p[k].flags;
        lo[k] = p[k].lo;
        hi[k] = p[k].hi;
        if (ia_is_empty(p[k])) {
            ia_interval e = ia_empty();
            e.flags = flags;
            return e;
        }
    }
    flags &= ~(unsigned)AA_UNBOUNDED;
    bool many;
    ia_interval r = cell_range(dim, lo, hi, channel, &many);
    r.flags |= flags | (many ? (unsigned)AA_DISCONTINUOUS : 0u);
    return r;
}

ia_interval sl_cellnoise_ia(int dim, const ia_interval *p)
{
    return cellnoise_ia(dim, p, CH_CELL);
}

void sl_vcellnoise_ia(int dim, const ia_interval *p, ia_interval out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = cellnoise_ia(dim, p, CH_VCELL + (unsigned)i);
}

/* ---- affine mode ---- */

static void cellnoise_aa(aa_context *ctx, aa_form *out, int dim,
                         const aa_form *p, unsigned channel)
{
    if (!dim_ok(dim)) {
        aa_from_interval(ctx, out, ia_make(0.0, 1.0));
        return;
    }
    double lo[4], hi[4];
    unsigned flags = 0;
    bool bounded = true;
    for (int k = 0; k < dim; k++) {
        flags |= p[k].flags;
        if (p[k].flags & AA_UNBOUNDED) {
            bounded = false;
            lo[k] = -INFINITY;
            hi[k] = INFINITY;
            continue;
        }
        ia_interval R = aa_range(&p[k]);
        lo[k] = R.lo;
        hi[k] = R.hi;
    }
    flags &= ~(unsigned)AA_UNBOUNDED;
    bool many = true;
    ia_interval r = bounded ? cell_range(dim, lo, hi, channel, &many)
                            : ia_make(0.0, CELL_MAX_VALUE);
    if (!many) {
        aa_const(out, r.lo);
        out->flags = (unsigned short)flags;
        return;
    }
    ia_interval range = ia_make(r.lo, r.hi);
    range.flags |= flags | AA_DISCONTINUOUS;
    aa_from_interval(ctx, out, range);
}

void sl_cellnoise_aa(aa_context *ctx, aa_form *out, int dim, const aa_form *p)
{
    cellnoise_aa(ctx, out, dim, p, CH_CELL);
}

void sl_vcellnoise_aa(aa_context *ctx, aa_form out[3], int dim,
                      const aa_form *p)
{
    for (int i = 0; i < 3; i++)
        cellnoise_aa(ctx, &out[i], dim, p, CH_VCELL + (unsigned)i);
}

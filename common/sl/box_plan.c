/*
 * box_plan.c: what a box run of a displacement shader may leave out
 * (issue 24). The renderer's affine runs of a displacement read P alone
 * (common/trace: the box of the displaced surface), but a shader that
 * takes derivatives (Du(s) for a filter width, calculatenormal(P)) runs in
 * the derivative-carrying mode (vm_deriv.inc), where every operation also
 * bounds d/du and d/dv: on a height-map terrain most of them feed only
 * N = calculatenormal(P), which no box reads.
 *
 * A backward liveness over the code, from P at END, of two sets of slots:
 * V, whose values may still be read on a way to P, and D, whose derivative
 * bounds may. Nothing is ever killed (a write in an undecided branch
 * merges with the old value), so each set at an instruction is the union
 * of what the instructions reachable from it read; without a loop every
 * jump goes forward and one pass from the end suffices. An instruction
 *
 *   - reads its operands' values when anything it writes is in V or D,
 *     and their derivative bounds when anything it writes is in D, or when
 *     it is a derivative (Du, Dv, Deriv, area, calculatenormal: its value
 *     is made of its operand's derivative bounds) writing into V;
 *   - of the kinds box runs can shorten (copies, the arithmetic, texture,
 *     calculatenormal) is SL_BOX_DEAD when nothing it writes is in V or D,
 *     SL_BOX_VALUE when nothing is in D (copies, arithmetic and texture
 *     lookups);
 *   - of any other kind runs as it is, and so reads all its operands'
 *     values (a texture channel, a branch condition, an escape flag stay
 *     exact), merge tables' death and return flags included.
 *
 * A dead instruction writes unbounded values with unbounded derivatives,
 * a value-only one unbounded derivatives: sound whatever reads them, and
 * by the construction above nothing that reaches P does. P itself is
 * computed by the same operations in the same order, so its forms are
 * those of the full run (test_sl_box_plan), except where a dead operation
 * before P's last write no longer takes a noise symbol (then P is still
 * an enclosure, with other symbols). Programs with loops, lights,
 * illuminance, trace or message passing get no plan (NULL).
 *
 * A slope run (sl_vm_run_slopes: P's values and its slope bounds, for the
 * renderer's hit proofs) has a plan of its own, the same liveness from P
 * in both V and D at END, and no SL_BOX_VALUE: there calculatenormal(P)
 * and what feeds only N is left out, and everything else runs as it is.
 * (A merge tells an unchanged slot by its value and derivative bounds
 * alike, so a value-only slot merged undecided could lose the
 * AA_DISCONTINUOUS flag its full run gives it, which a slope run must
 * keep: the flag refuses the proof. Its P and bounds are then the full
 * run's bit for bit. A box run's P keeps its values; its flags may
 * differ there, which only the walk's heuristics read.)
 *
 * What is live into the first instruction says which globals' values and
 * derivative bounds a box run reads at all (sl_program_box_reads): the
 * renderer leaves the others out of its box runs' binding (on heightmap.sl,
 * the tangents dPdu, dPdv and P's derivative bounds, which only
 * calculatenormal reads).
 */
#include "sl/bytecode.h"
#include "util/xalloc.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

/* Live sets larger than this (bytes, for the whole program) are not
 * worth their memory: no plan. */
#define BOX_PLAN_MAX_BYTES (16u << 20)

typedef struct live {
    int words;             /* 64-bit words per set */
    uint64_t *sets;        /* per pc (and one past the end): V, then D */
} live;

static uint64_t *set_v(live *l, int pc) { return &l->sets[(size_t)pc * 2 * (size_t)l->words]; }
static uint64_t *set_d(live *l, int pc) { return set_v(l, pc) + l->words; }

static void add_slot(uint64_t *set, int slot, int nslots)
{
    if (slot >= 0 && slot < nslots)
        set[slot >> 6] |= 1ull << (slot & 63);
}
static bool has_slot(const uint64_t *set, int slot, int nslots)
{
    return slot >= 0 && slot < nslots && (set[slot >> 6] >> (slot & 63)) & 1;
}
static void add_range(uint64_t *set, int first, int n, int nslots)
{
    for (int k = 0; k < n; k++)
        add_slot(set, first + k, nslots);
}
static bool any_in(const uint64_t *set, int first, int n, int nslots)
{
    for (int k = 0; k < n; k++)
        if (has_slot(set, first + k, nslots))
            return true;
    return false;
}

/* The operations a box run can shorten, with the slots they write and
 * read (exactly, as the VM runs them); false for the others. */
static bool shortenable(const sl_insn *in, int *zf, int *zn, int xf[4], int xn[4], int *nx)
{
    *nx = 0;
    switch ((sl_opcode)in->op) {
    case SL_OP_MOV: case SL_OP_NEG: case SL_OP_ABS: case SL_OP_SQRT: case SL_OP_INVSQRT:
        *zf = in->a, *zn = 1;
        xf[0] = in->b, xn[0] = 1, *nx = 1;
        return true;
    case SL_OP_ADD: case SL_OP_SUB: case SL_OP_MUL: case SL_OP_DIV: case SL_OP_MIN:
    case SL_OP_MAX:
        *zf = in->a, *zn = 1;
        xf[0] = in->b, xn[0] = 1, xf[1] = in->c, xn[1] = 1, *nx = 2;
        return true;
    case SL_OP_CLAMP:
        *zf = in->a, *zn = 1;
        xf[0] = in->b, xn[0] = 1, xf[1] = in->c, xn[1] = 1, xf[2] = in->d, xn[2] = 1, *nx = 3;
        return true;
    case SL_OP_MOVN:
        *zf = in->a, *zn = in->c;
        xf[0] = in->b, xn[0] = in->c, *nx = 1;
        return true;
    case SL_OP_TEXTURE:
        *zf = in->a, *zn = sl_texop_outs(in->d);
        xf[0] = in->c, xn[0] = 6, *nx = 1;
        return true;
    case SL_OP_CALCNORMAL:
        *zf = in->a, *zn = 3;
        xf[0] = in->b, xn[0] = 3, *nx = 1;
        return true;
    default:
        return false;
    }
}

/* texture lookups too: their values read only their arguments' values
 * (issue 24: a terrain's lookups feed P alone, and their derivative
 * bounds were a tenth of a box run) */
static bool value_only_kind(int op)
{
    return op != SL_OP_CALCNORMAL;
}

static bool is_derivative(int op)
{
    return op == SL_OP_DU || op == SL_OP_DV || op == SL_OP_DERIV || op == SL_OP_CALCNORMAL ||
           op == SL_OP_AREA;
}

static bool applies(const sl_program *p)
{
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        switch ((sl_opcode)in->op) {
        case SL_OP_LSTART: case SL_OP_LNEXT: case SL_OP_AMBIENT: case SL_OP_DIFFUSE:
        case SL_OP_SPECULAR: case SL_OP_PHONG: case SL_OP_RAY: case SL_OP_MESSAGE:
        case SL_OP_LOOP_TEST: case SL_OP_LOOP_END:
            return false;
        default:
            break;
        }
        const char *k = sl_opcode_operands((sl_opcode)in->op);
        const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
        for (int i = 0; i < 4; i++)
            if (k[i] == 'j' && ops[i] <= pc)
                return false;              /* a jump back: a loop */
    }
    return true;
}

/* Instruction pc's reads into live-in (V and D at pc), given live-out
 * (already copied there); its plan. */
static uint8_t step(const sl_program *p, const sl_insn *in, bool slopes, uint64_t *V,
                    uint64_t *D)
{
    int n = p->nslots;
    int zf, zn, xf[4], xn[4], nx;
    if (shortenable(in, &zf, &zn, xf, xn, &nx)) {
        bool zv = any_in(V, zf, zn, n), zd = any_in(D, zf, zn, n);
        if (!zv && !zd)
            return SL_BOX_DEAD;
        bool derivs = zd || (is_derivative(in->op) && zv);
        for (int i = 0; i < nx; i++) {
            add_range(V, xf[i], xn[i], n);
            if (derivs)
                add_range(D, xf[i], xn[i], n);
        }
        return !derivs && !slopes && value_only_kind(in->op) ? SL_BOX_VALUE : SL_BOX_RUN;
    }
    const char *k = sl_opcode_operands((sl_opcode)in->op);
    const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
    int reach = sl_operand_reach((sl_opcode)in->op) + 1;
    bool zv = false, zd = false;
    for (int i = 0; i < 4; i++)
        if (k[i] == 'z') {
            zv = zv || any_in(V, ops[i], reach, n);
            zd = zd || any_in(D, ops[i], reach, n);
        }
    bool derivs = zd || (is_derivative(in->op) && zv);
    for (int i = 0; i < 4; i++) {
        if (k[i] == 'x') {
            add_range(V, ops[i], reach, n);
            if (derivs)
                add_range(D, ops[i], reach, n);
        } else if (k[i] == 't' && ops[i] < p->ntables) {
            const uint16_t *t = &p->tables[ops[i]];
            for (int e = 1; e <= t[0] && ops[i] + e < p->ntables; e++) {
                unsigned x = t[e];
                if (x & SL_TABLE_STRING)
                    continue;
                if (x & SL_TABLE_DEATH)
                    add_slot(V, (int)(x & SL_TABLE_SLOT), n);
                if ((x & SL_TABLE_GUARDED) && e + 1 <= t[0] && ops[i] + e + 1 < p->ntables) {
                    e++;
                    add_slot(V, (int)(t[e] & SL_TABLE_SLOT), n);   /* the returned flag */
                }
            }
        }
    }
    return SL_BOX_RUN;
}

uint8_t *sl_program_box_plan(const sl_program *p, bool slopes, uint64_t *values,
                             uint64_t *derivs)
{
    uint64_t unused_values, unused_derivs;      /* the outputs are optional */
    if (!values)
        values = &unused_values;
    if (!derivs)
        derivs = &unused_derivs;
    *values = *derivs = ~0ull;
    if ((!slopes && !p->takes_derivatives) || p->ncode <= 0 || !applies(p))
        return NULL;
    live l;
    l.words = (p->nslots + 63) / 64;
    size_t bytes = ((size_t)p->ncode + 1) * 2 * (size_t)l.words * sizeof(uint64_t);
    if (l.words == 0 || bytes > BOX_PLAN_MAX_BYTES)
        return NULL;
    l.sets = xcalloc(((size_t)p->ncode + 1) * 2 * (size_t)l.words, sizeof(uint64_t));
    uint8_t *plan = xcalloc((size_t)p->ncode, 1);
    size_t setbytes = (size_t)l.words * sizeof(uint64_t);
    bool any = false;
    for (int pc = p->ncode - 1; pc >= 0; pc--) {
        const sl_insn *in = &p->code[pc];
        uint64_t *V = set_v(&l, pc), *D = set_d(&l, pc);
        if (in->op == SL_OP_END) {
            /* what a box run reads: P's values (and a slope run P's
             * derivative bounds) */
            add_range(V, sl_global_slot(SL_G_P), sl_global_size(SL_G_P), p->nslots);
            if (slopes)
                add_range(D, sl_global_slot(SL_G_P), sl_global_size(SL_G_P), p->nslots);
        } else {
            /* every successor: the next instruction (conservatively, after
             * a jump too) and the jump targets */
            memcpy(V, set_v(&l, pc + 1), setbytes);
            memcpy(D, set_d(&l, pc + 1), setbytes);
            const char *k = sl_opcode_operands((sl_opcode)in->op);
            const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
            for (int i = 0; i < 4; i++)
                if (k[i] == 'j' && ops[i] <= p->ncode) {
                    const uint64_t *tv = set_v(&l, ops[i]), *td = set_d(&l, ops[i]);
                    for (int w = 0; w < l.words; w++) {
                        V[w] |= tv[w];
                        D[w] |= td[w];
                    }
                }
        }
        /* u and v: a varying parameter is evaluated from them (PARAM) */
        add_range(V, sl_global_slot(SL_G_u), 1, p->nslots);
        add_range(V, sl_global_slot(SL_G_v), 1, p->nslots);
        add_range(D, sl_global_slot(SL_G_u), 1, p->nslots);
        add_range(D, sl_global_slot(SL_G_v), 1, p->nslots);
        plan[pc] = step(p, in, slopes, V, D);
        any = any || plan[pc] != SL_BOX_RUN;
    }
    if (any) {
        /* the globals a box run reads: live into its first instruction
         * (nothing is killed, so that is everything read on a way to P) */
        _Static_assert(SL_GLOBAL_SLOTS <= 64, "a bit per global slot");
        uint64_t globals = (1ull << SL_GLOBAL_SLOTS) - 1;
        *values = set_v(&l, 0)[0] & globals;
        *derivs = set_d(&l, 0)[0] & globals;
    }
    free(l.sets);
    if (!any)
        free(plan);
    return any ? plan : NULL;
}

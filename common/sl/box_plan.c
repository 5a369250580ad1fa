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
 * bounds may. The successors of an instruction are the next one (after a
 * jump too: an undecided branch runs both parts, one after the other) and
 * its jump targets. A write of a whole slot by an operation below kills
 * the slot; the merges of undecided branches and loops and of escapes
 * (break, return) read the old values they saved, so those reads are made
 * explicit (table_reads): where an undecided branch, loop or escape
 * begins (BR_BEGIN, BR_ELSE, LOOP_TEST, ESCAPE: the snapshot of the
 * slots of its merge table), each slot of the table that is live after
 * the merge (BR_END, LOOP_END, ACCUM_END) is read; at the merge, a slot
 * live after it is live before it (it writes nothing whole). (For the
 * code the generator emits, the edges already carry these: an else edge,
 * a loop's exit, the branch that guards what follows a return; the reads
 * keep the kills sound without counting on it.) Without a
 * loop every jump goes forward and one pass from the end suffices; a loop
 * (a jump back) takes passes until no set grows (the sets only grow, and
 * what an instruction reads grows with them: a fixpoint, reached within
 * one pass more than the loops' nesting depth). An instruction
 *
 *   - reads its operands' values when anything it writes is in V or D,
 *     and their derivative bounds when anything it writes is in D, or when
 *     it is a derivative (Du, Dv, Deriv, area, calculatenormal: its value
 *     is made of its operand's derivative bounds) writing into V;
 *   - of the kinds box runs can shorten (copies, the arithmetic and math
 *     functions, comparisons, texture, noise, calculatenormal) is
 *     SL_BOX_DEAD when nothing it writes is in V or D, SL_BOX_VALUE when
 *     nothing is in D (all but calculatenormal; the VM runs a noise or a
 *     comparison in full);
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
 * an enclosure, with other symbols). Programs with lights, illuminance,
 * trace or message passing get no plan (NULL).
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
 * Tape pruning (tape_plan.c) hands the liveness decisions: per
 * instruction 0, or the plan code of what a node's run proved it does
 * (SL_BOX_TAKE_B/C/D: it gives that operand; SL_BOX_ZERO/ONE: that
 * constant; SL_BOX_THEN/ELSE: its branch goes that way). Such an
 * instruction reads only its chosen operand (step_decided), so whatever
 * fed only the other side becomes dead with it. Those plans are made for
 * the plain affine mode too (a box run there reads P alone as well; its
 * VM runs SL_BOX_VALUE as SL_BOX_RUN, having no derivative bounds).
 *
 * What is live into the first instruction says which globals' values and
 * derivative bounds a box run reads at all (sl_program_box_reads): the
 * renderer leaves the others out of its box runs' binding (on heightmap.sl,
 * the tangents dPdu, dPdv and P's derivative bounds, which only
 * calculatenormal reads).
 */
#include "sl/bytecode.h"
#include "util/xalloc.h"

#include <assert.h>
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
 * read (exactly, as the VM runs them); false for the others (the case
 * splits' floor, ceil, round, mod and step among them: a run numbers its
 * splits as it meets them, split_plan.c) */
static bool shortenable(const sl_insn *in, int *zf, int *zn, int xf[4], int xn[4], int *nx)
{
    *nx = 0;
    switch ((sl_opcode)in->op) {
    case SL_OP_MOV: case SL_OP_NEG: case SL_OP_ABS: case SL_OP_SQRT: case SL_OP_INVSQRT:
    case SL_OP_EXP: case SL_OP_LOG: case SL_OP_SIN: case SL_OP_COS: case SL_OP_TAN:
    case SL_OP_ASIN: case SL_OP_ACOS: case SL_OP_ATAN: case SL_OP_SIGN: case SL_OP_NOT:
        *zf = in->a, *zn = 1;
        xf[0] = in->b, xn[0] = 1, *nx = 1;
        return true;
    case SL_OP_ADD: case SL_OP_SUB: case SL_OP_MUL: case SL_OP_DIV: case SL_OP_MIN:
    case SL_OP_MAX: case SL_OP_POW: case SL_OP_ATAN2: case SL_OP_LT: case SL_OP_LE:
    case SL_OP_GT: case SL_OP_GE: case SL_OP_EQ: case SL_OP_NE: case SL_OP_AND: case SL_OP_OR:
        *zf = in->a, *zn = 1;
        xf[0] = in->b, xn[0] = 1, xf[1] = in->c, xn[1] = 1, *nx = 2;
        return true;
    case SL_OP_SMOOTHSTEP: case SL_OP_MIX:
        *zf = in->a, *zn = 1;
        xf[0] = in->b, xn[0] = 1, xf[1] = in->c, xn[1] = 1, xf[2] = in->d, xn[2] = 1, *nx = 3;
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
        *zf = in->a, *zn = sl_box_writes(in);
        xf[0] = in->c, xn[0] = 6, *nx = 1;
        return true;
    case SL_OP_NOISE:         /* a function of its point (and periods) alone */
        *zf = in->a, *zn = sl_box_writes(in);
        xf[0] = in->b, xn[0] = SL_NOISE_DIM(in->c), *nx = 1;
        if (SL_NOISE_KIND(in->c) == SL_NOISE_PERIODIC)
            xf[1] = in->d, xn[1] = SL_NOISE_DIM(in->c), *nx = 2;
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
            return false;
        default:
            break;
        }
    }
    return true;
}

/* Instruction pc's reads into live-in (V and D at pc), given live-out
 * (already copied there); its plan. */
/* Where the merge of the region an instruction begins is (BR_BEGIN,
 * BR_ELSE: the BR_END of the branch; LOOP_TEST: its LOOP_END; ESCAPE: the
 * LOOP_END or ACCUM_END of the construct it leaves), -2 where none is
 * found (every slot of its table then counts as read), -1 for the other
 * instructions; and the table it saves */
static void region_ends(const sl_program *p, int *end, int *table)
{
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        int start = -1, end_op = -1, id = -1, kind = -1;
        end[pc] = -1;
        table[pc] = -1;
        switch ((sl_opcode)in->op) {
        case SL_OP_BR_BEGIN: start = pc, end_op = SL_OP_BR_END, table[pc] = in->c; break;
        case SL_OP_BR_ELSE:
            start = in->b, end_op = SL_OP_BR_END;
            if (in->b < p->ncode && p->code[in->b].op == SL_OP_BR_BEGIN)
                table[pc] = p->code[in->b].c;
            break;
        case SL_OP_LOOP_TEST: start = pc, end_op = SL_OP_LOOP_END, table[pc] = in->c; break;
        case SL_OP_ESCAPE:
            table[pc] = in->c;
            if (in->d == SL_ESCAPE_LOOP)
                start = in->b, end_op = SL_OP_LOOP_END;
            else
                id = in->b, kind = in->d, end_op = SL_OP_ACCUM_END;
            break;
        default: continue;
        }
        end[pc] = -2;
        for (int q = pc + 1; q < p->ncode; q++) {
            const sl_insn *e = &p->code[q];
            if (e->op == end_op &&
                (end_op == SL_OP_ACCUM_END ? e->a == id && e->d == kind : e->a == start)) {
                end[pc] = q;
                break;
            }
        }
        if (table[pc] < 0 || table[pc] >= p->ntables)
            end[pc] = -2, table[pc] = -1;
    }
}

/* The slots of table t that a region's start reads (region_ends): those
 * live after its merge (Vend, Dend; NULL: all of them) */
static void table_reads(const sl_program *p, int t, const uint64_t *Vend, const uint64_t *Dend,
                        uint64_t *V, uint64_t *D)
{
    int n = p->nslots;
    if (t < 0)
        return;
    const uint16_t *tab = &p->tables[t];
    for (int e = 1; e <= tab[0] && t + e < p->ntables; e++) {
        unsigned x = tab[e];
        if (x & SL_TABLE_STRING)
            continue;
        int slot = (int)(x & SL_TABLE_SLOT);
        if (!Vend || has_slot(Vend, slot, n))
            add_slot(V, slot, n);
        if (!Dend || has_slot(Dend, slot, n))
            add_slot(D, slot, n);
        if (x & SL_TABLE_GUARDED)
            e++;                          /* its flag: read by step */
    }
}

/* Clears slots [first, first + n) from a set */
static void kill_range(uint64_t *set, int first, int n, int nslots)
{
    for (int k = 0; k < n; k++) {
        int slot = first + k;
        if (slot >= 0 && slot < nslots)
            set[slot >> 6] &= ~(1ull << (slot & 63));
    }
}

/* A decided instruction (tape_plan.c: its node's run proved which
 * operand it takes, or its constant, or the side of its branch) reads
 * that operand alone, or nothing; it is dead where nothing it writes is
 * live (a decided branch is never dead: it still jumps) */
static uint8_t step_decided(const sl_program *p, const sl_insn *in, uint8_t code, uint64_t *V,
                            uint64_t *D)
{
    int n = p->nslots;
    if (code == SL_BOX_THEN || code == SL_BOX_ELSE)
        return code;
    bool zv = has_slot(V, in->a, n), zd = has_slot(D, in->a, n);
    if (!zv && !zd)
        return SL_BOX_DEAD;
    kill_range(V, in->a, 1, n);              /* z written whole */
    kill_range(D, in->a, 1, n);
    int x = code == SL_BOX_TAKE_B ? in->b : code == SL_BOX_TAKE_C ? in->c
                                           : code == SL_BOX_TAKE_D ? in->d : -1;
    if (x >= 0) {
        add_slot(V, x, n);
        if (zd)
            add_slot(D, x, n);           /* the copy takes its bounds along */
    }
    return code;
}

static uint8_t step(const sl_program *p, const sl_insn *in, bool slopes, uint64_t *V,
                    uint64_t *D)
{
    int n = p->nslots;
    int zf, zn, xf[4], xn[4], nx;
    if (shortenable(in, &zf, &zn, xf, xn, &nx)) {
        bool zv = any_in(V, zf, zn, n), zd = any_in(D, zf, zn, n);
        if (!zv && !zd)
            return SL_BOX_DEAD;
        kill_range(V, zf, zn, n);        /* z written whole */
        kill_range(D, zf, zn, n);
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
    if (reach == 1)                      /* a scalar operation: z written whole */
        for (int i = 0; i < 4; i++)
            if (k[i] == 'z') {
                kill_range(V, ops[i], 1, n);
                kill_range(D, ops[i], 1, n);
            }
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
    return sl_program_plan(p, slopes, NULL, values, derivs);
}

uint8_t *sl_program_plan(const sl_program *p, bool slopes, const uint8_t *decided,
                         uint64_t *values, uint64_t *derivs)
{
    uint64_t unused_values, unused_derivs;      /* the outputs are optional */
    if (!values)
        values = &unused_values;
    if (!derivs)
        derivs = &unused_derivs;
    *values = *derivs = ~0ull;
    assert(!(slopes && decided));                /* decisions are a box run's */
    if ((!slopes && !decided && !p->takes_derivatives) || p->ncode <= 0 || !applies(p))
        return NULL;
    live l;
    l.words = (p->nslots + 63) / 64;
    size_t bytes = ((size_t)p->ncode + 1) * 2 * (size_t)l.words * sizeof(uint64_t);
    if (l.words == 0 || bytes > BOX_PLAN_MAX_BYTES)
        return NULL;
    l.sets = xcalloc(((size_t)p->ncode + 1) * 2 * (size_t)l.words, sizeof(uint64_t));
    uint8_t *plan = xcalloc((size_t)p->ncode, 1);
    size_t setbytes = (size_t)l.words * sizeof(uint64_t);
    uint64_t *tmp = xcalloc(2 * (size_t)l.words, sizeof(uint64_t));
    int *end = xmalloc((size_t)p->ncode * sizeof *end);
    int *table = xmalloc((size_t)p->ncode * sizeof *table);
    region_ends(p, end, table);
    bool any = false, grew = true;
    while (grew) {                  /* to the fixpoint (a loop: several passes) */
        grew = false;
        any = false;
        for (int pc = p->ncode - 1; pc >= 0; pc--) {
            const sl_insn *in = &p->code[pc];
            uint64_t *V = tmp, *D = tmp + l.words;
            if (in->op == SL_OP_END) {
                /* what a box run reads: P's values (and a slope run P's
                 * derivative bounds) */
                memset(tmp, 0, 2 * setbytes);
                add_range(V, sl_global_slot(SL_G_P), sl_global_size(SL_G_P), p->nslots);
                if (slopes)
                    add_range(D, sl_global_slot(SL_G_P), sl_global_size(SL_G_P), p->nslots);
            } else {
                /* every successor: the next instruction (conservatively,
                 * after a jump too) and the jump targets, backward ones
                 * as far as the last pass has them */
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
            plan[pc] = decided && decided[pc] ? step_decided(p, in, decided[pc], V, D)
                                              : step(p, in, slopes, V, D);
            if (end[pc] != -1)             /* a region's start: its snapshot */
                table_reads(p, table[pc], end[pc] >= 0 ? set_v(&l, end[pc] + 1) : NULL,
                            end[pc] >= 0 ? set_d(&l, end[pc] + 1) : NULL, V, D);
            any = any || plan[pc] != SL_BOX_RUN;
            /* the sets only grow: any difference is growth */
            if (memcmp(set_v(&l, pc), tmp, 2 * setbytes) != 0) {
                memcpy(set_v(&l, pc), tmp, 2 * setbytes);
                grew = true;
            }
        }
    }
    free(tmp);
    free(end);
    free(table);
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

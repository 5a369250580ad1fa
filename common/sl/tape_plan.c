/*
 * tape_plan.c: tape pruning of box runs (issue 24, "shorter programs
 * deeper in the tree"; the idea of Duff 1992's and Keeter 2020's interval
 * evaluations of implicit surfaces, on affine box runs here).
 *
 * A box run bounds P over a node's (u,v) range. Where that run proves an
 * operation's choice over the whole range (min(x, y) with x below y at
 * every point, clamp(x, lo, hi) with x above hi, a smoothstep saturated, a
 * mix by exactly 0 or 1, a branch's condition decided), the choice holds
 * at every point of every child range too, since a child's range lies
 * inside its node's: the exact function there is the program with that
 * operation replaced by the operand it takes (or its constant, or the
 * branch taken). So the children's runs take it so (the plan codes
 * SL_BOX_TAKE_B .. SL_BOX_ELSE) and leave out what only the other side
 * read (box_plan.c's liveness: the fBm under a clamp's plateau, the hidden
 * layer of a saturated mask). The children's boxes still enclose the
 * surface: each is the box run of a program equal to the shader on its
 * range.
 *
 * Which operations count: per program at most SL_TAPE_SITES TAPE SITES,
 * the min, max, clamp, step, smoothstep, mix and branches whose decisions
 * would leave the most of the program dead (sl_program_choose_tape_sites:
 * a liveness per candidate and choice, the dead operations weighted by
 * what they cost), so a node's proved decisions fit in SL_TAPE_BITS bits a
 * site (its box's tape: common/trace keeps it in the box, 14 bits). A
 * site the run executes several times (a loop) is decided only where every
 * execution made the same choice (the VM notes them: vm_exec.inc).
 *
 * The tape of a node is a pure function of the node (the decisions its
 * own run proved, plus those its parent's tape gave its run), so a box
 * stays a pure function of (object, u-range, v-range): the same on every
 * thread and in every tile, cached or not.
 */
#include "sl/bytecode.h"
#include "util/xalloc.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(SL_TAPE_SITES * SL_TAPE_BITS <= 14, "a tape fits a box's 14 bits");
/* Programs above this many instructions get no sites (their liveness per
 * candidate would cost too much at compile time), and only the first
 * TAPE_MAX_CANDIDATES candidates are weighed. */
#define TAPE_MAX_CODE 8192
#define TAPE_MAX_CANDIDATES 48

/* A site is kept only where one of its decisions leaves at least this much
 * dead (tape_weight): a few operations, or one noise; and at least
 * 1/TAPE_MIN_SHARE of the weight of what a box run runs: a tape run costs
 * more a run (the notes, the plan's checks: about a tenth of a box run
 * where nothing dies), so a site that saves less than that slows the
 * render (with 1/8, the pattern shaders' steps, whose products by a mask
 * kill a few operations, are no sites: bricks and slate_roof 1.003x and
 * 1.006x of their instructions as sites) */
#define TAPE_MIN_GAIN 4
#define TAPE_MIN_SHARE 8

/* How many choices op has as a site (0: not a site) */
static int choices(int op)
{
    switch (op) {
    case SL_OP_MIN: case SL_OP_MAX: case SL_OP_STEP: case SL_OP_SMOOTHSTEP: case SL_OP_MIX:
    case SL_OP_BR_BEGIN:
        return 2;
    case SL_OP_CLAMP:
        return 3;
    default:
        return 0;
    }
}

uint8_t sl_tape_code(const sl_insn *in, int dec)
{
    if (dec < 1 || dec > choices(in->op))
        return 0;
    switch (in->op) {
    case SL_OP_MIN: case SL_OP_MAX: case SL_OP_CLAMP: case SL_OP_MIX:
        return (uint8_t)(SL_BOX_TAKE_B + dec - 1);
    case SL_OP_STEP: case SL_OP_SMOOTHSTEP:
        return dec == 1 ? SL_BOX_ZERO : SL_BOX_ONE;
    default:                                  /* BR_BEGIN */
        return dec == 1 ? SL_BOX_THEN : SL_BOX_ELSE;
    }
}

/*
 * Constants through arithmetic. A decided step or smoothstep gives an exact
 * 0 or 1 (the ZERO and ONE codes); a product by it, a sum with it, is
 * then decided too (0 y = 0, 1 y = y, 0 + y = y, y - 0 = y, for every real
 * y), so that step(0.5, t) * noise(P) leaves the noise dead where the step
 * is 0. A sweep in code order keeps the slots whose value is known: an
 * instruction that runs exactly once in every run ("once": outside every
 * jump's span and every escape's region, so no loop or branch is around
 * it) and writes a known 0 or 1 makes its slot known; any other write (a
 * merge's too) makes it unknown; and a known value is used only by a
 * reader that runs once as well. Two such instructions run in code order,
 * and a write between them in time would be between them in the code (a
 * jump that could bring one in would span one of them), so the reader sees
 * the value the sweep has. The constant pool's 0s and 1s are known from
 * the start.
 */
enum { K_UNKNOWN = -1 };

/* Per pc: whether it runs exactly once in every run, in code order */
static bool *runs_once(const sl_program *p)
{
    bool *once = xmalloc((size_t)p->ncode * sizeof *once);
    for (int pc = 0; pc < p->ncode; pc++)
        once[pc] = true;
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        const char *k = sl_opcode_operands((sl_opcode)in->op);
        const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
        for (int i = 0; i < 4; i++)
            if (k[i] == 'j') {
                int t = ops[i];
                int lo = t > pc ? pc + 1 : t, hi = t > pc ? t - 1 : pc;
                for (int q = lo; q <= hi && q < p->ncode; q++)
                    once[q] = false;
            }
        if (in->op == SL_OP_ESCAPE)          /* what follows a return or break */
            for (int q = pc + 1; q < p->ncode; q++)
                once[q] = false;
    }
    return once;
}

/* Forgets what instruction in writes (its written operands as far as
 * sl_operand_reach, the slots of its merge tables) */
static void forget_writes(const sl_program *p, const sl_insn *in, int *known)
{
    const char *k = sl_opcode_operands((sl_opcode)in->op);
    const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
    int reach = sl_operand_reach((sl_opcode)in->op) + 1;
    for (int i = 0; i < 4; i++) {
        if (k[i] == 'z') {
            for (int q = 0; q < reach && ops[i] + q < p->nslots; q++)
                known[ops[i] + q] = K_UNKNOWN;
        } else if (k[i] == 't' && ops[i] < p->ntables) {
            const uint16_t *t = &p->tables[ops[i]];
            for (int e = 1; e <= t[0] && ops[i] + e < p->ntables; e++)
                if (!(t[e] & SL_TABLE_STRING) && (int)(t[e] & SL_TABLE_SLOT) < p->nslots)
                    known[t[e] & SL_TABLE_SLOT] = K_UNKNOWN;
        }
    }
}

/* decided[] with the products, sums and differences that known 0s and 1s
 * decide (and those they make known in turn) */
static void fold_constants(const sl_program *p, const bool *once, uint8_t *decided)
{
    int *known = xmalloc((size_t)p->nslots * sizeof *known);
    for (int s = 0; s < p->nslots; s++) {
        known[s] = K_UNKNOWN;
        if (s >= SL_GLOBAL_SLOTS && s >= p->const_base && s < p->const_base + p->nconsts) {
            double v = p->consts[s - p->const_base];
            known[s] = v == 0.0 ? 0 : v == 1.0 ? 1 : K_UNKNOWN;
        }
    }
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        int v = K_UNKNOWN, x = K_UNKNOWN, y = K_UNKNOWN;
        bool arith = in->op == SL_OP_MOV || in->op == SL_OP_MUL || in->op == SL_OP_ADD ||
                     in->op == SL_OP_SUB;
        if (arith && once[pc]) {
            x = known[in->b];
            y = in->op == SL_OP_MOV ? K_UNKNOWN : known[in->c];
        }
        uint8_t d = decided[pc];
        if (d == SL_BOX_ZERO || d == SL_BOX_ONE) {
            v = d == SL_BOX_ONE;
        } else if (!d && in->op == SL_OP_MOV) {
            v = x;
        } else if (!d && in->op == SL_OP_MUL) {
            if (x == 0 || y == 0)
                d = SL_BOX_ZERO, v = 0;
            else if (x == 1)
                d = SL_BOX_TAKE_C, v = y;
            else if (y == 1)
                d = SL_BOX_TAKE_B, v = x;
        } else if (!d && in->op == SL_OP_ADD) {
            if (x == 0)
                d = SL_BOX_TAKE_C, v = y;
            else if (y == 0)
                d = SL_BOX_TAKE_B, v = x;
        } else if (!d && in->op == SL_OP_SUB) {
            if (y == 0)
                d = SL_BOX_TAKE_B, v = x;
            else if (x == 1 && y == 1)
                d = SL_BOX_ZERO, v = 0;
        }
        decided[pc] = d;
        forget_writes(p, in, known);
        if (v != K_UNKNOWN && once[pc] && in->a >= SL_GLOBAL_SLOTS && in->a < p->nslots &&
            (arith || d == SL_BOX_ZERO || d == SL_BOX_ONE))
            known[in->a] = v;
    }
    free(known);
}

/* The plan of decisions (sl_program_plan with the constants they make
 * folded through arithmetic); decided[] is left as it was */
static uint8_t *plan_of(const sl_program *p, const bool *once, const uint8_t *decided)
{
    uint8_t *d = xmalloc((size_t)p->ncode);
    memcpy(d, decided, (size_t)p->ncode);
    fold_constants(p, once, d);
    uint8_t *plan = sl_program_plan(p, false, d, NULL, NULL);
    free(d);
    return plan;
}

/* What leaving an operation out saves, roughly in units of an affine
 * addition */
static int tape_weight(const sl_insn *in)
{
    switch (in->op) {
    case SL_OP_NOISE: case SL_OP_TEXTURE:
        return 32;
    case SL_OP_SQRT: case SL_OP_INVSQRT: case SL_OP_EXP: case SL_OP_LOG: case SL_OP_SIN:
    case SL_OP_COS: case SL_OP_TAN: case SL_OP_ASIN: case SL_OP_ACOS: case SL_OP_ATAN:
    case SL_OP_POW: case SL_OP_ATAN2: case SL_OP_SMOOTHSTEP:
        return 4;
    case SL_OP_MUL: case SL_OP_DIV: case SL_OP_XPOINT: case SL_OP_XVECTOR: case SL_OP_XNORMAL:
        return 2;
    default:
        return 1;
    }
}

/* What the plan leaves dead that the base plan runs, weighed */
static long gain(const sl_program *p, const uint8_t *base, const uint8_t *plan)
{
    long g = 0;
    for (int pc = 0; pc < p->ncode; pc++)
        if (plan[pc] == SL_BOX_DEAD && base[pc] != SL_BOX_DEAD)
            g += tape_weight(&p->code[pc]);
    return g;
}

void sl_program_choose_tape_sites(sl_program *p)
{
    p->ntape_sites = 0;
    p->tape_site_of = NULL;
    if (p->kind != SL_SHADER_DISPLACEMENT || p->ncode <= 0 || p->ncode > TAPE_MAX_CODE)
        return;
    uint8_t *decided = xcalloc((size_t)p->ncode, 1);
    bool *once = runs_once(p);
    uint8_t *base = plan_of(p, once, decided);
    if (!base) {                         /* the analysis does not apply */
        free(once);
        free(decided);
        return;
    }
    long live = 0;                       /* what a box run runs, weighed */
    for (int pc = 0; pc < p->ncode; pc++)
        if (base[pc] != SL_BOX_DEAD)
            live += tape_weight(&p->code[pc]);
    long best_gain[SL_TAPE_SITES];
    int best_pc[SL_TAPE_SITES], nbest = 0, candidates = 0;
    for (int pc = 0; pc < p->ncode && candidates < TAPE_MAX_CANDIDATES; pc++) {
        const sl_insn *in = &p->code[pc];
        int n = choices(in->op);
        if (n == 0 || base[pc] == SL_BOX_DEAD)
            continue;
        candidates++;
        long g = 0;
        for (int dec = 1; dec <= n; dec++) {
            decided[pc] = sl_tape_code(in, dec);
            uint8_t *plan = plan_of(p, once, decided);
            if (plan) {
                long gd = gain(p, base, plan);
                g = gd > g ? gd : g;
                free(plan);
            }
        }
        decided[pc] = 0;
        if (g < TAPE_MIN_GAIN || g * TAPE_MIN_SHARE < live)
            continue;
        /* keep the SL_TAPE_SITES largest gains (the earlier site on a tie) */
        int at = nbest;
        while (at > 0 && best_gain[at - 1] < g)
            at--;
        if (at >= SL_TAPE_SITES)
            continue;
        int last = nbest < SL_TAPE_SITES ? nbest : SL_TAPE_SITES - 1;
        for (int k = last; k > at; k--) {
            best_gain[k] = best_gain[k - 1];
            best_pc[k] = best_pc[k - 1];
        }
        best_gain[at] = g;
        best_pc[at] = pc;
        if (nbest < SL_TAPE_SITES)
            nbest++;
    }
    free(base);
    free(decided);
    free(once);
    if (nbest == 0)
        return;
    p->tape_site_of = xmalloc((size_t)p->ncode);
    memset(p->tape_site_of, -1, (size_t)p->ncode);
    for (int i = 0; i < nbest; i++) {
        p->tape_site[i] = best_pc[i];
        p->tape_site_of[best_pc[i]] = (int8_t)i;
    }
    p->ntape_sites = nbest;
}

int sl_program_tape_site_count(const sl_program *self)
{
    return self->ntape_sites;
}

uint8_t *sl_program_tape_plan(const sl_program *p, uint32_t tape)
{
    if (tape == 0 || p->ntape_sites == 0)
        return NULL;
    uint8_t *decided = xcalloc((size_t)p->ncode, 1);
    bool any = false;
    for (int i = 0; i < p->ntape_sites; i++) {
        int dec = (int)(tape >> (SL_TAPE_BITS * i) & ((1u << SL_TAPE_BITS) - 1));
        const sl_insn *in = &p->code[p->tape_site[i]];
        decided[p->tape_site[i]] = sl_tape_code(in, dec);
        any = any || decided[p->tape_site[i]] != 0;
    }
    uint8_t *plan = NULL;
    if (any) {
        bool *once = runs_once(p);
        plan = plan_of(p, once, decided);
        free(once);
    }
    free(decided);
    return plan;
}

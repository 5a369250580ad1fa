/*
 * split_plan.c: which case splits of an affine run must agree (issue 24,
 * "walls and patterns"; sl_vm_split_begin, shader.h).
 *
 * A case split gives a floor, ceil, round, mod or step that takes two
 * values over the range one of them per run. Split independently, two
 * operations of one value (the filtered pulse train's
 * `d * floor(x) + min(d, x - floor(x))`) make cases no point has (floor(x)
 * = k in one, k + 1 in the other) and twice the splits the cell needs. An
 * operation is "the same" as an earlier one, q, when
 *
 *   - it has q's opcode and reads q's operand slots;
 *   - no instruction after q up to it writes those slots, and every one of
 *     them is a plain operation (copies, arithmetic, comparisons, the
 *     split operations: each writes its z operand alone, as the VM runs
 *     it); any other kind (branches and their merges, noise, texture,
 *     calls of the renderer, parameters) ends every chain;
 *   - no instruction after q up to it is a jump target: it is reached only
 *     by falling through from q, so the run executed q just before, on
 *     the same operand values.
 *
 * Then both compute the same function of the point: in each case the VM
 * gives the later one the value q took (sl_vm: split.at), which is the
 * value every point of that case has for both. A later operation's entry
 * names the first of its chain (the one that took a split of its own).
 * Programs with lights, illuminance, trace or message passing get no plan.
 */
#include "sl/bytecode.h"
#include "util/xalloc.h"

#include <stdbool.h>
#include <stdlib.h>

/* The split operations this many back are still looked at */
#define CHAIN_MAX 32

static bool splittable(int op)
{
    return op == SL_OP_FLOOR || op == SL_OP_CEIL || op == SL_OP_ROUND || op == SL_OP_MOD ||
           op == SL_OP_STEP;
}

static bool binary(int op) { return op == SL_OP_MOD || op == SL_OP_STEP; }

/* A plain operation: writes [*first, *first + *n) and nothing else (a
 * copy of n slots, or one of the scalar operations: sl_operand_reach 0) */
static bool plain(const sl_insn *in, int *first, int *n)
{
    if (in->op == SL_OP_MOVN) {
        *first = in->a, *n = in->c;
        return true;
    }
    if (sl_operand_reach((sl_opcode)in->op) != 0) return false;
    *first = in->a, *n = 1;
    return true;
}

static bool no_plan(int op)
{
    switch ((sl_opcode)op) {
    case SL_OP_LSTART: case SL_OP_LNEXT: case SL_OP_AMBIENT: case SL_OP_DIFFUSE:
    case SL_OP_SPECULAR: case SL_OP_PHONG: case SL_OP_RAY: case SL_OP_MESSAGE:
        return true;
    default:
        return false;
    }
}

static bool reads_in(const sl_insn *in, int first, int n)
{
    if (in->b >= first && in->b < first + n) return true;
    return binary(in->op) && in->c >= first && in->c < first + n;
}

int32_t *sl_program_split_same(const sl_program *p)
{
    if (p->ncode <= 0) return NULL;
    bool *target = xcalloc((size_t)p->ncode + 1, sizeof *target);
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        if (no_plan(in->op)) {
            free(target);
            return NULL;
        }
        const char *k = sl_opcode_operands((sl_opcode)in->op);
        const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
        for (int i = 0; i < 4; i++)
            if (k[i] == 'j' && ops[i] <= p->ncode)
                target[ops[i]] = true;
    }
    int32_t *same = xmalloc((size_t)p->ncode * sizeof *same);
    int chain[CHAIN_MAX], nchain = 0;
    bool any = false;
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        same[pc] = -1;
        if (target[pc]) nchain = 0;
        if (splittable(in->op)) {
            for (int i = nchain - 1; i >= 0; i--) {
                const sl_insn *q = &p->code[chain[i]];
                if (q->op == in->op && q->b == in->b && (!binary(in->op) || q->c == in->c)) {
                    same[pc] = chain[i];
                    any = true;
                    break;
                }
            }
            if (same[pc] < 0) {
                if (nchain == CHAIN_MAX) {          /* the oldest goes */
                    for (int i = 1; i < CHAIN_MAX; i++) chain[i - 1] = chain[i];
                    nchain--;
                }
                chain[nchain++] = pc;
            }
        }
        int first, n;
        if (!plain(in, &first, &n)) {
            nchain = 0;
            continue;
        }
        int kept = 0;                              /* those whose operands it writes go */
        for (int i = 0; i < nchain; i++)
            if (!reads_in(&p->code[chain[i]], first, n))
                chain[kept++] = chain[i];
        nchain = kept;
    }
    free(target);
    if (!any) {
        free(same);
        return NULL;
    }
    return same;
}

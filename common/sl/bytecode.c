/*
 * bytecode.c: opcode names, freeing a program, and the bytecode listing
 * (`aafarm-slc --dump`): the slot layout, parameters, constants and one
 * line per instruction with its source position and operands written out
 * (globals by name, constants by value, jumps as @pc, merge tables as
 * slot lists).
 */
#include "sl/bytecode.h"
#include "sl/ast.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

static const char *const names[SL_OP__COUNT] = {
#define SL_OPCODE_NAME(name, text, operands) text,
    SL_OPCODES(SL_OPCODE_NAME)
#undef SL_OPCODE_NAME
};

static const char *const kinds[SL_OP__COUNT] = {
#define SL_OPCODE_KINDS(name, text, operands) operands,
    SL_OPCODES(SL_OPCODE_KINDS)
#undef SL_OPCODE_KINDS
};

const char *sl_opcode_name(sl_opcode op)
{
    return (unsigned)op < SL_OP__COUNT ? names[op] : "?";
}

const char *sl_opcode_operands(sl_opcode op)
{
    return (unsigned)op < SL_OP__COUNT ? kinds[op] : "----";
}

static bool is_derivative_op(int op)
{
    return op == SL_OP_DU || op == SL_OP_DV || op == SL_OP_DERIV || op == SL_OP_CALCNORMAL ||
           op == SL_OP_AREA;
}

/* Does instruction `in` possibly write one of P's slots [0, 3)? A written
 * slot ('z') is the first of up to three; a merge table ('t') lists the
 * slots its construct writes. */
static bool may_write_P(const sl_program *p, const sl_insn *in)
{
    const char *k = kinds[in->op];
    const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
    int P = sl_global_slot(SL_G_P);
    for (int i = 0; i < 4; i++) {
        if (k[i] == 'z' && ops[i] < P + 3)
            return true;
        if (k[i] == 't' && ops[i] < p->ntables) {
            const uint16_t *t = &p->tables[ops[i]];
            for (int e = 1; e <= t[0] && ops[i] + e < p->ntables; e++)
                if (!(t[e] & SL_TABLE_STRING) && (t[e] & SL_TABLE_SLOT) < P + 3)
                    return true;
        }
    }
    return false;
}

bool sl_program_derivatives_reach_P(const sl_program *p)
{
    int first = -1, last_write = -1;
    for (int pc = 0; pc < p->ncode; pc++) {
        if (is_derivative_op(p->code[pc].op) && first < 0)
            first = pc;
        if (may_write_P(p, &p->code[pc]))
            last_write = pc;
    }
    if (first < 0)
        return false;
    if (last_write > first)
        return true;
    /* a jump back over the first derivative (a loop around it) */
    for (int pc = first; pc < p->ncode; pc++) {
        const char *k = kinds[p->code[pc].op];
        const uint16_t ops[4] = { p->code[pc].a, p->code[pc].b, p->code[pc].c, p->code[pc].d };
        for (int i = 0; i < 4; i++)
            if (k[i] == 'j' && ops[i] <= first)
                return true;
    }
    return false;
}

/* Conservative: does any instruction name a slot of global g (read or
 * written, as the first slot of an operand of its width, or in a merge
 * table)? A program that never names dPdu need not be given it. */
/* How many slots past its first an operand of `op` may reach: 0 for the
 * scalar operations (the VM runs them on one slot: vm_exec.inc), 15 for
 * copies of n slots, parameter defaults, argument blocks and arrays, and
 * 2 (a triple) for the rest. A matrix is never a global: it lives above
 * them, so a block that starts below a global and spans it is at most a
 * copy or an argument block. */
static int operand_reach(int op)
{
    switch (op) {
    case SL_OP_MOV: case SL_OP_ADD: case SL_OP_SUB: case SL_OP_MUL: case SL_OP_DIV:
    case SL_OP_NEG: case SL_OP_SQRT: case SL_OP_INVSQRT: case SL_OP_EXP: case SL_OP_LOG:
    case SL_OP_SIN: case SL_OP_COS: case SL_OP_TAN: case SL_OP_ASIN: case SL_OP_ACOS:
    case SL_OP_ATAN: case SL_OP_ABS: case SL_OP_SIGN: case SL_OP_FLOOR: case SL_OP_CEIL:
    case SL_OP_ROUND: case SL_OP_POW: case SL_OP_ATAN2: case SL_OP_MOD: case SL_OP_MIN:
    case SL_OP_MAX: case SL_OP_STEP: case SL_OP_CLAMP: case SL_OP_SMOOTHSTEP: case SL_OP_MIX:
    case SL_OP_LT: case SL_OP_LE: case SL_OP_GT: case SL_OP_GE: case SL_OP_EQ: case SL_OP_NE:
    case SL_OP_AND: case SL_OP_OR: case SL_OP_NOT: case SL_OP_BR_BEGIN: case SL_OP_LOOP_TEST:
    case SL_OP_DU: case SL_OP_DV: case SL_OP_DERIV:
        return 0;
    case SL_OP_MOVN: case SL_OP_PARAM: case SL_OP_RAY: case SL_OP_TEXTURE:
    case SL_OP_TEXINFO: case SL_OP_SFMT: case SL_OP_MESSAGE: case SL_OP_ALOAD:
    case SL_OP_ASTORE: case SL_OP_ESCAPE:
        return 15;
    default:
        return 2;
    }
}

int sl_operand_reach(sl_opcode op) { return operand_reach(op); }

void sl_program_assert_valid(const sl_program *p)
{
    assert(p->nslots <= SL_MAX_SLOTS && p->nstring_slots <= SL_MAX_STRING_SLOTS);
    assert(p->const_base + p->nconsts == p->nslots);
    assert(p->ncode > 0 && p->code[p->ncode - 1].op == SL_OP_END);
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        assert(in->op < SL_OP__COUNT);
        const char *k = kinds[in->op];
        const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
        (void)ops;   /* without asserts */
        for (int i = 0; i < 4; i++) {
            if (k[i] == 'x' || k[i] == 'z')
                assert(ops[i] < p->nslots && "a slot operand lies inside the program's slots");
            else if (k[i] == 's')
                assert(ops[i] < p->nstring_slots && "a string slot lies inside the program's");
            else if (k[i] == 'j')
                assert(ops[i] <= p->ncode && "a jump lands inside the program");
            else if (k[i] == 't')
                assert(ops[i] < p->ntables && "a merge table lies inside the program's");
        }
    }
}

bool sl_program_reads_global(const sl_program *p, sl_global g)
{
    int first = sl_global_slot(g), last = first + sl_global_size(g) - 1;
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        const char *k = kinds[in->op];
        const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
        /* how far past its first slot an operand may reach */
        int reach = operand_reach(in->op);
        for (int i = 0; i < 4; i++) {
            if ((k[i] == 'x' || k[i] == 'z') && ops[i] <= last && ops[i] + reach >= first)
                return true;
            if (k[i] == 't' && ops[i] < p->ntables) {
                const uint16_t *t = &p->tables[ops[i]];
                for (int e = 1; e <= t[0] && ops[i] + e < p->ntables; e++) {
                    int slot = t[e] & SL_TABLE_SLOT;
                    if (!(t[e] & SL_TABLE_STRING) && slot <= last && slot + 15 >= first)
                        return true;
                }
            }
        }
    }
    return false;
}

bool sl_program_reads_textures(const sl_program *p)
{
    for (int pc = 0; pc < p->ncode; pc++)
        if (p->code[pc].op == SL_OP_TEXTURE)
            return true;
    return false;
}

bool sl_program_uses_space(const sl_program *p, int space)
{
    for (int pc = 0; pc < p->ncode; pc++) {
        const sl_insn *in = &p->code[pc];
        if (in->op == SL_OP_SPACE) return true;            /* named at run time */
        if (in->op == SL_OP_SPACEK &&
            (in->b == space || (in->b == SL_SPACE_DEPTH && space == SL_SPACE_CAMERA)))
            return true;
    }
    return false;
}

uint64_t sl_program_global_slots(const sl_program *p)
{
    _Static_assert(SL_GLOBAL_SLOTS <= 64, "a global slot mask fits 64 bits");
    const uint64_t all = SL_GLOBAL_SLOTS == 64 ? ~0ull : (1ull << SL_GLOBAL_SLOTS) - 1;
    for (int pc = 0; pc < p->ncode; pc++)
        switch (p->code[pc].op) {
        case SL_OP_LSTART: case SL_OP_LNEXT: case SL_OP_AMBIENT: case SL_OP_DIFFUSE:
        case SL_OP_SPECULAR: case SL_OP_PHONG: case SL_OP_RAY: case SL_OP_MESSAGE:
            return all;
        default:
            break;
        }
    uint64_t mask = 0;
    for (int g = 0; g < SL_G__COUNT; g++)
        if (g == SL_G_u || g == SL_G_v || sl_program_reads_global(p, (sl_global)g))
            for (int k = 0; k < sl_global_size((sl_global)g); k++)
                mask |= 1ull << (sl_global_slot((sl_global)g) + k);
    return mask;
}

void sl_program_destroy(sl_program **self_p)
{
    sl_program *p = *self_p;
    if (!p)
        return;
    free(p->name);
    free(p->code);
    free(p->pos);
    free(p->consts);
    free(p->tables);
    free(p->box_plan);
    free(p->slope_plan);
    free(p->split_same);
    free(p->tape_site_of);
    for (int i = 0; i < p->nstrings; i++)
        free(p->strings[i]);
    free(p->strings);
    free(p->string_slots);
    for (int i = 0; i < p->nparams; i++)
        free(p->params[i].name);
    free(p->params);
    for (int i = 0; i < p->nfiles; i++)
        free(p->files[i]);
    free(p->files);
    free(p);
    *self_p = NULL;
}

void sl_program_pos_string(const sl_program *self, int pc, char *buf, size_t size)
{
    if (pc < 0 || pc >= self->ncode) {
        snprintf(buf, size, "?");
        return;
    }
    const sl_insn_pos *ip = &self->pos[pc];
    snprintf(buf, size, "%s:%d:%d", self->files[ip->file], ip->line, ip->col);
}

/* ---------------------------------------------------------------------- */
/* the listing                                                             */
/* ---------------------------------------------------------------------- */

/* "P.x", "Cs.g", "time" for a global slot; "r12" otherwise; "#0.5" for a
 * constant. */
static void slot_name(const sl_program *p, int slot, char *buf, size_t size)
{
    if (slot < SL_GLOBAL_SLOTS) {
        for (int g = 0; g < SL_G__COUNT; g++) {
            int base = sl_global_slot((sl_global)g), n = sl_global_size((sl_global)g);
            if (slot < base || slot >= base + n)
                continue;
            const char *comp = g >= SL_G_Cs && g <= SL_G_Oi ? "rgb"
                             : g == SL_G_Cl ? "rgb" : "xyz";
            if (n == 1)
                snprintf(buf, size, "%s", sl_global_name((sl_global)g));
            else
                snprintf(buf, size, "%s.%c", sl_global_name((sl_global)g), comp[slot - base]);
            return;
        }
    }
    if (slot >= p->const_base && slot < p->const_base + p->nconsts) {
        double k = p->consts[slot - p->const_base];
        for (int digits = 1; digits <= 17; digits++) {     /* shortest exact form */
            snprintf(buf, size, "#%.*g", digits, k);
            if (strtod(buf + 1, NULL) == k)
                break;
        }
        return;
    }
    snprintf(buf, size, "r%d", slot);
}

static void string_name(const sl_program *p, int slot, char *buf, size_t size)
{
    for (int i = 0; i < p->nstrings; i++) {
        if (p->string_slots[i] == slot) {
            snprintf(buf, size, "\"%s\"", p->strings[i]);
            return;
        }
    }
    snprintf(buf, size, "s%d", slot);
}

static void dump_table(const sl_program *p, int index, FILE *out)
{
    int count = p->tables[index];
    fputc('[', out);
    for (int i = 0; i < count; i++) {
        char buf[64], flag[64];
        int v = p->tables[index + 1 + i];
        if (v & SL_TABLE_STRING) {
            fprintf(out, "%ss%d", i ? " " : "", v & SL_TABLE_SLOT);
        } else if (v & SL_TABLE_GUARDED) {
            slot_name(p, v & SL_TABLE_SLOT, buf, sizeof buf);
            slot_name(p, p->tables[index + 2 + i], flag, sizeof flag);
            fprintf(out, "%s%s?%s", i ? " " : "", buf, flag);
            i++;
        } else {
            slot_name(p, v & SL_TABLE_SLOT, buf, sizeof buf);
            fprintf(out, "%s%s%s", i ? " " : "", buf, (v & SL_TABLE_DEATH) ? "!" : "");
        }
    }
    fputc(']', out);
}

static void dump_noise_variant(int v, FILE *out)
{
    static const char *const kind[] = { "noise", "pnoise", "cellnoise", "?" };
    fprintf(out, "%s/%dd%s", kind[SL_NOISE_KIND(v)], SL_NOISE_DIM(v),
            (v & SL_NOISE_VECTOR) ? "/3" : "");
}

static void dump_operand(const sl_program *p, char kind, int value, FILE *out)
{
    char buf[128];
    switch (kind) {
    case 'z': case 'x': slot_name(p, value, buf, sizeof buf); fputs(buf, out); break;
    case 's': string_name(p, value, buf, sizeof buf); fputs(buf, out); break;
    case 'j': fprintf(out, "@%04d", value); break;
    case 't': dump_table(p, value, out); break;
    case 'p': fprintf(out, "%s", p->params[value].name); break;
    case 'n': dump_noise_variant(value, out); break;
    default: fprintf(out, "%d", value); break;
    }
}

static void dump_insn(const sl_program *p, int pc, int width, FILE *out)
{
    const sl_insn *in = &p->code[pc];
    char where[256];
    sl_program_pos_string(p, pc, where, sizeof where);
    fprintf(out, "  %04d  %-*s  %-11s", pc, width, where, names[in->op]);
    const uint16_t ops[4] = { in->a, in->b, in->c, in->d };
    const char *k = kinds[in->op];
    bool first = true;
    for (int i = 0; i < 4; i++) {
        if (k[i] == '-')
            continue;
        if (i == 3 && ops[i] == 0 && (in->op == SL_OP_PARAM || in->op == SL_OP_SPARAM))
            continue;                 /* no constant default */
        fputs(first ? " " : ", ", out);
        first = false;
        dump_operand(p, k[i], ops[i], out);
    }
    fputc('\n', out);
}

void sl_program_dump(const sl_program *self, FILE *out)
{
    const sl_program *p = self;
    fprintf(out, "shader '%s' (%s): %d instructions, %d slots (%d globals, %d constants "
                 "from r%d), %d string slots\n",
            p->name,
            p->kind == SL_SHADER_SURFACE ? "surface"
            : p->kind == SL_SHADER_LIGHT ? "light" : "displacement", p->ncode,
            p->nslots, SL_GLOBAL_SLOTS, p->nconsts, p->const_base, p->nstring_slots);
    if (p->nparams)
        fprintf(out, "parameters:\n");
    for (int i = 0; i < p->nparams; i++)
        fprintf(out, "  %s%-6s %-16s %s%d\n", p->params[i].output ? "output " : "",
                sl_ty_name(p->params[i].type), p->params[i].name,
                p->params[i].type == SL_TYPE_STRING ? "s" : "r", p->params[i].slot);
    int width = 0;
    for (int pc = 0; pc < p->ncode; pc++) {
        char where[256];
        sl_program_pos_string(p, pc, where, sizeof where);
        if ((int)strlen(where) > width)
            width = (int)strlen(where);
    }
    fprintf(out, "code:\n");
    for (int pc = 0; pc < p->ncode; pc++)
        dump_insn(p, pc, width, out);
}

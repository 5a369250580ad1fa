/*
 * codegen.c: from the checked tree to bytecode (see codegen.h).
 *
 * Slots. Variables and temporaries are allocated from a stack pointer
 * (sp): a statement frees its temporaries, a block its variables. The
 * constant pool is placed after the highest slot used, so constant
 * operands are emitted with CONST_TAG and fixed up at the end; string
 * constants likewise in the string file.
 *
 * Expressions. cg_gen_expr(e, dst) returns the slot holding e's value; with
 * dst >= 0 the value must end up in dst. Componentwise (lane-wise) work
 * writes straight into dst: lane i only reads lane i of its operands, all
 * computed before, so an assignment like P = P + N * d needs no copy. Work
 * that mixes lanes (cross, transforms, calls) goes through temporaries.
 *
 * Control flow (paper §4.1). `if` becomes BR_BEGIN cond / BR_ELSE /
 * BR_END, loops LOOP_TEST / LOOP_END, each with a merge table: the slots
 * below the region's starting sp (variables that outlive the region) that
 * the region writes. A backend that cannot decide the condition runs both
 * sides and merges exactly those slots. break, continue and return become
 * flag variables: the statements after one that may escape are guarded by
 * "no flag set", and loop conditions test the flags; so every region is
 * single-entry single-exit and the merges stay sound.
 *
 * User functions are inlined at each call: parameters are bound to the
 * argument slots (by reference, as in RenderMan), the result goes to a
 * fresh slot. A nested function's extern variables are the enclosing
 * function's symbols, whose slots are those of the call being generated.
 *
 * Arrays occupy length * element slots; a constant index addresses an
 * element directly, a varying one goes through ALOAD/ASTORE lane by lane,
 * and a store puts the whole array in the enclosing merge table.
 *
 * Calls of built-in functions are generated in codegen_builtin.c; the
 * state and helpers both files use are declared in codegen_internal.h.
 */
#include "sl/codegen.h"
#include "sl/codegen_internal.h"
#include "sl/builtins.h"
#include "sl/check.h"
#include "sl/lexer.h"
#include "util/xalloc.h"
#include "tex/tex.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>


static void gen_stmt(cg *g, sl_node *n);

void cg_fail(cg *g, const char *fmt, ...)
{
    if (g->failed)
        return;
    g->failed = true;
    va_list ap;
    va_start(ap, fmt);
    sl_diag_vreport(g->diag, SL_DIAG_ERROR, g->cur, fmt, ap);
    va_end(ap);
}

/* ---------------------------------------------------------------------- */
/* slots                                                                   */
/* ---------------------------------------------------------------------- */

int cg_alloc_slots(cg *g, int n)
{
    int slot = g->sp;
    if (g->sp + n > SL_MAX_SLOTS) {
        cg_fail(g, "shader needs more than %d registers (the limit per shader)", SL_MAX_SLOTS);
        return SL_GLOBAL_SLOTS;
    }
    g->sp += n;
    if (g->sp > g->max_sp)
        g->max_sp = g->sp;
    return slot;
}

int cg_alloc_string(cg *g)
{
    if (g->ssp + 1 > SL_MAX_STRING_SLOTS / 2) {
        cg_fail(g, "shader needs more than %d string registers", SL_MAX_STRING_SLOTS / 2);
        return 0;
    }
    int slot = g->ssp++;
    if (g->ssp > g->max_ssp)
        g->max_ssp = g->ssp;
    return slot;
}

int cg_const_slot(cg *g, double value)
{
    sl_program *p = g->prog;
    for (int i = 0; i < p->nconsts; i++)
        if (memcmp(&p->consts[i], &value, sizeof value) == 0)
            return CONST_TAG | i;
    if (p->nconsts >= SL_MAX_SLOTS / 2) {
        cg_fail(g, "shader has more than %d constants", SL_MAX_SLOTS / 2);
        return CONST_TAG;
    }
    if (p->nconsts == g->consts_cap) {
        g->consts_cap = g->consts_cap ? 2 * g->consts_cap : 16;
        p->consts = xrealloc(p->consts, (size_t)g->consts_cap * sizeof *p->consts);
    }
    p->consts[p->nconsts] = value;
    return CONST_TAG | p->nconsts++;
}

int cg_string_const(cg *g, const char *text, size_t len)
{
    sl_program *p = g->prog;
    for (int i = 0; i < p->nstrings; i++)
        if (strlen(p->strings[i]) == len && memcmp(p->strings[i], text, len) == 0)
            return CONST_TAG | i;
    if (p->nstrings >= SL_MAX_STRING_SLOTS / 2) {
        cg_fail(g, "shader has more than %d string constants", SL_MAX_STRING_SLOTS / 2);
        return CONST_TAG;
    }
    if (p->nstrings == g->strings_cap) {
        g->strings_cap = g->strings_cap ? 2 * g->strings_cap : 8;
        p->strings = xrealloc(p->strings, (size_t)g->strings_cap * sizeof *p->strings);
        p->string_slots = xrealloc(p->string_slots,
                                      (size_t)g->strings_cap * sizeof *p->string_slots);
    }
    p->strings[p->nstrings] = xstrndup(text, len);
    return CONST_TAG | p->nstrings++;
}

static int file_index(cg *g, const char *file)
{
    sl_program *p = g->prog;
    if (!file)
        file = "";
    for (int i = 0; i < p->nfiles; i++)
        if (strcmp(p->files[i], file) == 0)
            return i;
    if (p->nfiles == g->files_cap) {
        g->files_cap = g->files_cap ? 2 * g->files_cap : 4;
        p->files = xrealloc(p->files, (size_t)g->files_cap * sizeof *p->files);
    }
    p->files[p->nfiles] = xstrndup(file, strlen(file));
    return p->nfiles++;
}

/* ---------------------------------------------------------------------- */
/* merge regions                                                           */
/* ---------------------------------------------------------------------- */

static void region_begin(cg *g)
{
    if (g->nregions == g->regions_cap) {
        g->regions_cap = g->regions_cap ? 2 * g->regions_cap : 8;
        g->regions = xrealloc(g->regions, (size_t)g->regions_cap * sizeof *g->regions);
    }
    region *r = &g->regions[g->nregions++];
    memset(r, 0, sizeof *r);
    r->start_sp = g->sp;
    r->start_ssp = g->ssp;
}

void cg_record_write(cg *g, int slot, int n)
{
    if (g->nregions == 0)
        return;
    region *r = &g->regions[g->nregions - 1];
    for (int s = slot; s < slot + n && s < r->start_sp; s++)
        r->bits[s / 8] |= (uint8_t)(1u << (s % 8));
}

void cg_record_string_write(cg *g, int slot)
{
    if (g->nregions == 0 || (slot & CONST_TAG))
        return;
    region *r = &g->regions[g->nregions - 1];
    if (slot < r->start_ssp)
        r->sbits[slot / 8] |= (uint8_t)(1u << (slot % 8));
}

static int push_table_entry(cg *g, uint16_t value)
{
    sl_program *p = g->prog;
    if (p->ntables == g->tables_cap) {
        g->tables_cap = g->tables_cap ? 2 * g->tables_cap : 64;
        p->tables = xrealloc(p->tables, (size_t)g->tables_cap * sizeof *p->tables);
    }
    p->tables[p->ntables] = value;
    return p->ntables++;
}

/* The "returned" flag guarding slot s, or -1. */
static int ret_guard(const cg *g, int s)
{
    for (int i = 0; i < g->nrets; i++)
        if (s >= g->rets[i].slot && s < g->rets[i].slot + g->rets[i].size)
            return g->rets[i].flag;
    return -1;
}

/* Closes the innermost region: its table (count of positions, then the
 * slots; string slots tagged SL_TABLE_STRING; a return slot tagged
 * SL_TABLE_GUARDED followed by its flag slot), merged into the enclosing
 * region. */
static int region_end(cg *g)
{
    assert(g->nregions > 0);
    region *r = &g->regions[g->nregions - 1];
    assert(g->sp >= r->start_sp && g->ssp >= r->start_ssp);
    int count = 0;
    for (int s = 0; s < r->start_sp; s++)
        if ((r->bits[s / 8] >> (s % 8)) & 1)
            count += ret_guard(g, s) >= 0 ? 2 : 1;
    for (int s = 0; s < r->start_ssp; s++)
        count += (r->sbits[s / 8] >> (s % 8)) & 1;
    if (g->prog->ntables + count + 1 > 0xffff) {
        cg_fail(g, "shader too large: merge tables exceed %d entries", 0xffff);
        g->nregions--;
        return 0;
    }
    int index = push_table_entry(g, (uint16_t)count);
    for (int s = 0; s < r->start_sp; s++) {
        if (!((r->bits[s / 8] >> (s % 8)) & 1))
            continue;
        int flag = ret_guard(g, s);
        if (flag >= 0) {
            push_table_entry(g, (uint16_t)(SL_TABLE_GUARDED | s));
            push_table_entry(g, (uint16_t)flag);
        } else if ((g->death[s / 8] >> (s % 8)) & 1) {
            push_table_entry(g, (uint16_t)(SL_TABLE_DEATH | s));
        } else {
            push_table_entry(g, (uint16_t)s);
        }
    }
    for (int s = 0; s < r->start_ssp; s++)
        if ((r->sbits[s / 8] >> (s % 8)) & 1)
            push_table_entry(g, (uint16_t)(SL_TABLE_STRING | s));
    g->nregions--;
    if (g->nregions > 0) {
        region *outer = &g->regions[g->nregions - 1];
        for (int s = 0; s < r->start_sp && s < outer->start_sp; s++)
            if ((r->bits[s / 8] >> (s % 8)) & 1)
                outer->bits[s / 8] |= (uint8_t)(1u << (s % 8));
        for (int s = 0; s < r->start_ssp && s < outer->start_ssp; s++)
            if ((r->sbits[s / 8] >> (s % 8)) & 1)
                outer->sbits[s / 8] |= (uint8_t)(1u << (s % 8));
    }
    return index;
}

static void set_death(cg *g, int slot, bool on)
{
    if (slot < 0)
        return;
    if (on)
        g->death[slot / 8] |= (uint8_t)(1u << (slot % 8));
    else
        g->death[slot / 8] &= (uint8_t)~(1u << (slot % 8));
}

/* ---------------------------------------------------------------------- */
/* emitting                                                                */
/* ---------------------------------------------------------------------- */

static int written_count(const sl_insn *in, const sl_program *p)
{
    switch (in->op) {
    case SL_OP_MOVN: return in->c;
    case SL_OP_NOISE: return (in->c & SL_NOISE_VECTOR) ? 3 : 1;
    case SL_OP_RANDOM: return in->b;
    case SL_OP_RAY: return (in->d & ((1 << SL_RAY_KIND_BITS) - 1)) == SL_RAY_TRACE ? 3 : 1;
    case SL_OP_TEXTURE: return sl_texop_outs(in->d);
    case SL_OP_CALCNORMAL: case SL_OP_AMBIENT: case SL_OP_DIFFUSE: case SL_OP_SPECULAR:
    case SL_OP_PHONG: case SL_OP_XPOINT: case SL_OP_XVECTOR: case SL_OP_XNORMAL:
    case SL_OP_SETCOMP:
        return 3;
    case SL_OP_SPACE: case SL_OP_SPACEK: case SL_OP_MINVERT: return 16;
    case SL_OP_PARAM: return p->params[in->b].size;
    case SL_OP_ASTORE: return 0;     /* the whole array: recorded by gen_store */
    case SL_OP_END: case SL_OP_SMOV: case SL_OP_SPARAM: case SL_OP_JMP:
    case SL_OP_BR_BEGIN: case SL_OP_BR_ELSE: case SL_OP_BR_END:
    case SL_OP_LOOP_TEST: case SL_OP_LOOP_END: case SL_OP_ACCUM_END:
        return 0;
    default: return 1;
    }
}

int cg_emit(cg *g, sl_opcode op, int a, int b, int c, int d)
{
    sl_program *p = g->prog;
    if (g->failed)
        return 0;
    if (p->ncode >= SL_MAX_CODE - 1) {
        cg_fail(g, "shader too large: more than %d instructions (after inlining functions)",
             SL_MAX_CODE - 1);
        return 0;
    }
    if (p->ncode == g->code_cap) {
        g->code_cap = g->code_cap ? 2 * g->code_cap : 256;
        p->code = xrealloc(p->code, (size_t)g->code_cap * sizeof *p->code);
        p->pos = xrealloc(p->pos, (size_t)g->code_cap * sizeof *p->pos);
    }
    sl_insn *in = &p->code[p->ncode];
    in->op = (uint8_t)op;
    in->a = (uint16_t)a;
    in->b = (uint16_t)b;
    in->c = (uint16_t)c;
    in->d = (uint16_t)d;
    sl_insn_pos *ip = &p->pos[p->ncode];
    ip->file = (uint16_t)file_index(g, g->cur.file);
    ip->line = g->cur.line;
    ip->col = (uint16_t)(g->cur.col > 0xffff ? 0xffff : g->cur.col);
    int w = written_count(in, p);
    if (w > 0)
        cg_record_write(g, a, w);
    if (op == SL_OP_SMOV || op == SL_OP_SPARAM)
        cg_record_string_write(g, a);
    return p->ncode++;
}

static int here(const cg *g) { return g->prog->ncode; }

/* ESCAPE flag: its table is patched when the construct it leaves closes. */
static void emit_escape(cg *g, int flag, int kind, int id)
{
    int pc = cg_emit(g, SL_OP_ESCAPE, flag, id, 0, kind);
    if (g->failed)
        return;
    if (g->nescapes == g->escapes_cap) {
        g->escapes_cap = g->escapes_cap ? 2 * g->escapes_cap : 16;
        g->escapes = xrealloc(g->escapes, (size_t)g->escapes_cap * sizeof *g->escapes);
    }
    g->escapes[g->nescapes++] = (struct pending_escape){ pc, kind, id };
}

static void patch_escapes(cg *g, int kind, int id, int table)
{
    int kept = 0;
    for (int i = 0; i < g->nescapes; i++) {
        struct pending_escape *e = &g->escapes[i];
        if (e->kind == kind && e->id == id) {
            if (!g->failed)
                g->prog->code[e->pc].c = (uint16_t)table;
        } else {
            g->escapes[kept++] = *e;
        }
    }
    g->nescapes = kept;
}

void cg_emit_mov(cg *g, int dst, int src, int n)
{
    if (dst == src || n == 0)
        return;
    if (n == 1)
        cg_emit(g, SL_OP_MOV, dst, src, 0, 0);
    else
        cg_emit(g, SL_OP_MOVN, dst, src, n, 0);
}

/* The value at src (size n) in dst when dst >= 0. */
int cg_into(cg *g, int src, int dst, int n)
{
    if (dst < 0 || dst == src)
        return src;
    cg_emit_mov(g, dst, src, n);
    return dst;
}

int cg_into_string(cg *g, int src, int dst)
{
    if (dst < 0 || dst == src)
        return src;
    cg_emit(g, SL_OP_SMOV, dst, src, 0, 0);
    return dst;
}

/* dst, or -1 when writing lane by lane into dst could overwrite a lane of
 * an operand before it is read (v = v.x * v: the broadcast v.x is lane 0
 * of the destination). */
int cg_lane_safe(int dst, int n, const int *args, const int *sizes, int k)
{
    if (dst < 0)
        return -1;
    for (int j = 0; j < k; j++) {
        int s = args[j], len = sizes[j];
        if (s & CONST_TAG)
            continue;
        bool overlap = s < dst + n && dst < s + len;
        if (overlap && !(len == n && s == dst))
            return -1;
    }
    return dst;
}

/* ---------------------------------------------------------------------- */
/* scalar helpers                                                          */
/* ---------------------------------------------------------------------- */

int cg_op1(cg *g, sl_opcode op, int x)
{
    int z = cg_alloc_slots(g, 1);
    cg_emit(g, op, z, x, 0, 0);
    return z;
}

int cg_op2(cg *g, sl_opcode op, int x, int y)
{
    int z = cg_alloc_slots(g, 1);
    cg_emit(g, op, z, x, y, 0);
    return z;
}

/* x . y over n lanes into z (or a new slot). */
int cg_gen_dot(cg *g, int x, int y, int n, int dst)
{
    int z = cg_target(g, dst, 1);
    cg_emit(g, SL_OP_MUL, z, x, y, 0);
    for (int i = 1; i < n; i++) {
        int t = cg_op2(g, SL_OP_MUL, x + i, y + i);
        cg_emit(g, SL_OP_ADD, z, z, t, 0);
    }
    return z;
}

/* Logical OR of flag slots, negated: "no flag set". -1 when none. */
static int none_set(cg *g, const int *flags, int n)
{
    if (n == 0)
        return -1;
    int any = flags[0];
    for (int i = 1; i < n; i++)
        any = cg_op2(g, SL_OP_OR, any, flags[i]);
    return cg_op1(g, SL_OP_NOT, any);
}

/* ---------------------------------------------------------------------- */
/* expressions                                                             */
/* ---------------------------------------------------------------------- */

static int gen_ident(cg *g, sl_node *e, int dst)
{
    sl_sym *s = e->sym;
    if (s->kind == SL_SYM_CONST)
        return cg_into(g, cg_const_slot(g, s->value), dst, 1);
    if (s->ty == SL_TYPE_STRING)
        return cg_into_string(g, s->slot, dst);
    return cg_into(g, s->slot, dst, cg_size_of(e));
}

static sl_opcode arith_op(int tok)
{
    switch (tok) {
    case SL_TOK_PLUS: return SL_OP_ADD;
    case SL_TOK_MINUS: return SL_OP_SUB;
    case SL_TOK_STAR: return SL_OP_MUL;
    case SL_TOK_SLASH: return SL_OP_DIV;
    case SL_TOK_LT: return SL_OP_LT;
    case SL_TOK_LE: return SL_OP_LE;
    case SL_TOK_GT: return SL_OP_GT;
    case SL_TOK_GE: return SL_OP_GE;
    case SL_TOK_EQ: return SL_OP_EQ;
    case SL_TOK_NE: return SL_OP_NE;
    case SL_TOK_AND: return SL_OP_AND;
    default: return SL_OP_OR;
    }
}

/* Matrix product a * b (4x4, row-major lanes: m[r][c] at r * 4 + c). */
int cg_gen_matmul(cg *g, int a, int b, int dst)
{
    int z = cg_alloc_slots(g, 16);
    for (int r = 0; r < 4; r++) {
        for (int c = 0; c < 4; c++) {
            int acc = z + r * 4 + c;
            cg_emit(g, SL_OP_MUL, acc, a + r * 4, b + c, 0);
            for (int k = 1; k < 4; k++) {
                int t = cg_op2(g, SL_OP_MUL, a + r * 4 + k, b + k * 4 + c);
                cg_emit(g, SL_OP_ADD, acc, acc, t, 0);
            }
        }
    }
    return cg_into(g, z, dst, 16);
}

int cg_gen_cross(cg *g, int a, int b, int dst)
{
    int z = cg_alloc_slots(g, 3);
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        int t = cg_op2(g, SL_OP_MUL, a + j, b + k);
        int u = cg_op2(g, SL_OP_MUL, a + k, b + j);
        cg_emit(g, SL_OP_SUB, z + i, t, u, 0);
    }
    return cg_into(g, z, dst, 3);
}

/* Constant folding: + - * / of two constants, evaluated once in double
 * (as the float mode would); -1 when not both constant. */
static int fold(cg *g, int op, int x, int y)
{
    if (!(x & CONST_TAG) || !(y & CONST_TAG))
        return -1;
    double a = g->prog->consts[x & ~CONST_TAG], b = g->prog->consts[y & ~CONST_TAG], r;
    switch (op) {
    case SL_TOK_PLUS: r = a + b; break;
    case SL_TOK_MINUS: r = a - b; break;
    case SL_TOK_STAR: r = a * b; break;
    case SL_TOK_SLASH: r = a / b; break;
    default: return -1;
    }
    if (!isfinite(r))
        return -1;
    return cg_const_slot(g, r);
}

/* Binary node e once its left operand e->a is in x. */
static int gen_binary_rest(cg *g, sl_node *e, int x, int dst)
{
    int na = cg_size_of(e->a), nb = cg_size_of(e->b);
    if (e->a->ty == SL_TYPE_STRING) {
        int y = cg_gen_expr(g, e->b, -1);
        int z = cg_target(g, dst, 1);
        cg_emit(g, e->op == SL_TOK_EQ ? SL_OP_SEQ : SL_OP_SNE, z, x, y, 0);
        return z;
    }
    int y = cg_gen_expr(g, e->b, -1);
    int folded = fold(g, e->op, x, y);
    if (folded >= 0)
        return cg_into(g, folded, dst, 1);
    switch (e->op) {
    case SL_TOK_DOT: return cg_gen_dot(g, x, y, 3, dst);
    case SL_TOK_CARET: return cg_gen_cross(g, x, y, dst);
    case SL_TOK_STAR:
        if (na == 16 && nb == 16)     /* RenderMan's a * b: a first, then b */
            return cg_gen_matmul(g, y, x, dst);
        break;
    case SL_TOK_SLASH:
        if (nb == 16) {               /* a / b = a * inverse(b) (RI Spec 3.2 §12) */
            int inv = cg_alloc_slots(g, 16);
            cg_emit(g, SL_OP_MINVERT, inv, y, 0, 0);
            if (na == 16)
                return cg_gen_matmul(g, inv, x, dst);
            int z = cg_target(g, dst, 16);
            for (int i = 0; i < 16; i++)
                cg_emit(g, SL_OP_MUL, z + i, x, inv + i, 0);
            return z;
        }
        break;
    case SL_TOK_EQ: case SL_TOK_NE:
        if (na > 1) {          /* all lanes equal / some lane differs */
            int z = cg_target(g, dst, 1);
            sl_opcode cmp = e->op == SL_TOK_EQ ? SL_OP_EQ : SL_OP_NE;
            sl_opcode join = e->op == SL_TOK_EQ ? SL_OP_AND : SL_OP_OR;
            int acc = cg_op2(g, cmp, x, y);
            for (int i = 1; i < na; i++)
                acc = cg_op2(g, join, acc, cg_op2(g, cmp, x + i, y + i));
            cg_emit_mov(g, z, acc, 1);
            return z;
        }
        break;
    default: break;
    }
    int n = cg_size_of(e);
    if (e->ty == SL_TY_BOOL)
        n = 1;
    int ops[2] = { x, y }, sizes[2] = { na, nb };
    int z = cg_target(g, cg_lane_safe(dst, n, ops, sizes, 2), n);
    for (int i = 0; i < n; i++)
        cg_emit(g, arith_op(e->op), z + i, cg_lane(x, na, i), cg_lane(y, nb, i), 0);
    return cg_into(g, z, dst, n);
}

/* A chain of binary operators, in the order of the recursion over `a`
 * (the same code), with a loop over its spine (ast.h). */
static int gen_binary(cg *g, sl_node *e, int dst)
{
    sl_spine spine;
    sl_spine_collect(&spine, e);
    int x = cg_gen_expr(g, spine.v[spine.n - 1]->a, -1);
    for (int i = spine.n - 1; i >= 0 && !g->failed; i--) {
        g->cur = spine.v[i]->pos;
        x = gen_binary_rest(g, spine.v[i], x, i == 0 ? dst : -1);
    }
    sl_spine_clear(&spine);
    if (g->failed)
        return dst >= 0 ? dst : SL_GLOBAL_SLOTS;
    return x;
}

static int gen_unary(cg *g, sl_node *e, int dst)
{
    int x = cg_gen_expr(g, e->a, -1);
    if (e->op == SL_TOK_MINUS && (x & CONST_TAG))
        return cg_into(g, cg_const_slot(g, -g->prog->consts[x & ~CONST_TAG]), dst, 1);
    int n = e->op == SL_TOK_NOT ? 1 : cg_size_of(e);
    int z = cg_target(g, dst, n);
    for (int i = 0; i < n; i++)
        cg_emit(g, e->op == SL_TOK_NOT ? SL_OP_NOT : SL_OP_NEG, z + i, x + i, 0, 0);
    return z;
}

/* A branch being generated: BR_BEGIN cond, then the then-part, BR_ELSE,
 * the else-part, BR_END, in three calls. */
typedef struct branch {
    sl_pos at;                       /* the if: where merge errors point */
    int begin, mid;
} branch;

static branch branch_begin(cg *g, int cond)
{
    branch b = { g->cur, cg_emit(g, SL_OP_BR_BEGIN, cond, 0, 0, 0), 0 };
    region_begin(g);
    return b;
}

static void branch_else(cg *g, branch *b)
{
    g->cur = b->at;
    b->mid = cg_emit(g, SL_OP_BR_ELSE, 0, b->begin, 0, 0);
}

static void branch_end(cg *g, const branch *b)
{
    g->cur = b->at;
    int end = cg_emit(g, SL_OP_BR_END, b->begin, 0, 0, 0);
    int table = region_end(g);
    if (g->failed)
        return;
    sl_insn *code = g->prog->code;
    code[b->begin].b = (uint16_t)(b->mid + 1);
    code[b->begin].c = (uint16_t)table;
    code[b->mid].a = (uint16_t)end;
    code[end].b = (uint16_t)table;
}

/* BR_BEGIN cond ... BR_ELSE ... BR_END around two generators. */
void cg_gen_branches(cg *g, int cond, branch_fn then_fn, void *then_arg,
                         branch_fn else_fn, void *else_arg)
{
    branch b = branch_begin(g, cond);
    then_fn(g, then_arg);
    branch_else(g, &b);
    if (else_fn)
        else_fn(g, else_arg);
    branch_end(g, &b);
}

typedef struct value_job {
    sl_node *e;
    int dst;
} value_job;

static void gen_value_job(cg *g, void *arg)
{
    value_job *job = arg;
    int saved = g->sp;
    if (job->e->ty == SL_TYPE_STRING)
        cg_into_string(g, cg_gen_expr(g, job->e, -1), job->dst);
    else
        cg_gen_expr(g, job->e, job->dst);
    g->sp = saved;
}

static int gen_cond_expr(cg *g, sl_node *e, int dst)
{
    bool str = e->ty == SL_TYPE_STRING;
    int z = dst >= 0 ? dst : str ? cg_alloc_string(g) : cg_alloc_slots(g, cg_size_of(e));
    int mark = g->sp;
    int c = cg_gen_expr(g, e->a, -1);
    g->sp = mark;
    value_job a = { e->b, z }, b = { e->c, z };
    cg_gen_branches(g, c, gen_value_job, &a, gen_value_job, &b);
    return z;
}

/* ---------------------------------------------------------------------- */
/* arrays                                                                  */
/* ---------------------------------------------------------------------- */

/* The length of array variable s here (an unsized parameter: its argument's). */
int cg_array_len(const sl_sym *s)
{
    int len = sl_ty_len(s->ty);
    return len ? len : s->cg_len;
}

int cg_array_operand(int len, int stride)
{
    int code = stride == 1 ? 0 : stride == 3 ? 1 : 2;
    return len | code << SL_ARRAY_STRIDE_SHIFT;
}

/* The element a constant index names, or -1 (reported) out of range. */
static int const_element(cg *g, const sl_node *x, int index, int len)
{
    double k = floor(g->prog->consts[index & ~CONST_TAG]);
    if (!(k >= 0 && k < len)) {
        cg_fail(g, "array index %g is out of range for '%s' (0 to %d)", k, x->a->name, len - 1);
        return -1;
    }
    return (int)k;
}

/* a[i] (x) into dst: a constant index addresses the element's slots, a
 * varying one loads lane by cg_lane (paper §4: in range modes the merge of
 * every element the index can reach). */
static int gen_index(cg *g, sl_node *x, int dst)
{
    const sl_sym *s = x->a->sym;
    int len = cg_array_len(s), n = cg_size_of(x);
    int i = cg_gen_expr(g, x->b, -1);
    if (i & CONST_TAG) {
        int k = const_element(g, x, i, len);
        return k < 0 ? 0 : cg_into(g, s->slot + k * n, dst, n);
    }
    /* lanes write z in turn: z must not hold the index */
    int z = dst >= 0 && !(i >= dst && i < dst + n) ? dst : cg_alloc_slots(g, n);
    for (int k = 0; k < n; k++)
        cg_emit(g, SL_OP_ALOAD, z + k, s->slot + k, i, cg_array_operand(len, n));
    return cg_into(g, z, dst, n);
}

/* a[i] = v: v's slots (size n) stored; every element may change. */
static int gen_store(cg *g, sl_node *x, sl_node *value, int dst)
{
    const sl_sym *s = x->a->sym;
    int len = cg_array_len(s), n = cg_size_of(x);
    int i = cg_gen_expr(g, x->b, -1);
    int v = cg_gen_expr(g, value, -1);
    if (i & CONST_TAG) {
        int k = const_element(g, x, i, len);
        if (k < 0)
            return 0;
        cg_emit_mov(g, s->slot + k * n, v, n);
        return cg_into(g, s->slot + k * n, dst, n);
    }
    for (int k = 0; k < n; k++)
        cg_emit(g, SL_OP_ASTORE, s->slot + k, i, v + k, cg_array_operand(len, n));
    cg_record_write(g, s->slot, len * n);
    return cg_into(g, v, dst, n);
}

/* RSL 2 resizable arrays (a local 'float a[];'): SL_RESIZABLE_CAPACITY
 * elements and a length slot. push stores at a[length] (astore: in range
 * modes merged into every element the length can reach) and adds 1; pop
 * subtracts 1 and loads a[length]; resize sets the length (floor(n), at
 * least 0); resize and reserve probe element n - 1 with aload, so a size
 * beyond the capacity stops the run there ("array index out of range");
 * arraylength reads the length. */
static int gen_resizable(cg *g, sl_node *e, int dst)
{
    const sl_sym *s = e->list[0]->sym;
    int L = s->cg_len_slot;
    if (!L) {
        cg_fail(g, "%s() on '%s': the array passed for it is not resizable (declare it without "
             "size or initializer, as 'float a[];')", e->name, s->name);
        return 0;
    }
    int len = cg_array_len(s), n = sl_ty_slots(sl_ty_elem(s->ty));
    if (strcmp(e->name, "arraylength") == 0)
        return cg_into(g, L, dst, 1);
    switch (e->op) {
    case SL_RESIZE_RESIZE: case SL_RESIZE_RESERVE: {
        int k = cg_op1(g, SL_OP_FLOOR, cg_gen_expr(g, e->list[1], -1));
        int probe = cg_op2(g, SL_OP_MAX, cg_op2(g, SL_OP_SUB, k, cg_const_slot(g, 1)), cg_const_slot(g, 0));
        cg_emit(g, SL_OP_ALOAD, cg_alloc_slots(g, 1), s->slot, probe, cg_array_operand(len, n));
        if (e->op == SL_RESIZE_RESIZE)
            cg_emit(g, SL_OP_MAX, L, k, cg_const_slot(g, 0), 0);
        return 0;
    }
    case SL_RESIZE_PUSH: {
        int v = cg_gen_expr(g, e->list[1], -1);
        for (int k = 0; k < n; k++)
            cg_emit(g, SL_OP_ASTORE, s->slot + k, L, v + k, cg_array_operand(len, n));
        cg_record_write(g, s->slot, len * n);
        cg_emit(g, SL_OP_ADD, L, L, cg_const_slot(g, 1), 0);
        return 0;
    }
    default: {               /* pop */
        cg_emit(g, SL_OP_SUB, L, L, cg_const_slot(g, 1), 0);
        int z = cg_alloc_slots(g, n);
        for (int k = 0; k < n; k++)
            cg_emit(g, SL_OP_ALOAD, z + k, s->slot + k, L, cg_array_operand(len, n));
        return cg_into(g, z, dst, n);
    }
    }
}

/* { values } into the array at dst. */
static int gen_array_init(cg *g, sl_node *e, int dst)
{
    int n = sl_ty_slots(sl_ty_elem(e->ty));
    for (int i = 0; i < e->nlist; i++) {
        int mark = g->sp;
        cg_gen_expr(g, e->list[i], dst + i * n);
        g->sp = mark;
    }
    return dst;
}

static int gen_assign(cg *g, sl_node *e, int dst)
{
    if (e->a->kind == SL_N_INDEX)
        return gen_store(g, e->a, e->b, dst);
    sl_sym *s = e->a->sym;
    if (s->ty == SL_TYPE_STRING) {
        int v = cg_gen_expr(g, e->b, -1);
        cg_into_string(g, v, s->slot);
        return cg_into_string(g, s->slot, dst);
    }
    cg_gen_expr(g, e->b, s->slot);
    return cg_into(g, s->slot, dst, sl_ty_slots(s->ty));
}

/* The matrix of a named space (constant or string slot), into 16 slots. */
static int gen_space_matrix(cg *g, sl_node *space, int dir)
{
    int m = cg_alloc_slots(g, 16);
    if (space->kind == SL_N_STR) {
        cg_emit(g, SL_OP_SPACEK, m, sl_space_find(space->name), dir, 0);
    } else {
        int s = cg_gen_expr(g, space, -1);
        cg_emit(g, SL_OP_SPACE, m, s, dir, 0);
    }
    return m;
}

static bool is_current(const sl_node *space)
{
    return space->kind == SL_N_STR && strcmp(space->name, "current") == 0;
}

/* Applies the named-space transform to x (3 slots): op XPOINT/XVECTOR use
 * the matrix itself, XNORMAL the inverse (it applies the transpose). */
int cg_gen_space_xform(cg *g, sl_opcode op, sl_node *space, int dir, int x, int dst)
{
    if (is_current(space))
        return cg_into(g, x, dst, 3);
    int use = op == SL_OP_XNORMAL ? 1 - dir : dir;
    int m = gen_space_matrix(g, space, use);
    int z = cg_target(g, dst, 3);       /* the transform reads x before it writes z */
    cg_emit(g, op, z, m, x, 0);
    return z;
}

static int gen_cast(cg *g, sl_node *e, int dst)
{
    int n = cg_size_of(e);
    int v;
    if (e->nlist == 1) {
        v = cg_gen_expr(g, e->list[0], e->name ? -1 : dst);
    } else {
        /* a component may read the destination: build in fresh slots. A
         * matrix is written in RenderMan's order (row vectors, the
         * translation in elements 12..14) and kept transposed, as vecmath
         * does: element k goes to row k % 4, column k / 4. */
        v = cg_alloc_slots(g, n);
        for (int i = 0; i < e->nlist; i++)
            cg_gen_expr(g, e->list[i], n == 16 ? v + (i % 4) * 4 + i / 4 : v + i);
    }
    if (e->name && e->ty == SL_TYPE_COLOR)      /* color "hsv" (h, s, v) */
        return cg_into(g, cg_gen_color_space(g, sl_color_space_find(e->name), v, true), dst, 3);
    if (e->name && e->ty == SL_TYPE_MATRIX) {   /* given in that space: M * to_current */
        sl_node space = { .kind = SL_N_STR, .name = e->name, .pos = e->pos };
        if (is_current(&space))
            return cg_into(g, v, dst, 16);
        int m = gen_space_matrix(g, &space, SL_SPACE_TO_CURRENT);
        return cg_gen_matmul(g, m, v, dst);
    }
    if (e->name && sl_ty_is_spatial(e->ty)) {
        sl_opcode op = e->ty == SL_TYPE_POINT ? SL_OP_XPOINT
                     : e->ty == SL_TYPE_VECTOR ? SL_OP_XVECTOR : SL_OP_XNORMAL;
        sl_node space = { .kind = SL_N_STR, .name = e->name, .pos = e->pos };
        return cg_gen_space_xform(g, op, &space, SL_SPACE_TO_CURRENT, v, dst);
    }
    return cg_into(g, v, dst, n);
}

static int gen_conv(cg *g, sl_node *e, int dst)
{
    int x = cg_gen_expr(g, e->a, -1);
    if (e->ty == SL_TY_BOOL) {
        int z = cg_target(g, dst, 1);
        cg_emit(g, SL_OP_NE, z, x, cg_const_slot(g, 0), 0);
        return z;
    }
    int n = cg_size_of(e);
    int z = cg_target(g, dst, n);
    if (n == 16) {
        for (int i = 0; i < 16; i++)
            cg_emit(g, SL_OP_MOV, z + i, i % 5 == 0 ? x : cg_const_slot(g, 0), 0, 0);
        return z;
    }
    for (int i = 0; i < n; i++)
        cg_emit(g, SL_OP_MOV, z + i, x, 0, 0);
    return z;
}

/* ---------------------------------------------------------------------- */
/* user functions: inlined                                                 */
/* ---------------------------------------------------------------------- */

static int gen_user_call(cg *g, sl_node *e, int dst)
{
    sl_func *f = e->func;
    if (g->inline_depth >= SL_MAX_INLINE_DEPTH) {
        cg_fail(g, "function calls nested too deeply (limit %d)", SL_MAX_INLINE_DEPTH);
        return 0;
    }
    int args[SL_MAX_FUNC_PARAMS];
    assert(e->nlist <= SL_MAX_FUNC_PARAMS);      /* the checker's limit */
    for (int i = 0; i < e->nlist; i++)
        args[i] = cg_gen_expr(g, e->list[i], -1);
    for (int i = 0; i < e->nlist; i++) {
        sl_sym *p = f->params[i];
        if (sl_ty_is_array(p->ty)) {       /* by reference, with its length */
            int len = cg_array_len(e->list[i]->sym);
            if (sl_ty_len(p->ty) && sl_ty_len(p->ty) != len) {
                cg_fail(g, "argument %d of '%s': an array of %d elements where %d are expected",
                     i + 1, f->name, len, sl_ty_len(p->ty));
                return 0;
            }
            p->cg_len = len;
            p->cg_len_slot = e->list[i]->sym->cg_len_slot;   /* resizable: its length */
        }
        p->slot = args[i];
    }
    int size = sl_ty_slots(f->ret);
    bool str = f->ret == SL_TYPE_STRING;
    int ret = size == 0 ? -1 : str ? cg_alloc_string(g) : cg_alloc_slots(g, size);
    int flag = -1;
    if (f->needs_ret_flag) {
        flag = cg_alloc_slots(g, 1);
        cg_emit(g, SL_OP_MOV, flag, cg_const_slot(g, 0), 0, 0);
    }
    int saved_slot = f->cg_ret_slot, saved_flag = f->cg_ret_flag, saved_id = f->cg_id;
    sl_func *saved_func = g->func;
    int saved_sp = g->sp, saved_ssp = g->ssp;
    f->cg_ret_slot = ret;
    f->cg_ret_flag = flag;
    f->cg_id = ++g->next_id;
    g->func = f;
    g->inline_depth++;
    if (flag >= 0 && ret >= 0 && !str)
        g->rets[g->nrets++] = (inline_ret){ ret, size, flag };
    if (flag >= 0) {                 /* early returns: the body is one region */
        set_death(g, flag, true);
        region_begin(g);
    }
    gen_stmt(g, f->body);
    if (flag >= 0) {
        int table = region_end(g);
        cg_emit(g, SL_OP_ACCUM_END, f->cg_id, table, 0, SL_ESCAPE_FUNC);
        patch_escapes(g, SL_ESCAPE_FUNC, f->cg_id, table);
        set_death(g, flag, false);
    }
    if (flag >= 0 && ret >= 0 && !str)
        g->nrets--;
    g->inline_depth--;
    g->func = saved_func;
    f->cg_ret_slot = saved_slot;
    f->cg_ret_flag = saved_flag;
    f->cg_id = saved_id;
    g->sp = saved_sp;
    g->ssp = saved_ssp;
    if (size == 0)
        return 0;
    return str ? cg_into_string(g, ret, dst) : cg_into(g, ret, dst, size);
}

/* One more level of nesting (SL_CG_MAX_DEPTH); false, reported, past it. */
static bool cg_enter(cg *g)
{
    if (g->depth >= SL_CG_MAX_DEPTH) {
        cg_fail(g, "expressions and statements nested too deeply once function calls are "
                "inlined (more than %d levels): call the functions here less deeply, or "
                "split their nested code into statements", SL_CG_MAX_DEPTH);
        return false;
    }
    g->depth++;
    return true;
}

int cg_gen_expr(cg *g, sl_node *e, int dst)
{
    if (g->failed)
        return dst >= 0 ? dst : SL_GLOBAL_SLOTS;
    sl_pos saved = g->cur;
    g->cur = e->pos;
    if (!cg_enter(g))
        return dst >= 0 ? dst : SL_GLOBAL_SLOTS;
    int r = 0;
    switch (e->kind) {
    case SL_N_NUM: r = cg_into(g, cg_const_slot(g, e->num), dst, 1); break;
    case SL_N_STR: r = cg_into_string(g, cg_string_const(g, e->name, e->len), dst); break;
    case SL_N_IDENT: r = gen_ident(g, e, dst); break;
    case SL_N_CALL:
        if (e->func)
            r = gen_user_call(g, e, dst);
        else if (e->builtin && e->builtin->lower == SL_LOWER_SPLINE)
            r = cg_gen_spline(g, e, dst);
        else if (e->builtin && e->builtin->lower == SL_LOWER_STRINGS)
            r = cg_gen_strings(g, e, dst);
        else if (e->builtin && e->builtin->lower == SL_LOWER_TEXTURE)
            r = cg_gen_texture(g, e, dst);
        else if (e->builtin)
            r = cg_gen_builtin(g, e, dst);
        else if (strcmp(e->name, "arraylength") != 0 || e->list[0]->sym->cg_len_slot)
            r = gen_resizable(g, e, dst);
        else            /* arraylength(a) of a fixed-size array */
            r = cg_into(g, cg_const_slot(g, cg_array_len(e->list[0]->sym)), dst, 1);
        break;
    case SL_N_INDEX: r = gen_index(g, e, dst); break;
    case SL_N_ARRAYINIT: r = gen_array_init(g, e, dst); break;
    case SL_N_UNARY: r = gen_unary(g, e, dst); break;
    case SL_N_BINARY: r = gen_binary(g, e, dst); break;
    case SL_N_COND: r = gen_cond_expr(g, e, dst); break;
    case SL_N_ASSIGN: r = gen_assign(g, e, dst); break;
    case SL_N_CAST: r = gen_cast(g, e, dst); break;
    case SL_N_CONV: r = gen_conv(g, e, dst); break;
    default: cg_fail(g, "internal error: unexpected expression"); break;
    }
    g->depth--;
    g->cur = saved;
    return r;
}

/* ---------------------------------------------------------------------- */
/* statements                                                              */
/* ---------------------------------------------------------------------- */

/* The flag slots of the escapes of n (loop's own continue excluded). */
static int escape_flags(cg *g, const sl_node *n, const sl_node *loop, int *flags)
{
    int count = 0;
    for (int i = 0; i < n->nescapes; i++) {
        const sl_escape *e = &n->escapes[i];
        int f = -1;
        if (e->kind == SL_ESC_BREAK)
            f = e->loop->cg_brk;
        else if (e->kind == SL_ESC_CONTINUE)
            f = e->loop == loop ? -1 : e->loop->cg_cnt;
        else
            f = e->func ? e->func->cg_ret_flag : g->shader_ret_flag;
        bool dup = false;
        for (int j = 0; j < count; j++)
            dup |= flags[j] == f;
        if (f >= 0 && !dup && count < 64)
            flags[count++] = f;
    }
    return count;
}

/* Statements list[from..n), the rest guarded after one that may escape:
 * each guard is a branch opened after that statement and closed after the
 * last one, innermost first. A loop over the guards, not a recursion: a
 * block may hold thousands of statements that escape. */
static void gen_list(cg *g, sl_node **list, int from, int n)
{
    branch *guards = NULL;
    int nguards = 0, cap = 0;
    for (int i = from; i < n && !g->failed; i++) {
        gen_stmt(g, list[i]);
        if (list[i]->nescapes == 0 || i == n - 1)
            continue;
        int flags[64];
        int count = escape_flags(g, list[i], NULL, flags);
        if (count == 0)
            continue;
        int mark = g->sp;
        g->cur = list[i + 1]->pos;
        int go = none_set(g, flags, count);
        g->sp = mark;
        if (nguards == cap) {
            cap = cap ? 2 * cap : 8;
            guards = xreallocarray(guards, (size_t)cap, sizeof *guards);
        }
        guards[nguards++] = branch_begin(g, go);
    }
    while (nguards > 0) {
        branch *b = &guards[--nguards];
        branch_else(g, b);
        branch_end(g, b);
    }
    free(guards);
}

static void gen_decl(cg *g, sl_node *n)
{
    for (int i = 0; i < n->nlist && !g->failed; i++) {
        sl_node *v = n->list[i];
        sl_sym *s = v->sym;
        if (!s)
            continue;       /* extern */
        g->cur = v->pos;
        if (s->ty == SL_TYPE_STRING) {
            s->slot = cg_alloc_string(g);
            int mark = g->sp;
            cg_into_string(g, v->a ? cg_gen_expr(g, v->a, -1) : cg_string_const(g, "", 0), s->slot);
            g->sp = mark;
            continue;
        }
        int size = sl_ty_slots(s->ty);
        s->slot = cg_alloc_slots(g, size);
        if (v->a) {
            cg_gen_expr(g, v->a, s->slot);
        } else {
            for (int k = 0; k < size; k++)
                cg_emit(g, SL_OP_MOV, s->slot + k, cg_const_slot(g, 0), 0, 0);
        }
        g->sp = s->slot + size;
        if (s->resizable) {       /* its length, after the elements */
            s->cg_len_slot = cg_alloc_slots(g, 1);
            cg_emit(g, SL_OP_MOV, s->cg_len_slot, cg_const_slot(g, 0), 0, 0);
        }
    }
}

typedef struct stmt_job {
    sl_node *stmt;
} stmt_job;

static void gen_stmt_job(cg *g, void *arg)
{
    stmt_job *job = arg;
    if (job->stmt) {
        int sp = g->sp, ssp = g->ssp;
        gen_stmt(g, job->stmt);
        g->sp = sp;
        g->ssp = ssp;
    }
}

static void gen_if(cg *g, sl_node *n)
{
    int mark = g->sp;
    int c = cg_gen_expr(g, n->a, -1);
    g->sp = mark;
    stmt_job a = { n->b }, b = { n->c };
    cg_gen_branches(g, c, gen_stmt_job, &a, n->c ? gen_stmt_job : NULL, &b);
}

static bool has_escape(const sl_node *body, sl_escape_kind kind, const sl_node *loop)
{
    for (int i = 0; i < body->nescapes; i++)
        if (body->escapes[i].kind == kind && body->escapes[i].loop == loop)
            return true;
    return false;
}

static int new_flag(cg *g)
{
    int f = cg_alloc_slots(g, 1);
    cg_emit(g, SL_OP_MOV, f, cg_const_slot(g, 0), 0, 0);
    return f;
}

/* while (cond) body, or for (; cond; step) body: loop is the node. */
static void gen_loop(cg *g, sl_node *loop, sl_node *cond, sl_node *step, sl_node *body)
{
    int saved_sp = g->sp;
    loop->cg_brk = has_escape(body, SL_ESC_BREAK, loop) ? new_flag(g) : -1;
    set_death(g, loop->cg_brk, true);
    loop->cg_cnt = has_escape(body, SL_ESC_CONTINUE, loop) ? cg_alloc_slots(g, 1) : -1;
    int flags[64];
    int nflags = escape_flags(g, body, loop, flags);
    int mark = g->sp;
    region_begin(g);
    int top = here(g);
    g->cur = loop->pos;
    int c = cond ? cg_gen_expr(g, cond, -1) : cg_const_slot(g, 1);
    int go = none_set(g, flags, nflags);
    if (go >= 0)
        c = cg_op2(g, SL_OP_AND, c, go);
    g->cur = loop->pos;
    int test = cg_emit(g, SL_OP_LOOP_TEST, c, 0, 0, 0);
    loop->cg_test = test;
    g->sp = mark;
    if (loop->cg_cnt >= 0)
        cg_emit(g, SL_OP_MOV, loop->cg_cnt, cg_const_slot(g, 0), 0, 0);
    stmt_job job = { body };
    gen_stmt_job(g, &job);
    if (step) {
        if (nflags > 0) {
            int go2 = none_set(g, flags, nflags);
            g->sp = mark;
            stmt_job sj = { step };
            cg_gen_branches(g, go2, gen_stmt_job, &sj, NULL, NULL);
        } else {
            gen_stmt_job(g, &(stmt_job){ step });
        }
    }
    g->cur = loop->pos;
    cg_emit(g, SL_OP_JMP, top, 0, 0, 0);
    int end = cg_emit(g, SL_OP_LOOP_END, test, 0, 0, 0);
    int table = region_end(g);
    if (!g->failed) {
        g->prog->code[test].b = (uint16_t)end;
        g->prog->code[test].c = (uint16_t)table;
        g->prog->code[end].b = (uint16_t)table;
    }
    patch_escapes(g, SL_ESCAPE_LOOP, test, table);
    set_death(g, loop->cg_brk, false);
    g->sp = saved_sp;
}

static void gen_return(cg *g, sl_node *n)
{
    sl_func *f = n->func;
    if (f) {
        if (n->a) {
            if (f->ret == SL_TYPE_STRING)
                cg_into_string(g, cg_gen_expr(g, n->a, -1), f->cg_ret_slot);
            else
                cg_gen_expr(g, n->a, f->cg_ret_slot);
        }
        if (f->cg_ret_flag >= 0 && !n->tail)
            emit_escape(g, f->cg_ret_flag, SL_ESCAPE_FUNC, f->cg_id);
    } else if (g->shader_ret_flag >= 0 && !n->tail) {
        emit_escape(g, g->shader_ret_flag, SL_ESCAPE_FUNC, 0);
    }
}

static void gen_stmt(cg *g, sl_node *n)
{
    if (!n || g->failed)
        return;
    g->cur = n->pos;
    if (!cg_enter(g))
        return;
    int mark = g->sp;
    switch (n->kind) {
    case SL_N_BLOCK: {
        int ssp = g->ssp;
        gen_list(g, n->list, 0, n->nlist);
        g->ssp = ssp;
        break;
    }
    case SL_N_DECL: gen_decl(g, n); g->depth--; return;
    case SL_N_EXPR: cg_gen_expr(g, n->a, -1); break;
    case SL_N_IF: gen_if(g, n); break;
    case SL_N_WHILE: gen_loop(g, n, n->a, NULL, n->b); break;
    case SL_N_FOR: {
        int ssp = g->ssp;
        gen_stmt(g, n->a);
        gen_loop(g, n, n->b, n->c, n->d);
        g->ssp = ssp;
        break;
    }
    case SL_N_BREAK:
        emit_escape(g, n->target->cg_brk, SL_ESCAPE_LOOP, n->target->cg_test);
        break;
    case SL_N_CONTINUE:
        cg_emit(g, SL_OP_MOV, n->target->cg_cnt, cg_const_slot(g, 1), 0, 0);
        break;
    case SL_N_RETURN: gen_return(g, n); break;
    default: break;
    }
    g->depth--;
    g->sp = mark;
}

/* ---------------------------------------------------------------------- */
/* the shader                                                              */
/* ---------------------------------------------------------------------- */

static void gen_params(cg *g)
{
    const sl_ast_file *f = g->file;
    sl_program *p = g->prog;
    p->params = xmalloc((size_t)(f->nparams + 1) * sizeof *p->params);
    p->nparams = f->nparams;
    for (int i = 0; i < f->nparams; i++) {
        sl_node *v = f->params[i];
        sl_sym *s = v->sym;
        sl_param *pp = &p->params[i];
        pp->name = xstrndup(s->name, strlen(s->name));
        pp->type = (sl_type)sl_ty_elem(s->ty);     /* arrays: the element type */
        pp->output = s->output;
        pp->size = sl_ty_slots(s->ty);
        g->cur = v->pos;
        bool str = s->ty == SL_TYPE_STRING;
        s->slot = str ? cg_alloc_string(g) : cg_alloc_slots(g, pp->size);
        pp->slot = s->slot;
        /* a constant default (a number or a string) travels in operand d:
         * one instruction per parameter */
        int k = -1;
        if (!v->a)
            k = str ? cg_string_const(g, "", 0) : pp->size == 1 ? cg_const_slot(g, 0) : -1;
        else if (v->a->kind == SL_N_NUM)
            k = cg_const_slot(g, v->a->num);
        else if (v->a->kind == SL_N_STR)
            k = cg_string_const(g, v->a->name, v->a->len);
        int at = cg_emit(g, str ? SL_OP_SPARAM : SL_OP_PARAM, s->slot, i, 0, k < 0 ? 0 : k);
        int mark = g->sp;
        if (k >= 0)
            ;
        else if (v->a)
            cg_gen_expr(g, v->a, s->slot);
        else
            for (int c = 0; c < pp->size; c++)
                cg_emit(g, SL_OP_MOV, s->slot + c, cg_const_slot(g, 0), 0, 0);
        g->sp = mark;
        if (!g->failed)
            p->code[at].c = (uint16_t)here(g);
    }
}

static const char *const operand_kinds[SL_OP__COUNT] = {
#define SL_OPCODE_OPERANDS(name, text, operands) operands,
    SL_OPCODES(SL_OPCODE_OPERANDS)
#undef SL_OPCODE_OPERANDS
};

/* Constants and string constants go after the highest slot used. */
static void fix_constants(cg *g)
{
    sl_program *p = g->prog;
    p->const_base = g->max_sp;
    p->nslots = g->max_sp + p->nconsts;
    p->nstring_slots = g->max_ssp + p->nstrings;
    for (int i = 0; i < p->nstrings; i++)
        p->string_slots[i] = g->max_ssp + i;
    for (int pc = 0; pc < p->ncode; pc++) {
        sl_insn *in = &p->code[pc];
        uint16_t *ops[4] = { &in->a, &in->b, &in->c, &in->d };
        const char *kinds = operand_kinds[in->op];
        for (int k = 0; k < 4; k++) {
            if (!(*ops[k] & CONST_TAG))
                continue;
            if (kinds[k] == 'x')
                *ops[k] = (uint16_t)(p->const_base + (*ops[k] & ~CONST_TAG));
            else if (kinds[k] == 's')
                *ops[k] = (uint16_t)(g->max_ssp + (*ops[k] & ~CONST_TAG));
        }
    }
    if (p->nslots > SL_MAX_SLOTS)
        cg_fail(g, "shader needs more than %d registers (the limit per shader)", SL_MAX_SLOTS);
}

static unsigned long next_serial(void)
{
    static atomic_ulong serial;
    return atomic_fetch_add(&serial, 1) + 1;
}

sl_program *sl_codegen(const sl_ast_file *file, sl_diag *diag)
{
    cg g = { .file = file, .diag = diag };
    g.prog = xmalloc(sizeof *g.prog);
    memset(g.prog, 0, sizeof *g.prog);
    sl_program *p = g.prog;
    p->name = xstrndup(file->name, strlen(file->name));
    p->kind = file->kind;
    p->serial = next_serial();
    g.sp = g.max_sp = SL_GLOBAL_SLOTS;
    g.shader_ret_flag = -1;
    g.cur = file->pos;
    gen_params(&g);
    if (file->needs_ret_flag) {
        g.shader_ret_flag = new_flag(&g);
        set_death(&g, g.shader_ret_flag, true);
        region_begin(&g);
    }
    gen_stmt(&g, file->body);
    if (file->needs_ret_flag) {
        int table = region_end(&g);
        g.cur = file->pos;
        cg_emit(&g, SL_OP_ACCUM_END, 0, table, 0, SL_ESCAPE_FUNC);
        patch_escapes(&g, SL_ESCAPE_FUNC, 0, table);
    }
    g.cur = file->pos;
    cg_emit(&g, SL_OP_END, 0, 0, 0, 0);
    fix_constants(&g);
    free(g.regions);
    free(g.escapes);
    if (g.failed) {
        sl_program_destroy(&p);
        return NULL;
    }
    /* every region closed, every inlined call returned */
    assert(g.nregions == 0 && g.nrets == 0 && g.inline_depth == 0);
    sl_program_assert_valid(p);
    return p;
}

/*
 * codegen.c: from the checked tree to bytecode (see codegen.h).
 *
 * Slots. Variables and temporaries are allocated from a stack pointer
 * (sp): a statement frees its temporaries, a block its variables. The
 * constant pool is placed after the highest slot used, so constant
 * operands are emitted with CONST_TAG and fixed up at the end; string
 * constants likewise in the string file.
 *
 * Expressions. gen_expr(e, dst) returns the slot holding e's value; with
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
 */
#include "sl/codegen.h"
#include "sl/builtins.h"
#include "sl/check.h"
#include "sl/lexer.h"
#include "sl/strbuf.h"
#include "tex/tex.h"

#include <math.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

enum { CONST_TAG = 0x8000 };

typedef struct region {
    int start_sp, start_ssp;
    uint8_t bits[SL_MAX_SLOTS / 8];
    uint8_t sbits[SL_MAX_STRING_SLOTS / 8];
} region;

/* The return slot of a function being inlined, dead while its "returned"
 * flag is 0 (every path that has not returned yet will still write it). */
typedef struct inline_ret {
    int slot, size, flag;
} inline_ret;

typedef struct cg {
    const sl_ast_file *file;
    sl_diag *diag;
    sl_program *prog;
    int code_cap, consts_cap, tables_cap, strings_cap, files_cap;
    int sp, max_sp, ssp, max_ssp;
    region *regions;
    int nregions, regions_cap;
    sl_pos cur;
    int inline_depth;
    inline_ret rets[SL_MAX_INLINE_DEPTH + 1];
    int nrets;
    sl_func *func;
    int shader_ret_flag;
    bool solar;                          /* the last illuminate/solar was a solar */
    uint8_t death[SL_MAX_SLOTS / 8];     /* escape flags: their paths are saved */
    struct pending_escape { int pc, kind, id; } *escapes;
    int nescapes, escapes_cap, next_id;
    bool failed;
} cg;

static int gen_expr(cg *g, sl_node *e, int dst);
static void gen_stmt(cg *g, sl_node *n);
static int gen_color_space(cg *g, int space, int x, bool from);

static void fail(cg *g, const char *fmt, ...) SL_PRINTF(2, 3);
static void fail(cg *g, const char *fmt, ...)
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

static int alloc_slots(cg *g, int n)
{
    int slot = g->sp;
    if (g->sp + n > SL_MAX_SLOTS) {
        fail(g, "shader needs more than %d registers (the limit per shader)", SL_MAX_SLOTS);
        return SL_GLOBAL_SLOTS;
    }
    g->sp += n;
    if (g->sp > g->max_sp)
        g->max_sp = g->sp;
    return slot;
}

static int alloc_string(cg *g)
{
    if (g->ssp + 1 > SL_MAX_STRING_SLOTS / 2) {
        fail(g, "shader needs more than %d string registers", SL_MAX_STRING_SLOTS / 2);
        return 0;
    }
    int slot = g->ssp++;
    if (g->ssp > g->max_ssp)
        g->max_ssp = g->ssp;
    return slot;
}

static int const_slot(cg *g, double value)
{
    sl_program *p = g->prog;
    for (int i = 0; i < p->nconsts; i++)
        if (memcmp(&p->consts[i], &value, sizeof value) == 0)
            return CONST_TAG | i;
    if (p->nconsts >= SL_MAX_SLOTS / 2) {
        fail(g, "shader has more than %d constants", SL_MAX_SLOTS / 2);
        return CONST_TAG;
    }
    if (p->nconsts == g->consts_cap) {
        g->consts_cap = g->consts_cap ? 2 * g->consts_cap : 16;
        p->consts = sl_xrealloc(p->consts, (size_t)g->consts_cap * sizeof *p->consts);
    }
    p->consts[p->nconsts] = value;
    return CONST_TAG | p->nconsts++;
}

static int string_const(cg *g, const char *text, size_t len)
{
    sl_program *p = g->prog;
    for (int i = 0; i < p->nstrings; i++)
        if (strlen(p->strings[i]) == len && memcmp(p->strings[i], text, len) == 0)
            return CONST_TAG | i;
    if (p->nstrings >= SL_MAX_STRING_SLOTS / 2) {
        fail(g, "shader has more than %d string constants", SL_MAX_STRING_SLOTS / 2);
        return CONST_TAG;
    }
    if (p->nstrings == g->strings_cap) {
        g->strings_cap = g->strings_cap ? 2 * g->strings_cap : 8;
        p->strings = sl_xrealloc(p->strings, (size_t)g->strings_cap * sizeof *p->strings);
        p->string_slots = sl_xrealloc(p->string_slots,
                                      (size_t)g->strings_cap * sizeof *p->string_slots);
    }
    p->strings[p->nstrings] = sl_xstrndup(text, len);
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
        p->files = sl_xrealloc(p->files, (size_t)g->files_cap * sizeof *p->files);
    }
    p->files[p->nfiles] = sl_xstrndup(file, strlen(file));
    return p->nfiles++;
}

/* ---------------------------------------------------------------------- */
/* merge regions                                                           */
/* ---------------------------------------------------------------------- */

static void region_begin(cg *g)
{
    if (g->nregions == g->regions_cap) {
        g->regions_cap = g->regions_cap ? 2 * g->regions_cap : 8;
        g->regions = sl_xrealloc(g->regions, (size_t)g->regions_cap * sizeof *g->regions);
    }
    region *r = &g->regions[g->nregions++];
    memset(r, 0, sizeof *r);
    r->start_sp = g->sp;
    r->start_ssp = g->ssp;
}

static void record_write(cg *g, int slot, int n)
{
    if (g->nregions == 0)
        return;
    region *r = &g->regions[g->nregions - 1];
    for (int s = slot; s < slot + n && s < r->start_sp; s++)
        r->bits[s / 8] |= (uint8_t)(1u << (s % 8));
}

static void record_string_write(cg *g, int slot)
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
        p->tables = sl_xrealloc(p->tables, (size_t)g->tables_cap * sizeof *p->tables);
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
    region *r = &g->regions[g->nregions - 1];
    int count = 0;
    for (int s = 0; s < r->start_sp; s++)
        if ((r->bits[s / 8] >> (s % 8)) & 1)
            count += ret_guard(g, s) >= 0 ? 2 : 1;
    for (int s = 0; s < r->start_ssp; s++)
        count += (r->sbits[s / 8] >> (s % 8)) & 1;
    if (g->prog->ntables + count + 1 > 0xffff) {
        fail(g, "shader too large: merge tables exceed %d entries", 0xffff);
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

static int emit(cg *g, sl_opcode op, int a, int b, int c, int d)
{
    sl_program *p = g->prog;
    if (g->failed)
        return 0;
    if (p->ncode >= SL_MAX_CODE - 1) {
        fail(g, "shader too large: more than %d instructions (after inlining functions)",
             SL_MAX_CODE - 1);
        return 0;
    }
    if (p->ncode == g->code_cap) {
        g->code_cap = g->code_cap ? 2 * g->code_cap : 256;
        p->code = sl_xrealloc(p->code, (size_t)g->code_cap * sizeof *p->code);
        p->pos = sl_xrealloc(p->pos, (size_t)g->code_cap * sizeof *p->pos);
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
        record_write(g, a, w);
    if (op == SL_OP_SMOV || op == SL_OP_SPARAM)
        record_string_write(g, a);
    return p->ncode++;
}

static int here(const cg *g) { return g->prog->ncode; }

/* ESCAPE flag: its table is patched when the construct it leaves closes. */
static void emit_escape(cg *g, int flag, int kind, int id)
{
    int pc = emit(g, SL_OP_ESCAPE, flag, id, 0, kind);
    if (g->failed)
        return;
    if (g->nescapes == g->escapes_cap) {
        g->escapes_cap = g->escapes_cap ? 2 * g->escapes_cap : 16;
        g->escapes = sl_xrealloc(g->escapes, (size_t)g->escapes_cap * sizeof *g->escapes);
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

static void emit_mov(cg *g, int dst, int src, int n)
{
    if (dst == src || n == 0)
        return;
    if (n == 1)
        emit(g, SL_OP_MOV, dst, src, 0, 0);
    else
        emit(g, SL_OP_MOVN, dst, src, n, 0);
}

/* The value at src (size n) in dst when dst >= 0. */
static int into(cg *g, int src, int dst, int n)
{
    if (dst < 0 || dst == src)
        return src;
    emit_mov(g, dst, src, n);
    return dst;
}

static int into_string(cg *g, int src, int dst)
{
    if (dst < 0 || dst == src)
        return src;
    emit(g, SL_OP_SMOV, dst, src, 0, 0);
    return dst;
}

static int target(cg *g, int dst, int n) { return dst >= 0 ? dst : alloc_slots(g, n); }

/* Lane i of a value of n slots (a float broadcasts). */
static int lane(int slot, int n, int i) { return n == 1 ? slot : slot + i; }

static int size_of(const sl_node *e) { return sl_ty_slots(e->ty); }

/* dst, or -1 when writing lane by lane into dst could overwrite a lane of
 * an operand before it is read (v = v.x * v: the broadcast v.x is lane 0
 * of the destination). */
static int lane_safe(int dst, int n, const int *args, const int *sizes, int k)
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

static int op1(cg *g, sl_opcode op, int x)
{
    int z = alloc_slots(g, 1);
    emit(g, op, z, x, 0, 0);
    return z;
}

static int op2(cg *g, sl_opcode op, int x, int y)
{
    int z = alloc_slots(g, 1);
    emit(g, op, z, x, y, 0);
    return z;
}

/* x . y over n lanes into z (or a new slot). */
static int gen_dot(cg *g, int x, int y, int n, int dst)
{
    int z = target(g, dst, 1);
    emit(g, SL_OP_MUL, z, x, y, 0);
    for (int i = 1; i < n; i++) {
        int t = op2(g, SL_OP_MUL, x + i, y + i);
        emit(g, SL_OP_ADD, z, z, t, 0);
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
        any = op2(g, SL_OP_OR, any, flags[i]);
    return op1(g, SL_OP_NOT, any);
}

/* ---------------------------------------------------------------------- */
/* expressions                                                             */
/* ---------------------------------------------------------------------- */

static int gen_ident(cg *g, sl_node *e, int dst)
{
    sl_sym *s = e->sym;
    if (s->kind == SL_SYM_CONST)
        return into(g, const_slot(g, s->value), dst, 1);
    if (s->ty == SL_TYPE_STRING)
        return into_string(g, s->slot, dst);
    return into(g, s->slot, dst, size_of(e));
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
static int gen_matmul(cg *g, int a, int b, int dst)
{
    int z = alloc_slots(g, 16);
    for (int r = 0; r < 4; r++) {
        for (int c = 0; c < 4; c++) {
            int acc = z + r * 4 + c;
            emit(g, SL_OP_MUL, acc, a + r * 4, b + c, 0);
            for (int k = 1; k < 4; k++) {
                int t = op2(g, SL_OP_MUL, a + r * 4 + k, b + k * 4 + c);
                emit(g, SL_OP_ADD, acc, acc, t, 0);
            }
        }
    }
    return into(g, z, dst, 16);
}

static int gen_cross(cg *g, int a, int b, int dst)
{
    int z = alloc_slots(g, 3);
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        int t = op2(g, SL_OP_MUL, a + j, b + k);
        int u = op2(g, SL_OP_MUL, a + k, b + j);
        emit(g, SL_OP_SUB, z + i, t, u, 0);
    }
    return into(g, z, dst, 3);
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
    return const_slot(g, r);
}

static int gen_binary(cg *g, sl_node *e, int dst)
{
    int na = size_of(e->a), nb = size_of(e->b);
    if (e->a->ty == SL_TYPE_STRING) {
        int x = gen_expr(g, e->a, -1), y = gen_expr(g, e->b, -1);
        int z = target(g, dst, 1);
        emit(g, e->op == SL_TOK_EQ ? SL_OP_SEQ : SL_OP_SNE, z, x, y, 0);
        return z;
    }
    int x = gen_expr(g, e->a, -1);
    int y = gen_expr(g, e->b, -1);
    int folded = fold(g, e->op, x, y);
    if (folded >= 0)
        return into(g, folded, dst, 1);
    switch (e->op) {
    case SL_TOK_DOT: return gen_dot(g, x, y, 3, dst);
    case SL_TOK_CARET: return gen_cross(g, x, y, dst);
    case SL_TOK_STAR:
        if (na == 16 && nb == 16)     /* RenderMan's a * b: a first, then b */
            return gen_matmul(g, y, x, dst);
        break;
    case SL_TOK_SLASH:
        if (nb == 16) {               /* a / b = a * inverse(b) (RI Spec 3.2 §12) */
            int inv = alloc_slots(g, 16);
            emit(g, SL_OP_MINVERT, inv, y, 0, 0);
            if (na == 16)
                return gen_matmul(g, inv, x, dst);
            int z = target(g, dst, 16);
            for (int i = 0; i < 16; i++)
                emit(g, SL_OP_MUL, z + i, x, inv + i, 0);
            return z;
        }
        break;
    case SL_TOK_EQ: case SL_TOK_NE:
        if (na > 1) {          /* all lanes equal / some lane differs */
            int z = target(g, dst, 1);
            sl_opcode cmp = e->op == SL_TOK_EQ ? SL_OP_EQ : SL_OP_NE;
            sl_opcode join = e->op == SL_TOK_EQ ? SL_OP_AND : SL_OP_OR;
            int acc = op2(g, cmp, x, y);
            for (int i = 1; i < na; i++)
                acc = op2(g, join, acc, op2(g, cmp, x + i, y + i));
            emit_mov(g, z, acc, 1);
            return z;
        }
        break;
    default: break;
    }
    int n = size_of(e);
    if (e->ty == SL_TY_BOOL)
        n = 1;
    int ops[2] = { x, y }, sizes[2] = { na, nb };
    int z = target(g, lane_safe(dst, n, ops, sizes, 2), n);
    for (int i = 0; i < n; i++)
        emit(g, arith_op(e->op), z + i, lane(x, na, i), lane(y, nb, i), 0);
    return into(g, z, dst, n);
}

static int gen_unary(cg *g, sl_node *e, int dst)
{
    int x = gen_expr(g, e->a, -1);
    if (e->op == SL_TOK_MINUS && (x & CONST_TAG))
        return into(g, const_slot(g, -g->prog->consts[x & ~CONST_TAG]), dst, 1);
    int n = e->op == SL_TOK_NOT ? 1 : size_of(e);
    int z = target(g, dst, n);
    for (int i = 0; i < n; i++)
        emit(g, e->op == SL_TOK_NOT ? SL_OP_NOT : SL_OP_NEG, z + i, x + i, 0, 0);
    return z;
}

/* BR_BEGIN cond ... BR_ELSE ... BR_END around two generators. */
typedef void (*branch_fn)(cg *g, void *arg);

static void gen_branches(cg *g, int cond, branch_fn then_fn, void *then_arg,
                         branch_fn else_fn, void *else_arg)
{
    sl_pos at = g->cur;              /* the if: where merge errors point */
    int begin = emit(g, SL_OP_BR_BEGIN, cond, 0, 0, 0);
    region_begin(g);
    then_fn(g, then_arg);
    g->cur = at;
    int mid = emit(g, SL_OP_BR_ELSE, 0, begin, 0, 0);
    if (else_fn)
        else_fn(g, else_arg);
    g->cur = at;
    int end = emit(g, SL_OP_BR_END, begin, 0, 0, 0);
    int table = region_end(g);
    if (g->failed)
        return;
    sl_insn *code = g->prog->code;
    code[begin].b = (uint16_t)(mid + 1);
    code[begin].c = (uint16_t)table;
    code[mid].a = (uint16_t)end;
    code[end].b = (uint16_t)table;
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
        into_string(g, gen_expr(g, job->e, -1), job->dst);
    else
        gen_expr(g, job->e, job->dst);
    g->sp = saved;
}

static int gen_cond_expr(cg *g, sl_node *e, int dst)
{
    bool str = e->ty == SL_TYPE_STRING;
    int z = dst >= 0 ? dst : str ? alloc_string(g) : alloc_slots(g, size_of(e));
    int mark = g->sp;
    int c = gen_expr(g, e->a, -1);
    g->sp = mark;
    value_job a = { e->b, z }, b = { e->c, z };
    gen_branches(g, c, gen_value_job, &a, gen_value_job, &b);
    return z;
}

/* ---------------------------------------------------------------------- */
/* arrays                                                                  */
/* ---------------------------------------------------------------------- */

/* The length of array variable s here (an unsized parameter: its argument's). */
static int array_len(const sl_sym *s)
{
    int len = sl_ty_len(s->ty);
    return len ? len : s->cg_len;
}

static int array_operand(int len, int stride)
{
    int code = stride == 1 ? 0 : stride == 3 ? 1 : 2;
    return len | code << SL_ARRAY_STRIDE_SHIFT;
}

/* The element a constant index names, or -1 (reported) out of range. */
static int const_element(cg *g, const sl_node *x, int index, int len)
{
    double k = floor(g->prog->consts[index & ~CONST_TAG]);
    if (!(k >= 0 && k < len)) {
        fail(g, "array index %g is out of range for '%s' (0 to %d)", k, x->a->name, len - 1);
        return -1;
    }
    return (int)k;
}

/* a[i] (x) into dst: a constant index addresses the element's slots, a
 * varying one loads lane by lane (paper §4: in range modes the merge of
 * every element the index can reach). */
static int gen_index(cg *g, sl_node *x, int dst)
{
    const sl_sym *s = x->a->sym;
    int len = array_len(s), n = size_of(x);
    int i = gen_expr(g, x->b, -1);
    if (i & CONST_TAG) {
        int k = const_element(g, x, i, len);
        return k < 0 ? 0 : into(g, s->slot + k * n, dst, n);
    }
    /* lanes write z in turn: z must not hold the index */
    int z = dst >= 0 && !(i >= dst && i < dst + n) ? dst : alloc_slots(g, n);
    for (int k = 0; k < n; k++)
        emit(g, SL_OP_ALOAD, z + k, s->slot + k, i, array_operand(len, n));
    return into(g, z, dst, n);
}

/* a[i] = v: v's slots (size n) stored; every element may change. */
static int gen_store(cg *g, sl_node *x, sl_node *value, int dst)
{
    const sl_sym *s = x->a->sym;
    int len = array_len(s), n = size_of(x);
    int i = gen_expr(g, x->b, -1);
    int v = gen_expr(g, value, -1);
    if (i & CONST_TAG) {
        int k = const_element(g, x, i, len);
        if (k < 0)
            return 0;
        emit_mov(g, s->slot + k * n, v, n);
        return into(g, s->slot + k * n, dst, n);
    }
    for (int k = 0; k < n; k++)
        emit(g, SL_OP_ASTORE, s->slot + k, i, v + k, array_operand(len, n));
    record_write(g, s->slot, len * n);
    return into(g, v, dst, n);
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
        fail(g, "%s() on '%s': the array passed for it is not resizable (declare it without "
             "size or initializer, as 'float a[];')", e->name, s->name);
        return 0;
    }
    int len = array_len(s), n = sl_ty_slots(sl_ty_elem(s->ty));
    if (strcmp(e->name, "arraylength") == 0)
        return into(g, L, dst, 1);
    switch (e->op) {
    case SL_RESIZE_RESIZE: case SL_RESIZE_RESERVE: {
        int k = op1(g, SL_OP_FLOOR, gen_expr(g, e->list[1], -1));
        int probe = op2(g, SL_OP_MAX, op2(g, SL_OP_SUB, k, const_slot(g, 1)), const_slot(g, 0));
        emit(g, SL_OP_ALOAD, alloc_slots(g, 1), s->slot, probe, array_operand(len, n));
        if (e->op == SL_RESIZE_RESIZE)
            emit(g, SL_OP_MAX, L, k, const_slot(g, 0), 0);
        return 0;
    }
    case SL_RESIZE_PUSH: {
        int v = gen_expr(g, e->list[1], -1);
        for (int k = 0; k < n; k++)
            emit(g, SL_OP_ASTORE, s->slot + k, L, v + k, array_operand(len, n));
        record_write(g, s->slot, len * n);
        emit(g, SL_OP_ADD, L, L, const_slot(g, 1), 0);
        return 0;
    }
    default: {               /* pop */
        emit(g, SL_OP_SUB, L, L, const_slot(g, 1), 0);
        int z = alloc_slots(g, n);
        for (int k = 0; k < n; k++)
            emit(g, SL_OP_ALOAD, z + k, s->slot + k, L, array_operand(len, n));
        return into(g, z, dst, n);
    }
    }
}

/* { values } into the array at dst. */
static int gen_array_init(cg *g, sl_node *e, int dst)
{
    int n = sl_ty_slots(sl_ty_elem(e->ty));
    for (int i = 0; i < e->nlist; i++) {
        int mark = g->sp;
        gen_expr(g, e->list[i], dst + i * n);
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
        int v = gen_expr(g, e->b, -1);
        into_string(g, v, s->slot);
        return into_string(g, s->slot, dst);
    }
    gen_expr(g, e->b, s->slot);
    return into(g, s->slot, dst, sl_ty_slots(s->ty));
}

/* The matrix of a named space (constant or string slot), into 16 slots. */
static int gen_space_matrix(cg *g, sl_node *space, int dir)
{
    int m = alloc_slots(g, 16);
    if (space->kind == SL_N_STR) {
        emit(g, SL_OP_SPACEK, m, sl_space_find(space->name), dir, 0);
    } else {
        int s = gen_expr(g, space, -1);
        emit(g, SL_OP_SPACE, m, s, dir, 0);
    }
    return m;
}

static bool is_current(const sl_node *space)
{
    return space->kind == SL_N_STR && strcmp(space->name, "current") == 0;
}

/* Applies the named-space transform to x (3 slots): op XPOINT/XVECTOR use
 * the matrix itself, XNORMAL the inverse (it applies the transpose). */
static int gen_space_xform(cg *g, sl_opcode op, sl_node *space, int dir, int x, int dst)
{
    if (is_current(space))
        return into(g, x, dst, 3);
    int use = op == SL_OP_XNORMAL ? 1 - dir : dir;
    int m = gen_space_matrix(g, space, use);
    int z = target(g, dst, 3);       /* the transform reads x before it writes z */
    emit(g, op, z, m, x, 0);
    return z;
}

static int gen_cast(cg *g, sl_node *e, int dst)
{
    int n = size_of(e);
    int v;
    if (e->nlist == 1) {
        v = gen_expr(g, e->list[0], e->name ? -1 : dst);
    } else {
        /* a component may read the destination: build in fresh slots. A
         * matrix is written in RenderMan's order (row vectors, the
         * translation in elements 12..14) and kept transposed, as vecmath
         * does: element k goes to row k % 4, column k / 4. */
        v = alloc_slots(g, n);
        for (int i = 0; i < e->nlist; i++)
            gen_expr(g, e->list[i], n == 16 ? v + (i % 4) * 4 + i / 4 : v + i);
    }
    if (e->name && e->ty == SL_TYPE_COLOR)      /* color "hsv" (h, s, v) */
        return into(g, gen_color_space(g, sl_color_space_find(e->name), v, true), dst, 3);
    if (e->name && e->ty == SL_TYPE_MATRIX) {   /* given in that space: M * to_current */
        sl_node space = { .kind = SL_N_STR, .name = e->name, .pos = e->pos };
        if (is_current(&space))
            return into(g, v, dst, 16);
        int m = gen_space_matrix(g, &space, SL_SPACE_TO_CURRENT);
        return gen_matmul(g, m, v, dst);
    }
    if (e->name && sl_ty_is_spatial(e->ty)) {
        sl_opcode op = e->ty == SL_TYPE_POINT ? SL_OP_XPOINT
                     : e->ty == SL_TYPE_VECTOR ? SL_OP_XVECTOR : SL_OP_XNORMAL;
        sl_node space = { .kind = SL_N_STR, .name = e->name, .pos = e->pos };
        return gen_space_xform(g, op, &space, SL_SPACE_TO_CURRENT, v, dst);
    }
    return into(g, v, dst, n);
}

static int gen_conv(cg *g, sl_node *e, int dst)
{
    int x = gen_expr(g, e->a, -1);
    if (e->ty == SL_TY_BOOL) {
        int z = target(g, dst, 1);
        emit(g, SL_OP_NE, z, x, const_slot(g, 0), 0);
        return z;
    }
    int n = size_of(e);
    int z = target(g, dst, n);
    if (n == 16) {
        for (int i = 0; i < 16; i++)
            emit(g, SL_OP_MOV, z + i, i % 5 == 0 ? x : const_slot(g, 0), 0, 0);
        return z;
    }
    for (int i = 0; i < n; i++)
        emit(g, SL_OP_MOV, z + i, x, 0, 0);
    return z;
}

/* ---------------------------------------------------------------------- */
/* built-in calls                                                          */
/* ---------------------------------------------------------------------- */

static int op_inputs(sl_opcode op)
{
    switch (op) {
    case SL_OP_CLAMP: case SL_OP_SMOOTHSTEP: case SL_OP_MIX: return 3;
    case SL_OP_POW: case SL_OP_ATAN2: case SL_OP_MOD: case SL_OP_MIN: case SL_OP_MAX:
    case SL_OP_STEP: case SL_OP_DERIV:
        return 2;
    default: return 1;
    }
}

/* Componentwise op over the result's lanes. */
static int gen_lanes(cg *g, sl_opcode op, const int *args, const int *sizes, int n, int dst)
{
    int k = op_inputs(op);
    int z = target(g, lane_safe(dst, n, args, sizes, k), n);
    for (int i = 0; i < n; i++) {
        int in[3] = { 0, 0, 0 };
        for (int j = 0; j < k; j++)
            in[j] = lane(args[j], sizes[j], i);
        emit(g, op, z + i, in[0], in[1], in[2]);
    }
    return into(g, z, dst, n);
}

/* Copies n values into consecutive fresh slots unless they already are. */
static int consecutive(cg *g, const int *slots, const int *sizes, int n)
{
    int total = 0;
    for (int i = 0; i < n; i++)
        total += sizes[i];
    if (n == 1 && !(slots[0] & CONST_TAG))
        return slots[0];
    int base = alloc_slots(g, total), o = 0;
    for (int i = 0; i < n; i++) {
        emit_mov(g, base + o, slots[i], sizes[i]);
        o += sizes[i];
    }
    return base;
}

static int gen_noise(cg *g, sl_node *e, const int *args, const int *sizes, int dst)
{
    const sl_builtin *b = e->builtin;
    int kind = (int)b->k;
    int n = e->nlist;
    int inputs = kind == SL_NOISE_PERIODIC ? n / 2 : n;
    int dim = 0;
    for (int i = 0; i < inputs; i++)
        dim += sizes[i];
    int in = consecutive(g, args, sizes, inputs);
    int period = 0;
    if (kind == SL_NOISE_PERIODIC)
        period = consecutive(g, args + inputs, sizes + inputs, inputs);
    int outs = size_of(e);
    int z = alloc_slots(g, outs);
    emit(g, SL_OP_NOISE, z, in, SL_NOISE_VARIANT(dim, kind, outs == 3), period);
    return into(g, z, dst, outs);
}

static int gen_transform(cg *g, sl_node *e, const int *args, int dst)
{
    sl_opcode op = e->builtin->op;
    int n = e->nlist;
    int x = args[n - 1];
    if (n == 2 && e->list[0]->ty == SL_TYPE_MATRIX) {
        int m = args[0];
        if (op == SL_OP_XNORMAL) {
            int inv = alloc_slots(g, 16);
            emit(g, SL_OP_MINVERT, inv, m, 0, 0);
            m = inv;
        }
        int z = alloc_slots(g, 3);
        emit(g, op, z, m, x, 0);
        return into(g, z, dst, 3);
    }
    if (n == 3)       /* from space a to "current", then to space b */
        x = gen_space_xform(g, op, e->list[0], SL_SPACE_TO_CURRENT, x, -1);
    return gen_space_xform(g, op, e->list[n - 2], SL_SPACE_FROM_CURRENT, x, dst);
}

/* v * inversesqrt(v . v), each component clamped to [-1, 1]: the identity
 * on a unit vector, and in interval/affine mode it keeps the result bounded
 * where |v| can vanish over a range (normalize(dPdu) at a pole, N of a
 * wide range): a unit vector's components never leave [-1, 1] (issue 9). */
static int gen_normalize(cg *g, int v, int dst)
{
    int d = gen_dot(g, v, v, 3, -1);
    int r = op1(g, SL_OP_INVSQRT, d);
    int z = target(g, dst, 3);
    int lo = const_slot(g, -1.0), hi = const_slot(g, 1.0);
    for (int i = 0; i < 3; i++) {
        emit(g, SL_OP_MUL, z + i, v + i, r, 0);
        emit(g, SL_OP_CLAMP, z + i, z + i, lo, hi);
    }
    return z;
}

/* faceforward(N, I [, Nref = Ng]) = (I . Nref < 0) ? N : -N */
typedef struct ff_job {
    int n, z;
    bool negate;
} ff_job;

static void gen_ff_job(cg *g, void *arg)
{
    ff_job *job = arg;
    for (int i = 0; i < 3; i++)
        emit(g, job->negate ? SL_OP_NEG : SL_OP_MOV, job->z + i, job->n + i, 0, 0);
}

static int gen_faceforward(cg *g, sl_node *e, const int *args, int dst)
{
    int nref = e->nlist == 3 ? args[2] : sl_global_slot(SL_G_Ng);
    int z = alloc_slots(g, 3);
    int mark = g->sp;
    int d = gen_dot(g, args[1], nref, 3, -1);
    int c = op2(g, SL_OP_LT, d, const_slot(g, 0));
    g->sp = mark;
    ff_job a = { args[0], z, false }, b = { args[0], z, true };
    gen_branches(g, c, gen_ff_job, &a, gen_ff_job, &b);
    return into(g, z, dst, 3);
}

static int gen_reflect(cg *g, const int *args, int dst)
{
    int d = gen_dot(g, args[0], args[1], 3, -1);
    int t = op2(g, SL_OP_MUL, d, const_slot(g, 2));
    int z = alloc_slots(g, 3);
    for (int i = 0; i < 3; i++) {
        int u = op2(g, SL_OP_MUL, t, args[1] + i);
        emit(g, SL_OP_SUB, z + i, args[0] + i, u, 0);
    }
    return into(g, z, dst, 3);
}

static int gen_light(cg *g, sl_node *e, const int *args, int dst)
{
    int z = alloc_slots(g, 3);
    emit(g, e->builtin->op, z, e->nlist > 0 ? args[0] : 0, e->nlist > 1 ? args[1] : 0,
         e->nlist > 2 ? args[2] : 0);
    return into(g, z, dst, 3);
}

/* ---------------------------------------------------------------------- */
/* color spaces and matrices                                               */
/* ---------------------------------------------------------------------- */

typedef struct select_job {
    int src, z, n;
} select_job;

static void gen_select_job(cg *g, void *arg)
{
    select_job *job = arg;
    emit_mov(g, job->z, job->src, job->n);
}

/* z = cond ? x : y over n slots (a branch: merged where cond is maybe). */
static int gen_select(cg *g, int cond, int x, int y, int n)
{
    int z = alloc_slots(g, n);
    select_job a = { x, z, n }, b = { y, z, n };
    gen_branches(g, cond, gen_select_job, &a, gen_select_job, &b);
    return z;
}

/* x / y, y replaced by 1 where it is 0 (the conversions' black and grey). */
static int safe_div(cg *g, int x, int y)
{
    int one = const_slot(g, 1);
    int d = gen_select(g, op2(g, SL_OP_EQ, y, const_slot(g, 0)), one, y, 1);
    return op2(g, SL_OP_DIV, x, d);
}

/* The linear color spaces: rgb -> space (3x3, row-major). */
static const double xyz_from_rgb[9] = {      /* linear Rec. 709 / sRGB primaries, D65 */
    0.4124564, 0.3575761, 0.1804375,
    0.2126729, 0.7151522, 0.0721750,
    0.0193339, 0.1191920, 0.9503041,
};
static const double yiq_from_rgb[9] = {      /* NTSC */
    0.299, 0.587, 0.114,
    0.596, -0.274, -0.322,
    0.211, -0.523, 0.312,
};

static void invert3(const double m[9], double inv[9])
{
    double c[9] = {
        m[4] * m[8] - m[5] * m[7], m[2] * m[7] - m[1] * m[8], m[1] * m[5] - m[2] * m[4],
        m[5] * m[6] - m[3] * m[8], m[0] * m[8] - m[2] * m[6], m[2] * m[3] - m[0] * m[5],
        m[3] * m[7] - m[4] * m[6], m[1] * m[6] - m[0] * m[7], m[0] * m[4] - m[1] * m[3],
    };
    double det = m[0] * c[0] + m[1] * c[3] + m[2] * c[6];
    for (int i = 0; i < 9; i++)
        inv[i] = c[i] / det;
}

static int gen_mat3(cg *g, const double m[9], int x)
{
    int z = alloc_slots(g, 3);
    for (int r = 0; r < 3; r++) {
        emit(g, SL_OP_MUL, z + r, x, const_slot(g, m[r * 3]), 0);
        for (int k = 1; k < 3; k++)
            emit(g, SL_OP_ADD, z + r, z + r, op2(g, SL_OP_MUL, x + k, const_slot(g, m[r * 3 + k])), 0);
    }
    return z;
}

/* hsv / hsl -> rgb without branches: channel k of the fully saturated hue
 * is clamp(|mod(6 h + (0, 4, 2)_k, 6) - 3| - 1, 0, 1); hsv scales it
 * towards white by s and by v, hsl around l. */
static int gen_from_hue(cg *g, int x, bool hsl)
{
    static const double offset[3] = { 0, 4, 2 };
    int z = alloc_slots(g, 3);
    int h6 = op2(g, SL_OP_MUL, x, const_slot(g, 6));
    int chroma;
    if (hsl) {       /* s (1 - |2 l - 1|) */
        int l2 = op2(g, SL_OP_SUB, op2(g, SL_OP_MUL, x + 2, const_slot(g, 2)), const_slot(g, 1));
        chroma = op2(g, SL_OP_MUL, x + 1, op2(g, SL_OP_SUB, const_slot(g, 1), op1(g, SL_OP_ABS, l2)));
    } else {         /* s v */
        chroma = op2(g, SL_OP_MUL, x + 1, x + 2);
    }
    for (int k = 0; k < 3; k++) {
        int a = offset[k] ? op2(g, SL_OP_ADD, h6, const_slot(g, offset[k])) : h6;
        a = op2(g, SL_OP_MOD, a, const_slot(g, 6));
        a = op1(g, SL_OP_ABS, op2(g, SL_OP_SUB, a, const_slot(g, 3)));
        a = op2(g, SL_OP_SUB, a, const_slot(g, 1));
        emit(g, SL_OP_CLAMP, a, a, const_slot(g, 0), const_slot(g, 1));
        if (hsl) {   /* l + chroma (c - 1/2) */
            int d = op2(g, SL_OP_SUB, a, const_slot(g, 0.5));
            emit(g, SL_OP_ADD, z + k, x + 2, op2(g, SL_OP_MUL, chroma, d), 0);
        } else {     /* v - chroma + chroma c = v (1 - s + s c) */
            int d = op2(g, SL_OP_SUB, a, const_slot(g, 1));
            emit(g, SL_OP_ADD, z + k, x + 2, op2(g, SL_OP_MUL, chroma, d), 0);
        }
    }
    return z;
}

/* rgb -> hsv / hsl: M = max, m = min, C = M - m; the hue from the sector
 * of the largest channel (0 for greys), h in [0, 1). */
static int gen_to_hue(cg *g, int x, bool hsl)
{
    int z = alloc_slots(g, 3);
    int r = x, gg = x + 1, b = x + 2;
    int M = op2(g, SL_OP_MAX, r, op2(g, SL_OP_MAX, gg, b));
    int m = op2(g, SL_OP_MIN, r, op2(g, SL_OP_MIN, gg, b));
    int C = op2(g, SL_OP_SUB, M, m);
    int hr = op2(g, SL_OP_MOD, safe_div(g, op2(g, SL_OP_SUB, gg, b), C), const_slot(g, 6));
    int hg = op2(g, SL_OP_ADD, safe_div(g, op2(g, SL_OP_SUB, b, r), C), const_slot(g, 2));
    int hb = op2(g, SL_OP_ADD, safe_div(g, op2(g, SL_OP_SUB, r, gg), C), const_slot(g, 4));
    int h = gen_select(g, op2(g, SL_OP_EQ, M, r), hr,
                       gen_select(g, op2(g, SL_OP_EQ, M, gg), hg, hb, 1), 1);
    emit(g, SL_OP_DIV, z, h, const_slot(g, 6), 0);
    if (hsl) {
        int l = op2(g, SL_OP_MUL, op2(g, SL_OP_ADD, M, m), const_slot(g, 0.5));
        int l2 = op2(g, SL_OP_SUB, op2(g, SL_OP_MUL, l, const_slot(g, 2)), const_slot(g, 1));
        int d = op2(g, SL_OP_SUB, const_slot(g, 1), op1(g, SL_OP_ABS, l2));
        emit(g, SL_OP_MOV, z + 1, safe_div(g, C, d), 0, 0);
        emit(g, SL_OP_MOV, z + 2, l, 0, 0);
    } else {
        emit(g, SL_OP_MOV, z + 1, safe_div(g, C, M), 0, 0);
        emit(g, SL_OP_MOV, z + 2, M, 0, 0);
    }
    return z;
}

/* A color in `space` to rgb (from) or rgb to `space` (!from). */
static int gen_color_space(cg *g, int space, int x, bool from)
{
    double inv[9];
    switch ((sl_color_space)space) {
    case SL_CSPACE_RGB: return x;
    case SL_CSPACE_HSV: return from ? gen_from_hue(g, x, false) : gen_to_hue(g, x, false);
    case SL_CSPACE_HSL: return from ? gen_from_hue(g, x, true) : gen_to_hue(g, x, true);
    case SL_CSPACE_YIQ:
        if (!from)
            return gen_mat3(g, yiq_from_rgb, x);
        invert3(yiq_from_rgb, inv);
        return gen_mat3(g, inv, x);
    case SL_CSPACE_XYZ:
        if (!from)
            return gen_mat3(g, xyz_from_rgb, x);
        invert3(xyz_from_rgb, inv);
        return gen_mat3(g, inv, x);
    case SL_CSPACE_XYY:
        if (!from) {     /* XYZ -> (X, Y) / (X + Y + Z), Y */
            int q = gen_mat3(g, xyz_from_rgb, x);
            int sum = op2(g, SL_OP_ADD, op2(g, SL_OP_ADD, q, q + 1), q + 2);
            int z = alloc_slots(g, 3);
            emit(g, SL_OP_MOV, z, safe_div(g, q, sum), 0, 0);
            emit(g, SL_OP_MOV, z + 1, safe_div(g, q + 1, sum), 0, 0);
            emit(g, SL_OP_MOV, z + 2, q + 1, 0, 0);
            return z;
        } else {         /* X = x Y / y, Z = (1 - x - y) Y / y */
            int q = alloc_slots(g, 3);
            int k = safe_div(g, x + 2, x + 1);
            emit(g, SL_OP_MUL, q, x, k, 0);
            emit(g, SL_OP_MOV, q + 1, x + 2, 0, 0);
            int w = op2(g, SL_OP_SUB, op2(g, SL_OP_SUB, const_slot(g, 1), x), x + 1);
            emit(g, SL_OP_MUL, q + 2, w, k, 0);
            invert3(xyz_from_rgb, inv);
            return gen_mat3(g, inv, q);
        }
    }
    return x;
}

static int gen_ctransform(cg *g, sl_node *e, const int *args, int dst)
{
    int n = e->nlist, x = args[n - 1];
    if (n == 3)
        x = gen_color_space(g, sl_color_space_find(e->list[0]->name), x, true);
    x = gen_color_space(g, sl_color_space_find(e->list[n - 2]->name), x, false);
    return into(g, x, dst, 3);
}

/* determinant: Laplace expansion by the 2x2 minors of rows 0-1 and 2-3
 * (the same for the transposed matrix the slots hold). */
static int gen_determinant(cg *g, int m, int dst)
{
    static const int pairs[6][2] = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } };
    static const double sign[6] = { 1, -1, 1, 1, -1, 1 };
    int z = target(g, dst, 1);
    for (int i = 0; i < 6; i++) {
        int a = pairs[i][0], b = pairs[i][1];
        int c = pairs[5 - i][0], d = pairs[5 - i][1];
        int top = op2(g, SL_OP_SUB, op2(g, SL_OP_MUL, m + a, m + 4 + b),
                      op2(g, SL_OP_MUL, m + b, m + 4 + a));
        int bot = op2(g, SL_OP_SUB, op2(g, SL_OP_MUL, m + 8 + c, m + 12 + d),
                      op2(g, SL_OP_MUL, m + 8 + d, m + 12 + c));
        int t = op2(g, SL_OP_MUL, top, bot);
        if (i == 0)
            emit(g, SL_OP_MOV, z, t, 0, 0);
        else
            emit(g, sign[i] > 0 ? SL_OP_ADD : SL_OP_SUB, z, z, t, 0);
    }
    return z;
}

/* translate(m, t), rotate(m, angle, axis), scale(m, s): the transform is
 * applied first, then m (as RiTranslate, RiRotate and RiScale concatenate
 * onto the current transformation): m' = X * m in RenderMan's order. The
 * slots hold the transpose (points as columns): X's 3x3 part at r * 4 + c,
 * the translation in column 3. */
static int gen_matrix_xform(cg *g, sl_node *e, const int *args, int dst)
{
    int x = alloc_slots(g, 16);
    int zero = const_slot(g, 0), one = const_slot(g, 1);
    for (int i = 0; i < 16; i++)
        emit(g, SL_OP_MOV, x + i, i % 5 == 0 ? one : zero, 0, 0);
    int kind = (int)e->builtin->k;
    if (kind == 0) {
        for (int r = 0; r < 3; r++)
            emit(g, SL_OP_MOV, x + r * 4 + 3, args[1] + r, 0, 0);
    } else if (kind == 2) {
        for (int r = 0; r < 3; r++)
            emit(g, SL_OP_MOV, x + r * 5, args[1] + r, 0, 0);
    } else {         /* Rodrigues: c I + s [a]x + (1 - c) a a^T, a the unit axis */
        int a = gen_normalize(g, args[2], -1);
        int c = op1(g, SL_OP_COS, args[1]), s = op1(g, SL_OP_SIN, args[1]);
        int t = op2(g, SL_OP_SUB, one, c);
        for (int r = 0; r < 3; r++) {
            for (int col = 0; col < 3; col++) {
                int v = op2(g, SL_OP_MUL, t, op2(g, SL_OP_MUL, a + r, a + col));
                if (r == col) {
                    emit(g, SL_OP_ADD, x + r * 4 + col, v, c, 0);
                    continue;
                }
                int k = 3 - r - col;              /* the third axis */
                bool plus = (col - r + 3) % 3 == 2; /* [a]x: +a_k below the cycle */
                int w = op2(g, SL_OP_MUL, s, a + k);
                emit(g, plus ? SL_OP_ADD : SL_OP_SUB, x + r * 4 + col, v, w, 0);
            }
        }
    }
    return gen_matmul(g, args[0], x, dst);
}

/* comp(m, row, col) / setcomp(m, row, col, v): element (row, col) of the
 * matrix as written (row vectors) is slot col * 4 + row. */
static int gen_mcomp(cg *g, const int *args, bool set, int dst)
{
    int m = args[0], r = args[1], c = args[2];
    if ((r & CONST_TAG) && (c & CONST_TAG)) {
        double rv = floor(g->prog->consts[r & ~CONST_TAG]);
        double cv = floor(g->prog->consts[c & ~CONST_TAG]);
        if (!(rv >= 0 && rv < 4 && cv >= 0 && cv < 4)) {
            fail(g, "matrix element (%g, %g) does not exist (rows and columns 0 to 3)", rv, cv);
            return 0;
        }
        int slot = m + (int)cv * 4 + (int)rv;
        if (!set)
            return into(g, slot, dst, 1);
        emit(g, SL_OP_MOV, slot, args[3], 0, 0);
        return 0;
    }
    /* a row or column outside 0..3 pushes the index past the 16 elements,
     * where aload/astore stop the run (range modes: clamped, conservative) */
    int fr = op1(g, SL_OP_FLOOR, r), fc = op1(g, SL_OP_FLOOR, c);
    int bad = op2(g, SL_OP_OR, op2(g, SL_OP_OR, op2(g, SL_OP_LT, fr, const_slot(g, 0)),
                                   op2(g, SL_OP_GT, fr, const_slot(g, 3))),
                  op2(g, SL_OP_OR, op2(g, SL_OP_LT, fc, const_slot(g, 0)),
                      op2(g, SL_OP_GT, fc, const_slot(g, 3))));
    int index = op2(g, SL_OP_ADD, op2(g, SL_OP_MUL, fc, const_slot(g, 4)), fr);
    index = op2(g, SL_OP_ADD, index, op2(g, SL_OP_MUL, bad, const_slot(g, 64)));
    if (set) {
        emit(g, SL_OP_ASTORE, m, index, args[3], array_operand(16, 1));
        record_write(g, m, 16);
        return 0;
    }
    int z = alloc_slots(g, 1);
    emit(g, SL_OP_ALOAD, z, m, index, array_operand(16, 1));
    return into(g, z, dst, 1);
}

/* refract(I, N, eta) = eta I - (eta I.N + sqrt(k)) N with k = 1 - eta^2
 * (1 - (I.N)^2); (0, 0, 0) where k < 0 (total internal reflection). */
static int gen_refract(cg *g, int I, int N, int eta, int dst)
{
    int d = gen_dot(g, I, N, 3, -1);
    int one = const_slot(g, 1);
    int sin2 = op2(g, SL_OP_SUB, one, op2(g, SL_OP_MUL, d, d));
    int k = op2(g, SL_OP_SUB, one, op2(g, SL_OP_MUL, op2(g, SL_OP_MUL, eta, eta), sin2));
    int root = op1(g, SL_OP_SQRT, op2(g, SL_OP_MAX, k, const_slot(g, 0)));
    int a = op2(g, SL_OP_ADD, op2(g, SL_OP_MUL, eta, d), root);
    int r = alloc_slots(g, 3), zero = alloc_slots(g, 3);
    for (int i = 0; i < 3; i++) {
        emit(g, SL_OP_SUB, r + i, op2(g, SL_OP_MUL, eta, I + i), op2(g, SL_OP_MUL, a, N + i), 0);
        emit(g, SL_OP_MOV, zero + i, const_slot(g, 0), 0, 0);
    }
    int z = gen_select(g, op2(g, SL_OP_LT, k, const_slot(g, 0)), zero, r, 3);
    return into(g, z, dst, 3);
}

/* fresnel(I, N, eta, Kr, Kt [, R, T]) (I and N unit vectors; eta the
 * ratio of the indices of refraction, as for refract): Cook and Torrance's
 * unpolarised dielectric reflectance with c = |I.N|, g^2 = 1/eta^2 + c^2 -
 * 1: Kr = 1/2 ((g - c)/(g + c))^2 (1 + ((c (g + c) - 1)/(c (g - c) + 1))^2),
 * 1 where g^2 < 0 (total internal reflection); Kt = 1 - Kr; R = reflect(I,
 * N), T = refract(I, N, eta). */
static int gen_fresnel(cg *g, sl_node *e, const int *args)
{
    int I = args[0], N = args[1], eta = args[2];
    int one = const_slot(g, 1);
    int c = op1(g, SL_OP_ABS, gen_dot(g, I, N, 3, -1));
    int inv = op2(g, SL_OP_DIV, one, eta);
    int g2 = op2(g, SL_OP_SUB, op2(g, SL_OP_ADD, op2(g, SL_OP_MUL, inv, inv),
                                   op2(g, SL_OP_MUL, c, c)), one);
    int gg = op1(g, SL_OP_SQRT, op2(g, SL_OP_MAX, g2, const_slot(g, 0)));
    int gpc = op2(g, SL_OP_ADD, gg, c), gmc = op2(g, SL_OP_SUB, gg, c);
    int a = safe_div(g, gmc, gpc);
    int b = safe_div(g, op2(g, SL_OP_SUB, op2(g, SL_OP_MUL, c, gpc), one),
                     op2(g, SL_OP_ADD, op2(g, SL_OP_MUL, c, gmc), one));
    int f = op2(g, SL_OP_MUL, op2(g, SL_OP_MUL, const_slot(g, 0.5), op2(g, SL_OP_MUL, a, a)),
                op2(g, SL_OP_ADD, one, op2(g, SL_OP_MUL, b, b)));
    int kr = gen_select(g, op2(g, SL_OP_LT, g2, const_slot(g, 0)), one, f, 1);
    if (e->nlist == 7) {      /* before Kr and Kt: the outputs may alias I or N */
        int r = gen_reflect(g, args, -1), t = gen_refract(g, I, N, eta, -1);
        emit_mov(g, args[5], r, 3);
        emit_mov(g, args[6], t, 3);
    }
    emit(g, SL_OP_MOV, args[3], kr, 0, 0);
    emit(g, SL_OP_SUB, args[4], one, kr, 0);
    return 0;
}

/* depth(P): z of P in camera space, (z - near) / (far - near), through the
 * VM's depth pseudo-space (sl_vm_set_clipping). */
static int gen_depth(cg *g, int p, int dst)
{
    int m = alloc_slots(g, 16);
    emit(g, SL_OP_SPACEK, m, SL_SPACE_DEPTH, SL_SPACE_TO_CURRENT, 0);
    int z = alloc_slots(g, 3);
    emit(g, SL_OP_XPOINT, z, m, p, 0);
    return into(g, z + 2, dst, 1);
}

/* filterstep(edge, x [, x1] [, "width", w] [, "filter", name]): the step
 * box-filtered over [x - fw/2, x + fw/2], fw = w (|Du(x)| du + |Dv(x)| dv)
 * the filter width of x, i.e. clamp((x - edge) / fw + 1/2, 0, 1); with x1,
 * over [min(x, x1), max(x, x1)]. A zero width gives the step. */
static int gen_filterstep(cg *g, sl_node *e, const int *args, int dst)
{
    int nf = 0;
    while (nf < e->nlist && e->list[nf]->ty == SL_TYPE_FLOAT)
        nf++;
    int width = -1;
    for (int i = nf; i + 1 < e->nlist; i += 2)
        if (strcmp(e->list[i]->name, "width") == 0)
            width = args[i + 1];
    int edge = args[0], x = args[1];
    int tiny = const_slot(g, 1e-12);
    int r;
    if (nf == 3) {
        int lo = op2(g, SL_OP_MIN, x, args[2]), hi = op2(g, SL_OP_MAX, x, args[2]);
        int w = op2(g, SL_OP_SUB, hi, lo);
        if (width >= 0) {       /* widen about the middle */
            int mid = op2(g, SL_OP_MUL, op2(g, SL_OP_ADD, lo, hi), const_slot(g, 0.5));
            w = op2(g, SL_OP_MUL, w, width);
            hi = op2(g, SL_OP_ADD, mid, op2(g, SL_OP_MUL, w, const_slot(g, 0.5)));
        }
        r = op2(g, SL_OP_DIV, op2(g, SL_OP_SUB, hi, edge), op2(g, SL_OP_MAX, w, tiny));
    } else {
        int du = op1(g, SL_OP_ABS, op1(g, SL_OP_DU, x));
        int dv = op1(g, SL_OP_ABS, op1(g, SL_OP_DV, x));
        int w = op2(g, SL_OP_ADD, op2(g, SL_OP_MUL, du, sl_global_slot(SL_G_du)),
                    op2(g, SL_OP_MUL, dv, sl_global_slot(SL_G_dv)));
        if (width >= 0)
            w = op2(g, SL_OP_MUL, w, width);
        r = op2(g, SL_OP_DIV, op2(g, SL_OP_SUB, x, edge), op2(g, SL_OP_MAX, w, tiny));
        r = op2(g, SL_OP_ADD, r, const_slot(g, 0.5));
    }
    int z = target(g, dst, 1);
    emit(g, SL_OP_CLAMP, z, r, const_slot(g, 0), const_slot(g, 1));
    return z;
}

/* The parts of an illuminance loop (parser.c): start, next (loads L and
 * Cl: they are written by the loop), and the cone test of
 * illuminance(P, axis, angle): L . axis >= cos(angle) |L| |axis|. */
static int gen_illuminance(cg *g, sl_node *e, const int *args, int dst)
{
    sl_opcode op = e->builtin->op;
    if (op == SL_OP_LSTART) {
        emit(g, SL_OP_LSTART, 0, 0, 0, 0);
        return 0;
    }
    int L = sl_global_slot(SL_G_L);
    if (op == SL_OP_LNEXT) {
        int z = target(g, dst, 1);
        emit(g, SL_OP_LNEXT, z, 0, 0, 0);
        record_write(g, L, 3);
        record_write(g, sl_global_slot(SL_G_Cl), 3);
        return z;
    }
    int d = gen_dot(g, L, args[0], 3, -1);
    int ll = op1(g, SL_OP_SQRT, gen_dot(g, L, L, 3, -1));
    int la = op1(g, SL_OP_SQRT, gen_dot(g, args[0], args[0], 3, -1));
    int r = op2(g, SL_OP_MUL, op2(g, SL_OP_MUL, op1(g, SL_OP_COS, args[1]), ll), la);
    int z = target(g, dst, 1);
    emit(g, SL_OP_GE, z, d, r, 0);
    return z;
}

/* concat, format, printf: a chain of scat over the pieces; a numeric
 * conversion becomes sfmt with the C spec ("%5.2f"; d and i as "lld"; the
 * triple and matrix conversions as "f" per component). */
typedef struct fmt_job {
    cg *g;
    sl_node *e;
    int next, cur;
} fmt_job;

static void fmt_append(cg *g, fmt_job *job, int s)
{
    int z = alloc_string(g);
    emit(g, SL_OP_SCAT, z, job->cur, s, 0);
    record_string_write(g, z);
    job->cur = z;
}

static void fmt_piece(void *arg, const char *spec, size_t len, char conv, const char *lit,
                      size_t litlen)
{
    fmt_job *job = arg;
    cg *g = job->g;
    if (litlen)
        fmt_append(g, job, string_const(g, lit, litlen));
    if (!spec)
        return;
    sl_node *a = job->e->list[job->next++];
    int x = gen_expr(g, a, -1);
    if (conv == 's') {
        fmt_append(g, job, x);
        return;
    }
    char c_spec[32];
    const char *tail = strchr("di", conv) ? "lld" : strchr("eg", conv) ? (conv == 'e' ? "e" : "g")
                                                                      : "f";
    snprintf(c_spec, sizeof c_spec, "%.*s%s", (int)(len), spec, tail);
    int t = alloc_string(g);
    emit(g, SL_OP_SFMT, t, x, string_const(g, c_spec, strlen(c_spec)), size_of(a));
    record_string_write(g, t);
    fmt_append(g, job, t);
}

static int gen_strings(cg *g, sl_node *e, int dst)
{
    sl_opcode op = e->builtin->op;
    fmt_job job = { g, e, 1, string_const(g, "", 0) };
    if (op == SL_OP_SCAT) {
        job.cur = gen_expr(g, e->list[0], -1);
        for (int i = 1; i < e->nlist; i++)
            fmt_append(g, &job, gen_expr(g, e->list[i], -1));
        return into_string(g, job.cur, dst);
    }
    sl_format_walk(e->list[0]->name, fmt_piece, &job);
    if (op == SL_OP_SPRINT) {
        emit(g, SL_OP_SPRINT, job.cur, 0, 0, 0);
        return 0;
    }
    return into_string(g, job.cur, dst);
}

/* textureinfo(name, "datum", var): TEXINFO into var (its type string is
 * "texture" whenever the texture opens). */
static int gen_texture_info(cg *g, sl_node *e, int name, int dst)
{
    int q = (int)e->num;
    sl_sym *var = e->list[2]->sym;
    int z = target(g, dst, 1);
    int size = q == SL_TEXINFO_RESOLUTION ? 2 : q == SL_TEXINFO_TYPE ? 0 : 1;
    emit(g, SL_OP_TEXINFO, z, name, size ? var->slot : 0, q);
    if (size)
        record_write(g, var->slot, size);
    else
        emit(g, SL_OP_SMOV, var->slot, string_const(g, "texture", 7), 0, 0);
    return z;
}

/* texture(), environment(), bump(), textureinfo() (check_texture; the
 * lookups of docs/textures.md): the six argument slots of TEXTURE
 * (bytecode.h) and the op. Footprint: the four-corner form's extent in s
 * and t times "width" ("swidth", "twidth"), plus "blur" ("sblur",
 * "tblur"); the other forms have the blur alone. environment() turns its
 * direction D into lat-long coordinates s = 1/2 + atan2(D.y, D.x) / 2pi,
 * t = acos(D.z / |D|) / pi (s periodic, t clamped); bump() returns
 * dh/ds (N x dPdt) + dh/dt (dPds x N), the change of the normal that a
 * displacement by h along N makes (to first order). */
static int gen_texture(cg *g, sl_node *e, int dst)
{
    int kind = e->op, npos = (int)e->num;
    int name = gen_expr(g, e->a, -1);
    if (kind == SL_TEX_INFO)
        return gen_texture_info(g, e, name, dst);
    int chan = e->b ? gen_expr(g, e->b, -1) : const_slot(g, 0);
    int pos[8];
    for (int i = 0; i < npos; i++)
        pos[i] = gen_expr(g, e->list[1 + i], -1);
    int blur[2] = { -1, -1 }, width[2] = { -1, -1 }, fill = const_slot(g, 0);
    int wrap[2] = { TEX_WRAP_PERIODIC, kind == SL_TEX_ENVIRONMENT ? TEX_WRAP_CLAMP
                                                                  : TEX_WRAP_PERIODIC };
    for (int i = 1 + npos; i + 1 < e->nlist; i += 2) {   /* "blur" before "sblur" */
        const char *pn = e->list[i]->name;
        sl_node *v = e->list[i + 1];
        if (strcmp(pn, "filter") == 0 || strcmp(pn, "samples") == 0)
            continue;
        if (strstr(pn, "wrap")) {
            int w = tex_wrap_find(v->name);
            if (pn[0] != 't')
                wrap[0] = w;
            if (pn[0] != 's')
                wrap[1] = w;
            continue;
        }
        int x = gen_expr(g, v, -1);
        if (strcmp(pn, "fill") == 0)
            fill = x;
        int *dstp = strstr(pn, "blur") ? blur : strstr(pn, "width") ? width : NULL;
        if (!dstp)
            continue;
        if (pn[0] != 't')
            dstp[0] = x;
        if (pn[0] != 's')
            dstp[1] = x;
    }
    int st[2], w[2];
    int zero = const_slot(g, 0);
    if (kind == SL_TEX_ENVIRONMENT) {
        int d = gen_normalize(g, pos[0], -1);
        int a = op2(g, SL_OP_ATAN2, d + 1, d);
        st[0] = op2(g, SL_OP_ADD, op2(g, SL_OP_MUL, a, const_slot(g, 0.5 / M_PI)),
                    const_slot(g, 0.5));
        st[1] = op2(g, SL_OP_MUL, op1(g, SL_OP_ACOS, d + 2), const_slot(g, 1.0 / M_PI));
    } else if (npos == 8) {
        for (int k = 0; k < 2; k++) {
            int sum = op2(g, SL_OP_ADD, op2(g, SL_OP_ADD, pos[k], pos[k + 2]),
                          op2(g, SL_OP_ADD, pos[k + 4], pos[k + 6]));
            st[k] = op2(g, SL_OP_MUL, sum, const_slot(g, 0.25));
            int lo = op2(g, SL_OP_MIN, op2(g, SL_OP_MIN, pos[k], pos[k + 2]),
                         op2(g, SL_OP_MIN, pos[k + 4], pos[k + 6]));
            int hi = op2(g, SL_OP_MAX, op2(g, SL_OP_MAX, pos[k], pos[k + 2]),
                         op2(g, SL_OP_MAX, pos[k + 4], pos[k + 6]));
            w[k] = op2(g, SL_OP_SUB, hi, lo);
            if (width[k] >= 0)
                w[k] = op2(g, SL_OP_MUL, w[k], width[k]);
        }
    } else if ((kind == SL_TEX_TEXTURE && npos == 2) || (kind == SL_TEX_BUMP && npos == 5)) {
        st[0] = pos[npos - 2];
        st[1] = pos[npos - 1];
    } else {
        st[0] = sl_global_slot(SL_G_s);
        st[1] = sl_global_slot(SL_G_t);
    }
    for (int k = 0; k < 2; k++) {
        if (npos != 8 || kind != SL_TEX_TEXTURE)
            w[k] = zero;
        if (blur[k] >= 0)
            w[k] = op2(g, SL_OP_ADD, w[k], op1(g, SL_OP_ABS, blur[k]));
    }
    int args = alloc_slots(g, 6);
    int src[6] = { st[0], st[1], w[0], w[1], chan, fill };
    for (int k = 0; k < 6; k++)
        emit(g, SL_OP_MOV, args + k, src[k], 0, 0);
    int op = kind == SL_TEX_BUMP ? SL_TEXOP_GRAD
           : size_of(e) == 3 ? SL_TEXOP_COLOR : SL_TEXOP_FLOAT;
    int outs = sl_texop_outs(SL_TEXOP(op, wrap[0], wrap[1]));
    int z = alloc_slots(g, outs);
    emit(g, SL_OP_TEXTURE, z, name, args, SL_TEXOP(op, wrap[0], wrap[1]));
    if (kind != SL_TEX_BUMP)
        return into(g, z, dst, outs);
    int a = gen_cross(g, pos[0], pos[2], -1), b = gen_cross(g, pos[1], pos[0], -1);
    int r = target(g, dst, 3);
    for (int i = 0; i < 3; i++)
        emit(g, SL_OP_ADD, r + i, op2(g, SL_OP_MUL, z, a + i), op2(g, SL_OP_MUL, z + 1, b + i),
             0);
    return r;
}

/* spline([basis,] t, knots): x = clamp(t, 0, 1) * segments; the segment
 * seg = min(floor(x), segments - 1) and its 4 knots are read with aload
 * (in interval/affine mode: the merge of every knot the segment range can
 * reach, so the result is conservative), then the cubic of the basis is
 * evaluated in x - seg by Horner's rule. */
static int gen_spline(cg *g, sl_node *e, int dst)
{
    const sl_spline_basis *b = sl_spline_basis_get(e->op);
    int first = e->list[0]->ty == SL_TYPE_STRING ? 1 : 0;
    int n = size_of(e);
    int t = gen_expr(g, e->list[first], -1);
    int nknots, base;
    sl_node *k0 = e->list[first + 1];
    if (sl_ty_is_array(k0->ty)) {
        nknots = array_len(k0->sym);
        base = k0->sym->slot;
        if (nknots < 4 || (nknots - 4) % b->step != 0) {
            fail(g, "a '%s' spline takes 4%s knots, not the %d of '%s'", b->name,
                 b->step == 3 ? ", 7, 10, ..." : b->step == 2 ? ", 6, 8, ..." : " or more",
                 nknots, k0->name);
            return 0;
        }
    } else {
        nknots = e->nlist - first - 1;
        base = alloc_slots(g, nknots * n);
        for (int i = 0; i < nknots; i++) {
            int mark = g->sp;
            gen_expr(g, e->list[first + 1 + i], base + i * n);
            g->sp = mark;
        }
    }
    int segs = (nknots - 4) / b->step + 1;
    int x = alloc_slots(g, 1);
    emit(g, SL_OP_CLAMP, x, t, const_slot(g, 0), const_slot(g, 1));
    int knot[4];                     /* first slot of each of the segment's knots */
    if (segs == 1) {
        for (int j = 0; j < 4; j++)
            knot[j] = base + j * n;
    } else {
        emit(g, SL_OP_MUL, x, x, const_slot(g, segs), 0);
        int seg = op2(g, SL_OP_MIN, op1(g, SL_OP_FLOOR, x), const_slot(g, segs - 1));
        emit(g, SL_OP_SUB, x, x, seg, 0);
        int at = op2(g, SL_OP_MUL, seg, const_slot(g, b->step));
        for (int j = 0; j < 4; j++) {
            if (e->op == SL_SPLINE_CONSTANT && j != 1)
                continue;
            int index = j ? op2(g, SL_OP_ADD, at, const_slot(g, j)) : at;
            knot[j] = alloc_slots(g, n);
            for (int k = 0; k < n; k++)
                emit(g, SL_OP_ALOAD, knot[j] + k, base + k, index, array_operand(nknots, n));
        }
    }
    if (e->op == SL_SPLINE_CONSTANT)
        return into(g, knot[1], dst, n);
    int z = target(g, dst, n);
    for (int k = 0; k < n; k++) {
        bool started = false;
        for (int i = 0; i < 4; i++) {
            /* the coefficient of x^(3-i): sum_j m[i][j] knot_j */
            int c = -1;
            for (int j = 0; j < 4; j++) {
                double w = b->m[i][j];
                if (w == 0)
                    continue;
                int term = w == 1 ? knot[j] + k : op2(g, SL_OP_MUL, knot[j] + k, const_slot(g, w));
                c = c < 0 ? term : op2(g, SL_OP_ADD, c, term);
            }
            if (started)
                emit(g, SL_OP_MUL, z + k, z + k, x, 0);
            if (c >= 0) {
                if (started)
                    emit(g, SL_OP_ADD, z + k, z + k, c, 0);
                else
                    emit(g, SL_OP_MOV, z + k, c, 0, 0);
                started = true;
            }
        }
    }
    return z;
}

/* The rest of RI Spec 3.2's built-ins, lowered to scalar operations:
 * ptlined(P0, P1, Q), the distance from Q to the segment P0 P1 (t =
 * clamp((Q - P0).(P1 - P0) / |P1 - P0|^2, 0, 1)); rotate(Q, angle, P0, P1),
 * Q rotated by angle (radians) about the line through P0 and P1, as
 * RiRotate and rotate(m, angle, axis) turn (Rodrigues' formula about the
 * unit axis a: p cos + (a ^ p) sin + a (a.p)(1 - cos)); specularbrdf(L, N,
 * V, roughness), the lobe specular() sums: pow(max(0, normalize(N) .
 * normalize(normalize(L) + V)), 1 / roughness) as a grey colour;
 * shadername(), the shader's name. */
static int gen_extra(cg *g, const sl_builtin *b, const int *args, int dst)
{
    switch ((int)b->k) {
    case 0: {
        int v = alloc_slots(g, 3), w = alloc_slots(g, 3), d = alloc_slots(g, 3);
        for (int i = 0; i < 3; i++) {
            emit(g, SL_OP_SUB, v + i, args[1] + i, args[0] + i, 0);
            emit(g, SL_OP_SUB, w + i, args[2] + i, args[0] + i, 0);
        }
        int vv = op2(g, SL_OP_MAX, gen_dot(g, v, v, 3, -1), const_slot(g, 1e-300));
        int t = alloc_slots(g, 1);
        emit(g, SL_OP_CLAMP, t, op2(g, SL_OP_DIV, gen_dot(g, w, v, 3, -1), vv),
             const_slot(g, 0), const_slot(g, 1));
        for (int i = 0; i < 3; i++)
            emit(g, SL_OP_SUB, d + i, w + i, op2(g, SL_OP_MUL, t, v + i), 0);
        int z = target(g, dst, 1);
        emit(g, SL_OP_SQRT, z, gen_dot(g, d, d, 3, -1), 0, 0);
        return z;
    }
    case 1: {
        int axis = alloc_slots(g, 3), p = alloc_slots(g, 3), r = alloc_slots(g, 3);
        for (int i = 0; i < 3; i++) {
            emit(g, SL_OP_SUB, axis + i, args[3] + i, args[2] + i, 0);
            emit(g, SL_OP_SUB, p + i, args[0] + i, args[2] + i, 0);
        }
        int a = gen_normalize(g, axis, -1);
        int c = op1(g, SL_OP_COS, args[1]), sn = op1(g, SL_OP_SIN, args[1]);
        int ap = op2(g, SL_OP_MUL, gen_dot(g, a, p, 3, -1),
                     op2(g, SL_OP_SUB, const_slot(g, 1), c));
        int x = gen_cross(g, a, p, -1);
        for (int i = 0; i < 3; i++) {
            int sum = op2(g, SL_OP_ADD, op2(g, SL_OP_MUL, p + i, c),
                          op2(g, SL_OP_MUL, x + i, sn));
            sum = op2(g, SL_OP_ADD, sum, op2(g, SL_OP_MUL, a + i, ap));
            emit(g, SL_OP_ADD, r + i, args[2] + i, sum, 0);
        }
        return into(g, r, dst, 3);
    }
    case 2: {
        int L = gen_normalize(g, args[0], -1), H = alloc_slots(g, 3);
        for (int i = 0; i < 3; i++)
            emit(g, SL_OP_ADD, H + i, L + i, args[2] + i, 0);
        int Hn = gen_normalize(g, H, -1), Nn = gen_normalize(g, args[1], -1);
        int c = op2(g, SL_OP_MAX, gen_dot(g, Nn, Hn, 3, -1), const_slot(g, 0));
        int lobe = op2(g, SL_OP_POW, c, op2(g, SL_OP_DIV, const_slot(g, 1), args[3]));
        int z = target(g, dst, 3);
        for (int i = 0; i < 3; i++)
            emit(g, SL_OP_MOV, z + i, lobe, 0, 0);
        return z;
    }
    default:
        return into_string(g, string_const(g, g->prog->name, strlen(g->prog->name)), dst);
    }
}

/* trace(P, R) and shadow(name, P): one RAY instruction, answered by the
 * renderer's tracer at points (vm.c sl_vm_ray). shadow() aims at the light
 * through the L global: in a light shader at the light of the last
 * illuminate (Ps - L) or solar (-L, to infinity), in a surface shader at
 * the current light of the illuminance loop. A displacement shader runs
 * over ranges of the surface, where a ray cannot be bounded: an error. */
static int gen_ray(cg *g, sl_node *e, int *args, int dst)
{
    bool trace = e->builtin->k == SL_RAY_TRACE;
    if (g->prog->kind == SL_SHADER_DISPLACEMENT) {
        fail(g, "%s() cannot be used in a displacement shader: it runs over ranges of the "
             "surface, where a traced ray has no bound (use it in a surface%s shader)",
             trace ? "trace" : "shadow", trace ? "" : " or light");
        return 0;
    }
    int kind = trace ? SL_RAY_TRACE
             : g->prog->kind == SL_SHADER_LIGHT ? (g->solar ? SL_RAY_SHADOW_SOLAR
                                                            : SL_RAY_SHADOW_ILLUMINATE)
             : SL_RAY_SHADOW_SURFACE;
    int n = trace ? 3 : 1;
    int P = trace ? args[0] : args[1];
    int D = trace ? args[1] : sl_global_slot(SL_G_L);
    int map = 0;
    if (!trace) {                 /* a slot of its own: a constant's is fixed up later */
        map = alloc_string(g);
        emit(g, SL_OP_SMOV, map, args[0], 0, 0);
    }
    int z = alloc_slots(g, n);
    emit(g, SL_OP_RAY, z, P, D, kind | map << SL_RAY_KIND_BITS);
    return into(g, z, dst, n);
}

static int gen_builtin(cg *g, sl_node *e, int dst)
{
    const sl_builtin *b = e->builtin;
    int args[8], sizes[8];
    for (int i = 0; i < e->nlist; i++) {
        sl_node *a = e->list[i];
        sizes[i] = size_of(a);
        args[i] = gen_expr(g, a, -1);
    }
    int n = size_of(e);
    switch (b->lower) {
    case SL_LOWER_OP: return gen_lanes(g, b->op, args, sizes, n, dst);
    case SL_LOWER_SCALE: {
        int z = target(g, dst, 1);
        emit(g, SL_OP_MUL, z, args[0], const_slot(g, b->k), 0);
        return z;
    }
    case SL_LOWER_LOGBASE: {
        int z = target(g, dst, 1);
        emit(g, SL_OP_DIV, z, op1(g, SL_OP_LOG, args[0]), op1(g, SL_OP_LOG, args[1]), 0);
        return z;
    }
    case SL_LOWER_LENGTH: {
        int z = target(g, dst, 1);
        emit(g, SL_OP_SQRT, z, gen_dot(g, args[0], args[0], 3, -1), 0, 0);
        return z;
    }
    case SL_LOWER_NORMALIZE: return gen_normalize(g, args[0], dst);
    case SL_LOWER_DISTANCE: {
        int d = alloc_slots(g, 3);
        for (int i = 0; i < 3; i++)
            emit(g, SL_OP_SUB, d + i, args[1] + i, args[0] + i, 0);
        int z = target(g, dst, 1);
        emit(g, SL_OP_SQRT, z, gen_dot(g, d, d, 3, -1), 0, 0);
        return z;
    }
    case SL_LOWER_DOT: return gen_dot(g, args[0], args[1], 3, dst);
    case SL_LOWER_CROSS: return gen_cross(g, args[0], args[1], dst);
    case SL_LOWER_FACEFORWARD: return gen_faceforward(g, e, args, dst);
    case SL_LOWER_REFLECT: return gen_reflect(g, args, dst);
    case SL_LOWER_TRANSFORM: return gen_transform(g, e, args, dst);
    case SL_LOWER_CALCNORMAL: case SL_LOWER_AREA: {
        int z = alloc_slots(g, n);
        emit(g, b->op, z, args[0], 0, 0);
        return into(g, z, dst, n);
    }
    case SL_LOWER_DERIV: return gen_lanes(g, b->op, args, sizes, n, dst);
    case SL_LOWER_COMP: return into(g, args[0] + (int)b->k, dst, 1);
    case SL_LOWER_SETCOMP_K:
        emit(g, SL_OP_MOV, args[0] + (int)b->k, args[1], 0, 0);
        return 0;
    case SL_LOWER_COMP_RT: {
        int z = target(g, dst, 1);
        emit(g, SL_OP_COMP, z, args[0], args[1], 0);
        return z;
    }
    case SL_LOWER_SETCOMP_RT:
        emit(g, SL_OP_SETCOMP, args[0], args[1], args[2], 0);
        return 0;
    case SL_LOWER_NOISE: return gen_noise(g, e, args, sizes, dst);
    case SL_LOWER_RANDOM: {
        int z = alloc_slots(g, n);
        emit(g, SL_OP_RANDOM, z, n, 0, 0);
        return into(g, z, dst, n);
    }
    case SL_LOWER_LIGHT: return gen_light(g, e, args, dst);
    case SL_LOWER_CTRANSFORM: return gen_ctransform(g, e, args, dst);
    case SL_LOWER_DETERMINANT: return gen_determinant(g, args[0], dst);
    case SL_LOWER_MATRIX_XFORM: return gen_matrix_xform(g, e, args, dst);
    case SL_LOWER_MCOMP: return gen_mcomp(g, args, false, dst);
    case SL_LOWER_MSETCOMP: return gen_mcomp(g, args, true, dst);
    case SL_LOWER_REFRACT: return gen_refract(g, args[0], args[1], args[2], dst);
    case SL_LOWER_FRESNEL: return gen_fresnel(g, e, args);
    case SL_LOWER_DEPTH: return gen_depth(g, args[0], dst);
    case SL_LOWER_FILTERSTEP: return gen_filterstep(g, e, args, dst);
    case SL_LOWER_ILLUMINANCE: return gen_illuminance(g, e, args, dst);
    case SL_LOWER_EMITTER: {      /* L = Ps - position / axis / 0 */
        int L = sl_global_slot(SL_G_L), P = sl_global_slot(SL_G_P);
        g->prog->emits_light = true;
        g->solar = b->k != 0;
        for (int i = 0; i < 3; i++) {
            if (b->k == 0)
                emit(g, SL_OP_SUB, L + i, P + i, args[0] + i, 0);
            else
                emit(g, SL_OP_MOV, L + i, e->nlist ? args[0] + i : const_slot(g, 0), 0, 0);
        }
        return 0;
    }
    case SL_LOWER_MESSAGE: {
        bool str = e->list[1]->ty == SL_TYPE_STRING;
        int size = str ? 0 : size_of(e->list[1]);
        int z = target(g, dst, 1);
        emit(g, SL_OP_MESSAGE, z, args[0], args[1], (int)b->k | size << 4);
        if (str)
            record_string_write(g, args[1]);
        else
            record_write(g, args[1], size);
        return z;
    }
    case SL_LOWER_RAY: return gen_ray(g, e, args, dst);
    case SL_LOWER_EXTRA: return gen_extra(g, b, args, dst);
    case SL_LOWER_SPLINE: case SL_LOWER_STRINGS: break;     /* gen_spline, gen_strings */
    case SL_LOWER_TEXTURE: break;                           /* gen_texture */
    case SL_LOWER_MATCH: {
        int z = target(g, dst, 1);
        emit(g, SL_OP_SMATCH, z, args[0], args[1], 0);
        return z;
    }
    }
    return 0;
}

/* ---------------------------------------------------------------------- */
/* user functions: inlined                                                 */
/* ---------------------------------------------------------------------- */

static int gen_user_call(cg *g, sl_node *e, int dst)
{
    sl_func *f = e->func;
    if (g->inline_depth >= SL_MAX_INLINE_DEPTH) {
        fail(g, "function calls nested too deeply (limit %d)", SL_MAX_INLINE_DEPTH);
        return 0;
    }
    int args[64];
    if (e->nlist > 64) {
        fail(g, "too many arguments in call to '%s'", f->name);
        return 0;
    }
    for (int i = 0; i < e->nlist; i++)
        args[i] = gen_expr(g, e->list[i], -1);
    for (int i = 0; i < e->nlist; i++) {
        sl_sym *p = f->params[i];
        if (sl_ty_is_array(p->ty)) {       /* by reference, with its length */
            int len = array_len(e->list[i]->sym);
            if (sl_ty_len(p->ty) && sl_ty_len(p->ty) != len) {
                fail(g, "argument %d of '%s': an array of %d elements where %d are expected",
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
    int ret = size == 0 ? -1 : str ? alloc_string(g) : alloc_slots(g, size);
    int flag = -1;
    if (f->needs_ret_flag) {
        flag = alloc_slots(g, 1);
        emit(g, SL_OP_MOV, flag, const_slot(g, 0), 0, 0);
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
        emit(g, SL_OP_ACCUM_END, f->cg_id, table, 0, SL_ESCAPE_FUNC);
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
    return str ? into_string(g, ret, dst) : into(g, ret, dst, size);
}

static int gen_expr(cg *g, sl_node *e, int dst)
{
    if (g->failed)
        return dst >= 0 ? dst : SL_GLOBAL_SLOTS;
    sl_pos saved = g->cur;
    g->cur = e->pos;
    int r = 0;
    switch (e->kind) {
    case SL_N_NUM: r = into(g, const_slot(g, e->num), dst, 1); break;
    case SL_N_STR: r = into_string(g, string_const(g, e->name, e->len), dst); break;
    case SL_N_IDENT: r = gen_ident(g, e, dst); break;
    case SL_N_CALL:
        if (e->func)
            r = gen_user_call(g, e, dst);
        else if (e->builtin && e->builtin->lower == SL_LOWER_SPLINE)
            r = gen_spline(g, e, dst);
        else if (e->builtin && e->builtin->lower == SL_LOWER_STRINGS)
            r = gen_strings(g, e, dst);
        else if (e->builtin && e->builtin->lower == SL_LOWER_TEXTURE)
            r = gen_texture(g, e, dst);
        else if (e->builtin)
            r = gen_builtin(g, e, dst);
        else if (strcmp(e->name, "arraylength") != 0 || e->list[0]->sym->cg_len_slot)
            r = gen_resizable(g, e, dst);
        else            /* arraylength(a) of a fixed-size array */
            r = into(g, const_slot(g, array_len(e->list[0]->sym)), dst, 1);
        break;
    case SL_N_INDEX: r = gen_index(g, e, dst); break;
    case SL_N_ARRAYINIT: r = gen_array_init(g, e, dst); break;
    case SL_N_UNARY: r = gen_unary(g, e, dst); break;
    case SL_N_BINARY: r = gen_binary(g, e, dst); break;
    case SL_N_COND: r = gen_cond_expr(g, e, dst); break;
    case SL_N_ASSIGN: r = gen_assign(g, e, dst); break;
    case SL_N_CAST: r = gen_cast(g, e, dst); break;
    case SL_N_CONV: r = gen_conv(g, e, dst); break;
    default: fail(g, "internal error: unexpected expression"); break;
    }
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

typedef struct list_job {
    sl_node **list;
    int from, n;
} list_job;

static void gen_list(cg *g, sl_node **list, int from, int n);

static void gen_list_job(cg *g, void *arg)
{
    list_job *job = arg;
    gen_list(g, job->list, job->from, job->n);
}

/* Statements list[from..n), the rest guarded after one that may escape. */
static void gen_list(cg *g, sl_node **list, int from, int n)
{
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
        list_job job = { list, i + 1, n };
        gen_branches(g, go, gen_list_job, &job, NULL, NULL);
        return;
    }
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
            s->slot = alloc_string(g);
            int mark = g->sp;
            into_string(g, v->a ? gen_expr(g, v->a, -1) : string_const(g, "", 0), s->slot);
            g->sp = mark;
            continue;
        }
        int size = sl_ty_slots(s->ty);
        s->slot = alloc_slots(g, size);
        if (v->a) {
            gen_expr(g, v->a, s->slot);
        } else {
            for (int k = 0; k < size; k++)
                emit(g, SL_OP_MOV, s->slot + k, const_slot(g, 0), 0, 0);
        }
        g->sp = s->slot + size;
        if (s->resizable) {       /* its length, after the elements */
            s->cg_len_slot = alloc_slots(g, 1);
            emit(g, SL_OP_MOV, s->cg_len_slot, const_slot(g, 0), 0, 0);
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
    int c = gen_expr(g, n->a, -1);
    g->sp = mark;
    stmt_job a = { n->b }, b = { n->c };
    gen_branches(g, c, gen_stmt_job, &a, n->c ? gen_stmt_job : NULL, &b);
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
    int f = alloc_slots(g, 1);
    emit(g, SL_OP_MOV, f, const_slot(g, 0), 0, 0);
    return f;
}

/* while (cond) body, or for (; cond; step) body: loop is the node. */
static void gen_loop(cg *g, sl_node *loop, sl_node *cond, sl_node *step, sl_node *body)
{
    int saved_sp = g->sp;
    loop->cg_brk = has_escape(body, SL_ESC_BREAK, loop) ? new_flag(g) : -1;
    set_death(g, loop->cg_brk, true);
    loop->cg_cnt = has_escape(body, SL_ESC_CONTINUE, loop) ? alloc_slots(g, 1) : -1;
    int flags[64];
    int nflags = escape_flags(g, body, loop, flags);
    int mark = g->sp;
    region_begin(g);
    int top = here(g);
    g->cur = loop->pos;
    int c = cond ? gen_expr(g, cond, -1) : const_slot(g, 1);
    int go = none_set(g, flags, nflags);
    if (go >= 0)
        c = op2(g, SL_OP_AND, c, go);
    g->cur = loop->pos;
    int test = emit(g, SL_OP_LOOP_TEST, c, 0, 0, 0);
    loop->cg_test = test;
    g->sp = mark;
    if (loop->cg_cnt >= 0)
        emit(g, SL_OP_MOV, loop->cg_cnt, const_slot(g, 0), 0, 0);
    stmt_job job = { body };
    gen_stmt_job(g, &job);
    if (step) {
        if (nflags > 0) {
            int go2 = none_set(g, flags, nflags);
            g->sp = mark;
            stmt_job sj = { step };
            gen_branches(g, go2, gen_stmt_job, &sj, NULL, NULL);
        } else {
            gen_stmt_job(g, &(stmt_job){ step });
        }
    }
    g->cur = loop->pos;
    emit(g, SL_OP_JMP, top, 0, 0, 0);
    int end = emit(g, SL_OP_LOOP_END, test, 0, 0, 0);
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
                into_string(g, gen_expr(g, n->a, -1), f->cg_ret_slot);
            else
                gen_expr(g, n->a, f->cg_ret_slot);
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
    int mark = g->sp;
    switch (n->kind) {
    case SL_N_BLOCK: {
        int ssp = g->ssp;
        gen_list(g, n->list, 0, n->nlist);
        g->ssp = ssp;
        break;
    }
    case SL_N_DECL: gen_decl(g, n); return;
    case SL_N_EXPR: gen_expr(g, n->a, -1); break;
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
        emit(g, SL_OP_MOV, n->target->cg_cnt, const_slot(g, 1), 0, 0);
        break;
    case SL_N_RETURN: gen_return(g, n); break;
    default: break;
    }
    g->sp = mark;
}

/* ---------------------------------------------------------------------- */
/* the shader                                                              */
/* ---------------------------------------------------------------------- */

static void gen_params(cg *g)
{
    const sl_ast_file *f = g->file;
    sl_program *p = g->prog;
    p->params = sl_xrealloc(NULL, (size_t)(f->nparams + 1) * sizeof *p->params);
    p->nparams = f->nparams;
    for (int i = 0; i < f->nparams; i++) {
        sl_node *v = f->params[i];
        sl_sym *s = v->sym;
        sl_param *pp = &p->params[i];
        pp->name = sl_xstrndup(s->name, strlen(s->name));
        pp->type = (sl_type)sl_ty_elem(s->ty);     /* arrays: the element type */
        pp->output = s->output;
        pp->size = sl_ty_slots(s->ty);
        g->cur = v->pos;
        bool str = s->ty == SL_TYPE_STRING;
        s->slot = str ? alloc_string(g) : alloc_slots(g, pp->size);
        pp->slot = s->slot;
        /* a constant default (a number or a string) travels in operand d:
         * one instruction per parameter */
        int k = -1;
        if (!v->a)
            k = str ? string_const(g, "", 0) : pp->size == 1 ? const_slot(g, 0) : -1;
        else if (v->a->kind == SL_N_NUM)
            k = const_slot(g, v->a->num);
        else if (v->a->kind == SL_N_STR)
            k = string_const(g, v->a->name, v->a->len);
        int at = emit(g, str ? SL_OP_SPARAM : SL_OP_PARAM, s->slot, i, 0, k < 0 ? 0 : k);
        int mark = g->sp;
        if (k >= 0)
            ;
        else if (v->a)
            gen_expr(g, v->a, s->slot);
        else
            for (int c = 0; c < pp->size; c++)
                emit(g, SL_OP_MOV, s->slot + c, const_slot(g, 0), 0, 0);
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
        fail(g, "shader needs more than %d registers (the limit per shader)", SL_MAX_SLOTS);
}

static unsigned long next_serial(void)
{
    static atomic_ulong serial;
    return atomic_fetch_add(&serial, 1) + 1;
}

sl_program *sl_codegen(const sl_ast_file *file, sl_diag *diag)
{
    cg g = { .file = file, .diag = diag };
    g.prog = sl_xrealloc(NULL, sizeof *g.prog);
    memset(g.prog, 0, sizeof *g.prog);
    sl_program *p = g.prog;
    p->name = sl_xstrndup(file->name, strlen(file->name));
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
        emit(&g, SL_OP_ACCUM_END, 0, table, 0, SL_ESCAPE_FUNC);
        patch_escapes(&g, SL_ESCAPE_FUNC, 0, table);
    }
    g.cur = file->pos;
    emit(&g, SL_OP_END, 0, 0, 0, 0);
    fix_constants(&g);
    free(g.regions);
    free(g.escapes);
    if (g.failed) {
        sl_program_free(p);
        return NULL;
    }
    return p;
}

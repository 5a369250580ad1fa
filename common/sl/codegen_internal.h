/*
 * codegen_internal.h: what codegen.c (expressions, statements, slots,
 * regions) and codegen_builtin.c (calls of built-in functions) share: the
 * generator's state and the helpers both sides emit code with. Private to
 * the code generator; the public interface is codegen.h.
 */
#ifndef SL_CODEGEN_INTERNAL_H
#define SL_CODEGEN_INTERNAL_H

#include "sl/codegen.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

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
    int depth;                           /* nesting of gen_stmt / cg_gen_expr */
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

/* codegen.c: diagnostics and slots */
void cg_fail(cg *g, const char *fmt, ...) SL_PRINTF(2, 3);
int cg_alloc_slots(cg *g, int n);
int cg_alloc_string(cg *g);
int cg_const_slot(cg *g, double value);
int cg_string_const(cg *g, const char *text, size_t len);
void cg_record_write(cg *g, int slot, int n);
void cg_record_string_write(cg *g, int slot);

/* codegen.c: emitting */
int cg_emit(cg *g, sl_opcode op, int a, int b, int c, int d);
void cg_emit_mov(cg *g, int dst, int src, int n);
int cg_into(cg *g, int src, int dst, int n);
int cg_into_string(cg *g, int src, int dst);
int cg_lane_safe(int dst, int n, const int *args, const int *sizes, int k);

static inline int cg_target(cg *g, int dst, int n) { return dst >= 0 ? dst : cg_alloc_slots(g, n); }

/* Lane i of a value of n slots (a float broadcasts). */
static inline int cg_lane(int slot, int n, int i) { return n == 1 ? slot : slot + i; }

static inline int cg_size_of(const sl_node *e) { return sl_ty_slots(e->ty); }

/* codegen.c: expressions */
int cg_op1(cg *g, sl_opcode op, int x);
int cg_op2(cg *g, sl_opcode op, int x, int y);
int cg_gen_dot(cg *g, int x, int y, int n, int dst);
int cg_gen_matmul(cg *g, int a, int b, int dst);
int cg_gen_cross(cg *g, int a, int b, int dst);
int cg_array_len(const sl_sym *s);
int cg_array_operand(int len, int stride);
int cg_gen_space_xform(cg *g, sl_opcode op, sl_node *space, int dir, int x, int dst);
int cg_gen_expr(cg *g, sl_node *e, int dst);

/* BR_BEGIN cond ... BR_ELSE ... BR_END around two generators. */
typedef void (*branch_fn)(cg *g, void *arg);
void cg_gen_branches(cg *g, int cond, branch_fn then_fn, void *then_arg,
                     branch_fn else_fn, void *else_arg);

/* codegen_builtin.c: calls of built-in functions */
int cg_gen_builtin(cg *g, sl_node *e, int dst);
int cg_gen_color_space(cg *g, int space, int x, bool from);
int cg_gen_strings(cg *g, sl_node *e, int dst);
int cg_gen_texture(cg *g, sl_node *e, int dst);
int cg_gen_spline(cg *g, sl_node *e, int dst);

#endif

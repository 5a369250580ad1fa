/*
 * ast.h: the syntax tree of a shading-language source, as the parser
 * (parser.c) builds it, the checker (check.c) annotates it and the code
 * generator (codegen.c) lowers it to bytecode.
 *
 * One node type (sl_node) for expressions and statements: a kind, a source
 * position, up to four children and a list, plus the annotations the
 * checker adds (result type, resolved symbol / built-in / user function,
 * escape targets of statements). Nodes, symbols and functions live in an
 * arena (sl_arena) freed in one go after compiling; names point into the
 * lexer's interned strings, so the lexer outlives the tree.
 *
 * Types (sl_ty) are the public sl_type values plus two internal ones:
 * SL_TY_BOOL, the type of comparisons and logical operators (RenderMan's
 * "relation"), and SL_TY_ERROR, the type of an expression that already
 * produced an error (it silences follow-up errors: no cascades), and the
 * two types of untyped lists (below).
 */
#ifndef SL_AST_H
#define SL_AST_H

#include <stdbool.h>
#include <stddef.h>

#include "sl/arena.h"
#include "sl/diag.h"
#include "sl/shader.h"

/* ---- types ---- */

typedef int sl_ty;
enum { SL_TY_BOOL = SL_TYPE_MATRIX + 1, SL_TY_ERROR, SL_TY_LIST3, SL_TY_LIST16 };

/* SL_TY_LIST3 / SL_TY_LIST16: an untyped list `(x, y, z)` (16 values: a
 * matrix) whose type the context has not given yet; the checker retypes
 * it where it is assigned, passed or returned, or reports it. */
static inline bool sl_ty_is_list(sl_ty ty) { return ty == SL_TY_LIST3 || ty == SL_TY_LIST16; }

/* Arrays: a flag, the element type and the length (0: an unsized function
 * parameter `float a[]`, which takes the length of each argument). */
enum { SL_TY_ARRAY_FLAG = 1 << 24, SL_MAX_ARRAY_LEN = 4095 };
static inline sl_ty sl_ty_array(sl_ty elem, int len) { return SL_TY_ARRAY_FLAG | elem | (len << 8); }
static inline bool sl_ty_is_array(sl_ty ty) { return (ty & SL_TY_ARRAY_FLAG) != 0; }
static inline sl_ty sl_ty_elem(sl_ty ty) { return sl_ty_is_array(ty) ? (ty & 0xff) : ty; }
static inline int sl_ty_len(sl_ty ty) { return (ty >> 8) & 0xfff; }

const char *sl_ty_name(sl_ty ty);            /* "float", "point", "bool", "float[4]" */
int sl_ty_slots(sl_ty ty);                   /* scalar slots: 1, 3, 16, n * those; 0 */
bool sl_ty_is_triple(sl_ty ty);              /* point vector normal color */
bool sl_ty_is_spatial(sl_ty ty);             /* point vector normal */

/* ---- symbols and functions ---- */

typedef enum sl_sym_kind {
    SL_SYM_GLOBAL,      /* P, N, ... (renderer-supplied) */
    SL_SYM_CONST,       /* PI */
    SL_SYM_PARAM,       /* shader parameter */
    SL_SYM_LOCAL,       /* local variable */
    SL_SYM_FPARAM,      /* user function parameter */
} sl_sym_kind;

typedef struct sl_sym {
    const char *name;
    sl_ty ty;
    sl_sym_kind kind;
    sl_pos pos;
    bool output;        /* output parameter */
    bool writable;      /* may be assigned */
    bool warned;        /* checker: hidden from a nested function, said once */
    int global;         /* SL_SYM_GLOBAL: the sl_global */
    double value;       /* SL_SYM_CONST */
    int param_index;    /* SL_SYM_PARAM */
    int slot;           /* codegen: first slot (scalar or string file) */
    int cg_len;         /* codegen: the length bound to an unsized array parameter */
    bool resizable;     /* RSL 2: a local 'float a[];' (SL_RESIZABLE_CAPACITY) */
    int cg_len_slot;    /* codegen: the slot of a resizable array's length (0: none) */
} sl_sym;

/* RSL 2 resizable arrays (a local declared without size or initializer):
 * the elements they can hold; their length lives in a slot of its own. */
enum { SL_RESIZABLE_CAPACITY = 64 };
/* The call node's op for resize(a, n), reserve(a, n), push(a, v), pop(a). */
enum { SL_RESIZE_RESIZE, SL_RESIZE_RESERVE, SL_RESIZE_PUSH, SL_RESIZE_POP };

typedef struct sl_node sl_node;

/* The parameters of a user function, and so the arguments of a call of
 * one (docs/shading-language.md, Limits): a checker error beyond it. */
enum { SL_MAX_FUNC_PARAMS = 255 };

typedef struct sl_func {
    const char *name;
    sl_ty ret;
    sl_pos pos;
    sl_sym **params;
    int nparams;
    sl_node *body;
    bool nested;                /* defined inside a function or the shader body */
    int depth;                  /* checker: block depth of a nested definition (0: file) */
    bool declared;              /* checker: nested, in scope (its overload group's first
                                   definition declares the whole group) */
    bool defined;               /* checker: its body has been checked */
    /* checker */
    struct sl_func **calls;     /* user functions called, for the recursion check */
    int ncalls, calls_cap;
    int mark;                   /* DFS state */
    bool needs_ret_flag;        /* a return that is not the last statement */
    /* codegen: the inlined call being generated */
    int cg_ret_slot, cg_ret_flag, cg_id;
} sl_func;

/* ---- nodes ---- */

typedef enum sl_node_kind {
    /* expressions */
    SL_N_NUM,        /* num */
    SL_N_STR,        /* name/len: the string */
    SL_N_IDENT,      /* name; sym */
    SL_N_CALL,       /* name, list: args; builtin or func */
    SL_N_UNARY,      /* op ('-' or '!'), a */
    SL_N_BINARY,     /* op, a, b */
    SL_N_COND,       /* a ? b : c */
    SL_N_ASSIGN,     /* op (= += -= *= /=), a (lvalue), b */
    SL_N_CAST,       /* cast_ty, name: space or NULL, list: 1, 3 or 16 values;
                        cast_ty SL_TYPE_VOID: an untyped list (x, y, z) */
    SL_N_CONV,       /* implicit conversion of a to ty (checker) */
    SL_N_INDEX,      /* a[b]: a the array (an SL_N_IDENT), b the index */
    SL_N_ARRAYINIT,  /* { list }: the initializer of an array */
    SL_N_ERROR,      /* an expression that failed to parse (already reported) */
    /* statements */
    SL_N_BLOCK,      /* list */
    SL_N_DECL,       /* list of SL_N_VAR */
    SL_N_VAR,        /* sym, a: initializer or NULL */
    SL_N_EXPR,       /* a */
    SL_N_IF,         /* a: cond, b: then, c: else or NULL */
    SL_N_WHILE,      /* a: cond, b: body */
    SL_N_FOR,        /* a: init or NULL, b: cond or NULL, c: step or NULL, d: body */
    SL_N_BREAK,      /* num: levels; target: the loop */
    SL_N_CONTINUE,   /* num: levels; target: the loop */
    SL_N_RETURN,     /* a: value or NULL; func: the function (NULL: shader) */
    SL_N_EMPTY,
    SL_N_FUNC,       /* a nested function definition: func (no code of its own) */
} sl_node_kind;

/* A statement's escape: a break/continue/return inside it that leaves it. */
typedef enum sl_escape_kind { SL_ESC_BREAK, SL_ESC_CONTINUE, SL_ESC_RETURN } sl_escape_kind;
typedef struct sl_escape {
    sl_escape_kind kind;
    sl_node *loop;       /* BREAK/CONTINUE: the target loop */
    sl_func *func;       /* RETURN: the function (NULL: the shader body) */
} sl_escape;

struct sl_node {
    sl_node_kind kind;
    sl_pos pos;
    sl_ty ty;                   /* checker: type of an expression */
    int op;                     /* operator token kind */
    double num;
    const char *name;
    size_t len;
    sl_ty cast_ty;              /* SL_N_CAST */
    sl_node *a, *b, *c, *d;
    sl_node **list;
    int nlist;
    /* checker annotations */
    sl_sym *sym;
    const struct sl_builtin *builtin;
    sl_func *func;
    sl_node *target;
    sl_escape *escapes;
    int nescapes;
    bool tail;                  /* SL_N_RETURN: last statement of its function */
    /* codegen scratch for loops: flag slots (-1: none), pc of LOOP_TEST */
    int cg_brk, cg_cnt, cg_test;
};

/* A parsed source: the user functions and the one shader. */
typedef struct sl_ast_file {
    sl_func **funcs;
    int nfuncs;
    bool has_shader;
    sl_shader_kind kind;
    const char *name;
    sl_pos pos;
    sl_node **params;           /* SL_N_VAR nodes (sym->kind SL_SYM_PARAM) */
    int nparams;
    sl_node *body;
    bool needs_ret_flag;        /* checker: a 'return' before the body's end */
} sl_ast_file;

sl_node *sl_node_new(sl_arena *arena, sl_node_kind kind, sl_pos pos);

/* The left spine of a chain of binary operators. `a + b + c` parses as
 * `(a + b) + c`, so a chain of n terms is a tree n deep along `a`; the
 * parser builds it with a loop, and every later pass walks it with a loop
 * over the spine instead of recursing along `a` (the other edges of the
 * tree are bounded by SL_PARSE_MAX_DEPTH: docs/shading-language.md,
 * Limits). v[0] is the node given, v[i + 1] is v[i]->a, and v[n - 1]->a
 * is not an SL_N_BINARY. Chains up to SL_SPINE_INLINE long need no heap. */
enum { SL_SPINE_INLINE = 16 };
typedef struct sl_spine {
    sl_node **v;
    int n, cap;
    sl_node *inline_v[SL_SPINE_INLINE];
} sl_spine;

/* Fills *s (not initialised before) with the spine under n (an SL_N_BINARY);
 * the struct must not be copied while in use. */
void sl_spine_collect(sl_spine *s, sl_node *n);
void sl_spine_clear(sl_spine *s);
/* Appends to a growing pointer array kept in the arena. */
void sl_list_push(sl_arena *arena, void ***list, int *n, int *cap, void *item);

#endif

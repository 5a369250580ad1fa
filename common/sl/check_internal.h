/*
 * check_internal.h: what check.c (scopes, conversions, expressions,
 * statements, functions) and check_call.c (calls) share: the checker's
 * state and its helpers. Private to the checker; the public interface is
 * check.h.
 */
#ifndef SL_CHECK_INTERNAL_H
#define SL_CHECK_INTERNAL_H

#include "sl/check.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct checker {
    sl_arena *arena;
    sl_diag *diag;
    sl_ast_file *file;
    sl_sym *globals[SL_G__COUNT];
    sl_sym *pi;
    sl_sym *ncomps, *dtime;   /* RI Spec 3.2 §13: 3 color components; no motion blur */
    sl_sym **syms;                 /* scope stack */
    int nsyms, syms_cap;
    int scope_start;               /* first sym of the innermost scope */
    int func_base;                 /* first sym of the current function */
    sl_func **vfuncs;              /* nested functions in scope, innermost last */
    int nvfuncs, vfuncs_cap;
    int vfuncs_start;              /* first of the innermost scope */
    int depth;                     /* block depth */
    int *fhead, *fnext;            /* file-level functions by name: a hash
                                      table of chains in file order (fhead:
                                      index + 1 of a chain's first, 0: none) */
    unsigned fmask;                /* fhead's size - 1 */
    sl_func **allfuncs;            /* every function, nested ones too */
    int nallfuncs, allfuncs_cap;
    sl_func *func;                 /* function being checked (NULL: shader) */
    sl_node **loops;
    int nloops, loops_cap;
    uint64_t ignored_warned;       /* optional texture()/shadow() parameters
                                      warned about (check_call.c, warn_ignored) */
} checker;

enum { MAX_OVERLOADS = 32 };

/* check.c */
void ck_error(checker *c, sl_pos pos, const char *fmt, ...) SL_PRINTF(3, 4);
sl_sym *ck_lookup(checker *c, const char *name);
int ck_find_funcs(checker *c, const char *name, sl_func **out, int max);
void ck_func_signature(const sl_func *f, char *buf, size_t size);
bool ck_can_convert(sl_ty have, sl_ty want);
void ck_wrap_conv(checker *c, sl_node **np, sl_ty want);
sl_ty ck_set_ty(sl_node *n, sl_ty ty);
sl_ty ck_check_ident(checker *c, sl_node *n);
bool ck_check_assignable(checker *c, sl_node *lhs, const char *what);
sl_ty ck_check_expr(checker *c, sl_node **np, sl_ty hint);

/* check_call.c: a call of a built-in or user function */
sl_ty ck_check_call(checker *c, sl_node *n, sl_ty hint);

#endif

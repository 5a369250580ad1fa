/*
 * ast.c: node construction and the small facts about types (names, slot
 * counts) that every stage shares. The tree lives in an sl_arena (arena.c).
 */
#include "sl/ast.h"
#include "sl/strbuf.h"

#include "util/xalloc.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------- */
/* types                                                                   */
/* ---------------------------------------------------------------------- */

const char *sl_ty_name(sl_ty ty)
{
    if (sl_ty_is_array(ty)) {       /* "float[4]", "color[]": a few per thread */
        static _Thread_local char names[4][32];
        static _Thread_local int next;
        char *buf = names[next++ % 4];
        int len = sl_ty_len(ty);
        if (len)
            snprintf(buf, sizeof names[0], "%s[%d]", sl_ty_name(sl_ty_elem(ty)), len);
        else
            snprintf(buf, sizeof names[0], "%s[]", sl_ty_name(sl_ty_elem(ty)));
        return buf;
    }
    switch (ty) {
    case SL_TYPE_VOID: return "void";
    case SL_TYPE_FLOAT: return "float";
    case SL_TYPE_POINT: return "point";
    case SL_TYPE_VECTOR: return "vector";
    case SL_TYPE_NORMAL: return "normal";
    case SL_TYPE_COLOR: return "color";
    case SL_TYPE_STRING: return "string";
    case SL_TYPE_MATRIX: return "matrix";
    case SL_TY_BOOL: return "bool";
    case SL_TY_LIST3: return "untyped triple";
    case SL_TY_LIST16: return "untyped 16-tuple";
    default: return "<error>";
    }
}

int sl_ty_slots(sl_ty ty)
{
    if (sl_ty_is_array(ty))
        return sl_ty_len(ty) * sl_ty_slots(sl_ty_elem(ty));
    switch (ty) {
    case SL_TYPE_FLOAT: case SL_TY_BOOL: case SL_TYPE_STRING: return 1;
    case SL_TYPE_POINT: case SL_TYPE_VECTOR: case SL_TYPE_NORMAL:
    case SL_TYPE_COLOR: case SL_TY_LIST3: return 3;
    case SL_TYPE_MATRIX: case SL_TY_LIST16: return 16;
    default: return 0;
    }
}

bool sl_ty_is_triple(sl_ty ty)
{
    return ty == SL_TYPE_POINT || ty == SL_TYPE_VECTOR || ty == SL_TYPE_NORMAL ||
           ty == SL_TYPE_COLOR;
}

bool sl_ty_is_spatial(sl_ty ty)
{
    return ty == SL_TYPE_POINT || ty == SL_TYPE_VECTOR || ty == SL_TYPE_NORMAL;
}

/* ---------------------------------------------------------------------- */
/* nodes                                                                   */
/* ---------------------------------------------------------------------- */

sl_node *sl_node_new(sl_arena *arena, sl_node_kind kind, sl_pos pos)
{
    sl_node *n = sl_arena_alloc(arena, sizeof *n);
    n->kind = kind;
    n->pos = pos;
    n->ty = SL_TYPE_VOID;
    n->cg_brk = n->cg_cnt = -1;
    return n;
}

void sl_list_push(sl_arena *arena, void ***list, int *n, int *cap, void *item)
{
    if (*n == *cap) {
        int ncap = *cap ? *cap * 2 : 4;
        void **grown = sl_arena_alloc(arena, (size_t)ncap * sizeof *grown);
        if (*n)
            memcpy(grown, *list, (size_t)*n * sizeof *grown);
        *list = grown;
        *cap = ncap;
    }
    (*list)[(*n)++] = item;
}

void sl_spine_collect(sl_spine *s, sl_node *n)
{
    assert(n && n->kind == SL_N_BINARY);
    s->v = s->inline_v;
    s->n = 0;
    s->cap = SL_SPINE_INLINE;
    for (; n->kind == SL_N_BINARY; n = n->a) {
        if (s->n == s->cap) {
            s->cap *= 2;
            if (s->v == s->inline_v) {
                s->v = xreallocarray(NULL, (size_t)s->cap, sizeof *s->v);
                memcpy(s->v, s->inline_v, sizeof s->inline_v);
            } else {
                s->v = xreallocarray(s->v, (size_t)s->cap, sizeof *s->v);
            }
        }
        s->v[s->n++] = n;
    }
}

void sl_spine_clear(sl_spine *s)
{
    if (s->v != s->inline_v)
        free(s->v);
    memset(s, 0, sizeof *s);
}

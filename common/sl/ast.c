/*
 * ast.c: the arena the syntax tree lives in, node construction and the
 * small facts about types (names, slot counts) that every stage shares.
 */
#include "sl/ast.h"
#include "sl/strbuf.h"

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
/* arena: a list of chunks, each allocation zeroed                         */
/* ---------------------------------------------------------------------- */

typedef struct chunk {
    struct chunk *next;
    size_t used, size;
    max_align_t data[];
} chunk;

struct sl_arena {
    chunk *head;
};

enum { CHUNK_SIZE = 64 * 1024 };

sl_arena *sl_arena_new(void)
{
    sl_arena *self = sl_xrealloc(NULL, sizeof *self);
    self->head = NULL;
    return self;
}

void sl_arena_destroy(sl_arena **self_p)
{
    if (!*self_p)
        return;
    chunk *c = (*self_p)->head;
    while (c) {
        chunk *next = c->next;
        free(c);
        c = next;
    }
    free(*self_p);
    *self_p = NULL;
}

void *sl_arena_alloc(sl_arena *self, size_t size)
{
    size_t align = sizeof(max_align_t);
    size = (size + align - 1) / align * align;
    chunk *c = self->head;
    if (!c || c->used + size > c->size) {
        size_t cap = size > CHUNK_SIZE ? size : CHUNK_SIZE;
        c = sl_xrealloc(NULL, sizeof *c + cap);
        c->used = 0;
        c->size = cap;
        c->next = self->head;
        self->head = c;
    }
    void *p = (char *)c->data + c->used;
    c->used += size;
    memset(p, 0, size);
    return p;
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

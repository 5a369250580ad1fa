/*
 * normal_memo.c: the camera-space unit normal of a displaced surface's
 * base over a (u,v) box (normal_memo.h), remembered per thread.
 *
 * A box run binds N = the base's unit normal moved to camera space
 * (geom_unit_normal_aa, then trace_camera_normal_aa), which for a bilinear
 * patch is normalize(Ng) in affine arithmetic. On a planar patch (a height
 * field's base, a flat quad) Ng carries no noise symbol and is the same in
 * every box, and so is N, as on a flat polygon (a mesh face); the memo
 * keeps, per object slot (16, by the object's id), the last such Ng and
 * object transform and the N they gave.
 *
 * Same bits by construction, as the VM's uniform memo (vm_uniform.inc):
 * the computation reads Ng, the object's from_camera, flip, normal_scale
 * and normal_len2 (all of them key the entry, compared bit for bit), and
 * the context only where it takes a noise symbol or folds an error for
 * lack of one, which a kept result did not (it is also symbol-free). Only
 * bilinear patches (normalize(Ng)) and polygons without vertex normals
 * (Ng's range normalised): other kinds' normals read u, v, P or the
 * vertex normals too.
 */
#include "trace/normal_memo.h"
#include "trace/displace.h"
#include "util/xalloc.h"

#include <stdlib.h>
#include <string.h>

enum { NORMAL_MEMO_LOG2 = 4, NORMAL_MEMO_ENTRIES = 1 << NORMAL_MEMO_LOG2 };

typedef struct normal_entry {
    bool valid;
    aa_form Ng[3];                 /* symbol-free: only the fields before c */
    mat4 from_camera;
    bool flip;
    double normal_scale, normal_len2[2];
    aa_form N[3];                  /* symbol-free */
} normal_entry;

struct trace_normal_memo {
    normal_entry e[NORMAL_MEMO_ENTRIES];
};

static bool symbol_free(const aa_form f[3])
{
    return f[0].n == 0 && f[1].n == 0 && f[2].n == 0;
}

static bool same_bits(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }

/* a symbol-free form's fields, bit for bit (the coefficients past n are
 * stale by design, so never compared) */
static bool same_free_form(const aa_form *a, const aa_form *b)
{
    return a->n == 0 && b->n == 0 && a->flags == b->flags && same_bits(&a->x0, &b->x0, 8) &&
           same_bits(&a->err, &b->err, 8) && same_bits(&a->lo, &b->lo, 8) &&
           same_bits(&a->hi, &b->hi, 8);
}

static bool entry_is(const normal_entry *e, const trace_object *obj, const aa_form Ng[3])
{
    return e->valid && same_free_form(&e->Ng[0], &Ng[0]) && same_free_form(&e->Ng[1], &Ng[1]) &&
           same_free_form(&e->Ng[2], &Ng[2]) && e->flip == obj->flip &&
           same_bits(&e->from_camera, &obj->from_camera, sizeof e->from_camera) &&
           same_bits(&e->normal_scale, &obj->normal_scale, sizeof e->normal_scale) &&
           same_bits(e->normal_len2, obj->normal_len2, sizeof e->normal_len2);
}

void trace_camera_unit_normal_aa(trace_thread *th, const trace_object *obj, const aa_form *u,
                                 const aa_form *v, const geom_aa *g, aa_form N[3])
{
    aa_context *ctx = &th->ctx;
    normal_entry *e = NULL;
    bool pure = obj->surf.kind == GEOM_PATCH ||
                (obj->surf.kind == GEOM_POLYGON && !geom_has_vertex_normals(&obj->surf));
    if (pure && symbol_free(g->Ng)) {
        if (!th->normals)
            th->normals = xcalloc(1, sizeof *th->normals);
        e = &th->normals->e[(unsigned)obj->id & (NORMAL_MEMO_ENTRIES - 1)];
        if (entry_is(e, obj, g->Ng)) {
            memcpy(N, e->N, 3 * sizeof N[0]);
            th->stats.normal_hits++;
            return;
        }
    }
    int used = ctx->used;
    long folded = ctx->folded;
    aa_form Nn[3];
    geom_unit_normal_aa(ctx, &obj->surf, u, v, g, Nn);
    trace_camera_normal_aa(ctx, obj, Nn, N);
    if (e && ctx->used == used && ctx->folded == folded && symbol_free(N)) {
        memcpy(e->Ng, g->Ng, sizeof e->Ng);
        e->from_camera = obj->from_camera;
        e->flip = obj->flip;
        e->normal_scale = obj->normal_scale;
        memcpy(e->normal_len2, obj->normal_len2, sizeof e->normal_len2);
        memcpy(e->N, N, sizeof e->N);
        e->valid = true;
    }
}

void trace_normal_memo_free(trace_thread *th)
{
    free(th->normals);
    th->normals = NULL;
}

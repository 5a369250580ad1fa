/*
 * mesh.c: mesh objects, their pieces' BVH and the views of pieces (see
 * mesh.h).
 *
 * The BVH over a mesh's pieces is built once per world (trace_renderer_new,
 * over build_threads threads; a displaced mesh's boxes from regions of the
 * tree, its pieces' root boxes made when a ray first reaches them: see
 * "a displaced mesh's boxes" below) and shared by all threads: binned
 * surface-area heuristic
 * over the pieces' box centres (Wald, "On fast construction of SAH-based
 * bounding volume hierarchies", 2007: 12 bins along the axis where the
 * centres spread most, O(n log n)), a leaf holding up to LEAF_MAX pieces,
 * 32-byte nodes of float boxes rounded outward, in the mesh's object space.
 * A piece's own box is kept in 6 bytes, each coordinate one step of a
 * 255-step grid over its leaf's box, rounded outward (the quantized leaf
 * boxes of compressed BVHs: Mahovsky, "Ray tracing with reduced-precision
 * bounding volume hierarchies", 2005; Ylitie et al., "Efficient incoherent
 * ray traversal on GPUs through compressed wide BVHs", 2017), so the
 * pieces' float boxes are freed once the tree is built.
 * Traversal visits the nearer child first and skips what lies beyond the
 * best hit, as the object BVH (bvh.c).
 */
#include "trace/mesh.h"

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "trace/displace.h"
#include "trace/instance.h"
#include "trace/lazy_roots.h"
#include "trace/region.h"
#include "util/xalloc.h"

/* ---- views ---------------------------------------------------------- */

/* 2-way set-associative: a view goes to one of the two slots of its set,
 * the older of the two making room. Pieces and placements have a cache
 * each: a placement's view stays put while its pieces' views are made. */
enum { PIECE_SETS = 128, PLACE_SETS = 32 };

typedef struct view_cache {
    int sets;
    trace_view *slot;                  /* 2 * sets */
    int64_t *key;                      /* the view's object id and element; -1: empty */
    int32_t *place;                    /* and its object's placement (trace_object.place) */
    unsigned char *older;              /* per set: the slot to replace next (0, 1) */
} view_cache;

typedef struct trace_views {
    view_cache cache[2];               /* trace_view_kind */
    trace_view hit;                    /* the hit a traversal returns */
    trace_view hit_proto;              /* its box_proto, when that is a moved
                                          placement's prototype piece */
    trace_view *held[TRACE_RAY_DEPTH_LIMIT + 1];   /* hits being shaded, per depth */
    trace_view *held_proto[TRACE_RAY_DEPTH_LIMIT + 1];   /* and their box_proto */
} trace_views;

void trace_object_camera_bound(const trace_object *obj, const trace_box *b, trace_box *out)
{
    out->bend = 0.0f;
    trace_box_no_slab(out);
    if (b->flags & AA_UNBOUNDED || !isfinite(b->lo.x + b->lo.y + b->lo.z + b->hi.x + b->hi.y + b->hi.z)) {
        out->lo = v3(-INFINITY, -INFINITY, -INFINITY);
        out->hi = v3(INFINITY, INFINITY, INFINITY);
        out->flags = AA_UNBOUNDED;
        return;
    }
    out->flags = b->flags;
    for (int i = 0; i < 8; i++) {
        vec3 c = v3((i & 1) ? b->hi.x : b->lo.x, (i & 2) ? b->hi.y : b->lo.y,
                    (i & 4) ? b->hi.z : b->lo.z);
        vec3 p = mat4_xform_point(&obj->to_camera, c);
        if (i == 0) { out->lo = out->hi = p; continue; }
        out->lo = v3(fmin(out->lo.x, p.x), fmin(out->lo.y, p.y), fmin(out->lo.z, p.z));
        out->hi = v3(fmax(out->hi.x, p.x), fmax(out->hi.y, p.y), fmax(out->hi.z, p.z));
    }
    /* the corner transform rounds: widen by a relative hair */
    vec3 e = v3_scale(v3(fabs(out->hi.x) + fabs(out->lo.x), fabs(out->hi.y) + fabs(out->lo.y),
                         fabs(out->hi.z) + fabs(out->lo.z)), 1e-12);
    out->lo = v3_sub(out->lo, e);
    out->hi = v3_add(out->hi, e);
}

/* trace_mesh_view_make, computing du and dv only where they matter (grid:
 * a view that rays will shade; always for a displaced piece, whose
 * shader reads them), not for an undisplaced piece's bounds alone */
static bool make(trace_thread *th, const trace_object *mesh_obj, int k, bool boxes,
                 bool grid, trace_view *out);

bool trace_mesh_view_make(trace_thread *th, const trace_object *mesh_obj, int k, bool boxes,
                          trace_view *out)
{
    return make(th, mesh_obj, k, boxes, true, out);
}

static bool make(trace_thread *th, const trace_object *mesh_obj, int k, bool boxes,
                 bool grid, trace_view *out)
{
    const trace_mesh *m = mesh_obj->mesh;
    assert(m && k >= 0 && k < m->npieces);
    trace_object *v = &out->obj;
    *v = *mesh_obj;
    v->mesh = NULL;
    /* a moved placement's box_proto is its prototype mesh, no piece's
     * (trace_view_hit_moved gives its piece the prototype's piece) */
    v->box_proto = NULL;
    v->id = m->first_id + k;
    v->top = mesh_obj->id;
    v->primvars = out->pv;
    assert(m->nprimvars <= TRACE_MAX_PRIMVARS);
    if (!m->piece(m->user, mesh_obj, k, &v->surf, out->pv, &v->nprimvars)) {
        trace_thread_fail(th, "a mesh piece could not be made again (internal error)");
        return false;
    }
    v->shared_edges = trace_mesh_shared_edges(m, k);
    double dudv[2];
    trace_box held;                    /* its root box when the store holds it */
    bool known = m->lazy && trace_lazy_root(m->lazy, k, &held, dudv);
    if (known) {
        v->du = dudv[0];               /* what a thread found first */
        v->dv = dudv[1];
    } else if (grid || (boxes && v->displacement)) {
        trace_object_grid_spacing(th->world, v);
    }
    if (boxes) {
        if (v->displacement && known) {
            v->root = held;
        } else if (v->displacement) {
            trace_surface_box(th, v, 0, 1, 0, 1, &v->root);
            /* a pure function of the piece: the first thread's is every
             * thread's (a failed or cancelled run is not one) */
            if (m->lazy && !th->failed &&
                trace_lazy_root_put(m->lazy, k, &v->root, v->du, v->dv))
                th->stats.lazy_roots++;
        } else {
            geom_bounds(&v->surf, &v->root.lo, &v->root.hi);
            v->root.flags = 0;
            v->root.bend = 0.0f;
            trace_box_no_slab(&v->root);
        }
        trace_object_camera_bound(v, &v->root, &v->bound);
    }
    return !th->failed;
}

const trace_object *trace_object_piece(trace_thread *th, const trace_object *obj, int k,
                                       trace_view *storage)
{
    if (!obj->mesh) {
        assert(k == 0);
        return obj;
    }
    return trace_mesh_view_make(th, obj, k, true, storage) ? &storage->obj : NULL;
}

void trace_view_copy(trace_view *dst, const trace_view *src)
{
    dst->obj = src->obj;
    int n = src->obj.nprimvars;
    if (n > 0) memcpy(dst->pv, src->pv, (size_t)n * sizeof *dst->pv);
    dst->obj.primvars = dst->pv;
}

static void cache_init(view_cache *c, int sets)
{
    assert(sets > 0 && (sets & (sets - 1)) == 0);
    c->sets = sets;
    c->slot = xmalloc(sizeof *c->slot * (size_t)(2 * sets));
    c->key = xmalloc(sizeof *c->key * (size_t)(2 * sets));
    c->place = xcalloc((size_t)(2 * sets), sizeof *c->place);
    c->older = xcalloc((size_t)sets, sizeof *c->older);
    for (int i = 0; i < 2 * sets; i++) c->key[i] = -1;
}

static void cache_free(view_cache *c)
{
    free(c->slot);
    free(c->key);
    free(c->place);
    free(c->older);
}

static trace_views *views_of(trace_thread *th)
{
    if (!th->views) {
        th->views = xcalloc(1, sizeof *th->views);
        cache_init(&th->views->cache[TRACE_VIEWS_PIECES], PIECE_SETS);
        cache_init(&th->views->cache[TRACE_VIEWS_PLACES], PLACE_SETS);
    }
    return th->views;
}

void trace_views_free(trace_thread *th)
{
    if (!th->views) return;
    for (int d = 0; d <= TRACE_RAY_DEPTH_LIMIT; d++) {
        free(th->views->held[d]);
        free(th->views->held_proto[d]);
    }
    for (int i = 0; i < 2; i++) cache_free(&th->views->cache[i]);
    free(th->views);
    th->views = NULL;
}

const trace_object *trace_view_get(trace_thread *th, trace_view_kind which, const trace_object *obj,
                                   int k, trace_view_make_fn make_view)
{
    view_cache *c = &views_of(th)->cache[which];
    /* the object and the element: objects sharing a mesh share its ids,
     * placements tell them apart */
    int64_t key = (int64_t)obj->id << 32 | (uint32_t)k;
    uint64_t h = ((uint64_t)key ^ (uint64_t)obj->place << 40) * 0x9e3779b97f4a7c15ull;
    unsigned set = (unsigned)(h >> 32) & (unsigned)(c->sets - 1);   /* sets: a power of 2 */
    th->stats.views_asked++;
    for (unsigned w = 0; w < 2; w++)
        if (c->key[2 * set + w] == key && c->place[2 * set + w] == obj->place) {
            c->older[set] = (unsigned char)(1 - w);
            return &c->slot[2 * set + w].obj;
        }
    unsigned s = 2 * set + c->older[set];
    c->key[s] = -1;
    if (!make_view(th, obj, k, &c->slot[s])) return NULL;
    c->key[s] = key;
    c->place[s] = obj->place;
    c->older[set] = (unsigned char)(1 - c->older[set]);
    th->stats.views_made++;
    return &c->slot[s].obj;
}

static bool make_piece(trace_thread *th, const trace_object *mesh_obj, int k, trace_view *out)
{
    return trace_mesh_view_make(th, mesh_obj, k, true, out);
}

const trace_object *trace_mesh_view(trace_thread *th, const trace_object *mesh_obj, int k)
{
    return trace_view_get(th, TRACE_VIEWS_PIECES, mesh_obj, k, make_piece);
}

void trace_view_hit(trace_thread *th, const trace_object *v, trace_hit *best)
{
    trace_view_copy(&th->views->hit, (const trace_view *)v);
    best->obj = &th->views->hit.obj;
}

bool trace_view_hit_moved(trace_thread *th, const trace_object *v, trace_hit *hit)
{
    trace_views *vs = views_of(th);
    assert(v->mesh && v->box_proto && hit->obj == &vs->hit.obj);
    const trace_mesh *m = v->mesh;
    trace_view_copy(&vs->hit_proto, &vs->hit);
    const trace_object *pp = &vs->hit_proto.obj;
    int k = pp->id - m->first_id;
    assert(k >= 0 && k < m->npieces);
    /* the placement's piece: no boxes of its own (box_proto's, whose
     * displacement runs with the prototype's du, dv), and its own du, dv
     * where its surface shader reads them (as a displaced surface's
     * placement view has: they follow its size on the screen) */
    if (!make(th, v, k, false, false, &vs->hit)) return false;
    trace_object *p = &vs->hit.obj;
    p->box_proto = pp;
    trace_instance_set_motion(p, pp);
    const sl_program *sp = p->surface ? sl_instance_program(p->surface) : NULL;
    if (sp && (sl_program_reads_global(sp, SL_G_du) || sl_program_reads_global(sp, SL_G_dv))) {
        trace_object_grid_spacing(th->world, p);
    } else {
        p->du = pp->du;                /* read by nothing */
        p->dv = pp->dv;
    }
    p->root = pp->root;                /* (no bound: a hit is not walked again) */
    if (hit->has_point) trace_surface_point_move(p, &hit->point);
    if (hit->kind == TRACE_LEAF_WALL)
        hit->wall_normal = v3_normalize(mat4_xform_vector(&p->from_proto, hit->wall_normal));
    hit->obj = p;
    return true;
}

const trace_object *trace_view_hold(trace_thread *th, const trace_object *obj, int depth)
{
    if (!th->views || obj != &th->views->hit.obj) return obj;
    assert(depth >= 0 && depth <= TRACE_RAY_DEPTH_LIMIT);
    trace_view **h = &th->views->held[depth];
    if (!*h) *h = xmalloc(sizeof **h);
    trace_view_copy(*h, &th->views->hit);
    if (obj->box_proto == &th->views->hit_proto.obj) {
        /* a moved placement's piece: its prototype's piece held too */
        trace_view **hp = &th->views->held_proto[depth];
        if (!*hp) *hp = xmalloc(sizeof **hp);
        trace_view_copy(*hp, &th->views->hit_proto);
        (*h)->obj.box_proto = &(*hp)->obj;
    }
    return &(*h)->obj;
}

/* ---- the pieces' BVH -------------------------------------------------- */

typedef struct mesh_node {
    float lo[3], hi[3];
    int32_t a;                         /* leaf: first of idx; interior: left child */
    int32_t n;                         /* leaf: pieces (> 0); interior: 0, right = a + 1 */
} mesh_node;

struct trace_mesh_bvh {
    mesh_node *nodes;
    int nnodes;
    int32_t *idx;
    uint8_t (*q)[6];                   /* per idx slot: its element's box on its leaf's grid */
};

/* LEAF_MAX: a leaf's elements are culled by their 6-byte boxes, so large
 * leaves cost little (1.5 % of a render of 100,000 instances against
 * leaves of 4) and save nodes: 0.17 nodes an element instead of 0.58. */
enum { LEAF_MAX = 16, BINS = 12, SAH_DEPTH = 40, MESH_STACK = 128, TASK_MAX = 8192 };

static double area_of(const float lo[3], const float hi[3])
{
    double e[3];
    for (int i = 0; i < 3; i++) e[i] = (double)hi[i] - lo[i];
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

/* lo, hi grown to hold b; a NaN of b is passed over (as fminf, fmaxf
 * would, for accumulators that start at +-infinity: never NaN) */
static inline void grow(float lo[3], float hi[3], const float b[6])
{
    for (int i = 0; i < 3; i++) {
        lo[i] = b[i] < lo[i] ? b[i] : lo[i];
        hi[i] = b[3 + i] > hi[i] ? b[3 + i] : hi[i];
    }
}

static double centre(const float b[6], int axis)
{
    double c = 0.5 * ((double)b[axis] + b[3 + axis]);
    return isfinite(c) ? c : 0.0;
}

/* A subtree built apart (on any of the build's threads) into its own
 * nodes, joined to the tree afterwards: which subtrees are tasks depends
 * on the tree alone (TASK_MAX), never on the thread count, so the tree is
 * the same for any count. */
typedef struct bvh_task {
    int id, first, count, depth;       /* its root's node, its elements, its depth */
    float box[6];                      /* its root's box */
    float cbox[6];                     /* and its elements' centres' range (lo, hi) */
    bool has_cbox;
    mesh_node *nodes;                  /* the subtree, its root first */
    int nnodes;
} bvh_task;

typedef struct build_ctx {
    const float (*bounds)[6];
    float (*centres)[3];               /* each piece's box centre (0 where not finite) */
    struct trace_mesh_bvh *bvh;
    bvh_task *tasks;                   /* subtrees left to build (NULL: build them here) */
    int ntasks, cap;
} build_ctx;

typedef struct sah_bin {
    float lo[3], hi[3];
    int n;
} sah_bin;

static int bin_of(float x, float lo, float scale)
{
    int b = (int)((x - lo) * scale);
    return b < 0 ? 0 : b >= BINS ? BINS - 1 : b;
}

/* the SAH split of idx[first, first + count): the pieces are binned by
 * their centres along the axis where the centres spread most; false when
 * no split beats the leaf */
/* lo[0..3), hi[0..3) grown to hold point x (finite: compares, not
 * fminf/fmaxf; which zero an end of a centres' range is changes no bin,
 * scale or axis in sah_split, so neither does the order of the points) */
static inline void grow_point(float lo[3], float hi[3], const float x[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = x[a] < lo[a] ? x[a] : lo[a];
        hi[a] = x[a] > hi[a] ? x[a] : hi[a];
    }
}

/* cbox: the range of the elements' centres when the parent's split made
 * it (NULL: made here); lc, rc: the two sides' ranges, made while the
 * elements are parted (for the children's splits: a pass less each) */
static bool sah_split(build_ctx *c, int first, int count, double parent_area, int *mid,
                      float left[6], float right[6], const float *cbox, float lc[6], float rc[6])
{
    int32_t *idx = c->bvh->idx + first;
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (cbox) {
        memcpy(clo, cbox, sizeof clo);
        memcpy(chi, cbox + 3, sizeof chi);
    } else {
        for (int i = 0; i < count; i++) grow_point(clo, chi, c->centres[idx[i]]);
    }
    float scale[3];
    sah_bin bins[3][BINS];
    int wide = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[wide] - clo[wide]) wide = a;
    for (int a = 0; a < 3; a++) {
        scale[a] = a == wide && chi[a] > clo[a] ? (float)BINS / (chi[a] - clo[a]) : 0.0f;
        for (int b = 0; b < BINS; b++) {
            sah_bin *bn = &bins[a][b];
            bn->n = 0;
            for (int i = 0; i < 3; i++) bn->lo[i] = INFINITY, bn->hi[i] = -INFINITY;
        }
    }
    for (int i = 0; i < count; i++) {
        const float *x = c->centres[idx[i]], *bb = c->bounds[idx[i]];
        for (int a = 0; a < 3; a++) {
            if (scale[a] == 0.0f) continue;
            sah_bin *bn = &bins[a][bin_of(x[a], clo[a], scale[a])];
            bn->n++;
            grow(bn->lo, bn->hi, bb);
        }
    }
    double best = (double)count * parent_area;   /* the leaf's cost, as an upper bound */
    int best_axis = -1, best_bin = -1;
    for (int a = 0; a < 3; a++) {
        if (scale[a] == 0.0f) continue;
        /* sweep: the right parts' areas from the right, then the left */
        double rarea[BINS];
        int rcnt[BINS];
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        int n = 0;
        for (int b = BINS - 1; b > 0; b--) {
            const sah_bin *bn = &bins[a][b];
            n += bn->n;
            if (bn->n) {
                float bb[6] = {bn->lo[0], bn->lo[1], bn->lo[2], bn->hi[0], bn->hi[1], bn->hi[2]};
                grow(lo, hi, bb);
            }
            rcnt[b] = n;
            rarea[b] = n ? area_of(lo, hi) : 0.0;
        }
        for (int i = 0; i < 3; i++) lo[i] = INFINITY, hi[i] = -INFINITY;
        n = 0;
        for (int b = 0; b < BINS - 1; b++) {
            const sah_bin *bn = &bins[a][b];
            n += bn->n;
            if (bn->n) {
                float bb[6] = {bn->lo[0], bn->lo[1], bn->lo[2], bn->hi[0], bn->hi[1], bn->hi[2]};
                grow(lo, hi, bb);
            }
            if (n == 0 || rcnt[b + 1] == 0) continue;
            double cost = n * area_of(lo, hi) + rcnt[b + 1] * rarea[b + 1];
            if (isfinite(cost) && cost < best) {
                best = cost;
                best_axis = a;
                best_bin = b;
            }
        }
    }
    if (best_axis < 0) return false;
    /* the two sides' boxes: the unions of their bins' */
    for (int i = 0; i < 3; i++) {
        left[i] = right[i] = INFINITY;
        left[3 + i] = right[3 + i] = -INFINITY;
    }
    for (int b = 0; b < BINS; b++) {
        const sah_bin *bn = &bins[best_axis][b];
        if (bn->n == 0) continue;
        float bb[6] = {bn->lo[0], bn->lo[1], bn->lo[2], bn->hi[0], bn->hi[1], bn->hi[2]};
        float *side = b <= best_bin ? left : right;
        grow(side, side + 3, bb);
    }
    for (int a = 0; a < 3; a++) {
        lc[a] = rc[a] = INFINITY;
        lc[3 + a] = rc[3 + a] = -INFINITY;
    }
    int i = 0, j = count - 1;
    while (i <= j) {
        const float *x = c->centres[idx[i]];
        if (bin_of(x[best_axis], clo[best_axis], scale[best_axis]) <= best_bin) {
            grow_point(lc, lc + 3, x);
            i++;
        } else {
            grow_point(rc, rc + 3, x);
            int32_t t = idx[i];
            idx[i] = idx[j];
            idx[j--] = t;
        }
    }
    *mid = i;
    return i > 0 && i < count;
}

/* Node id over idx[first, first + count); box: its elements' union when
 * the parent's split knew it, else NULL (made here); cbox: their centres'
 * range likewise */
static void build_node(build_ctx *c, int id, int first, int count, int depth, const float *box,
                       const float *cbox)
{
    struct trace_mesh_bvh *t = c->bvh;
    assert(count > 0 && id < t->nnodes);
    mesh_node *n = &t->nodes[id];
    if (box) {
        memcpy(n->lo, box, sizeof n->lo);
        memcpy(n->hi, box + 3, sizeof n->hi);
    } else {
        for (int i = 0; i < 3; i++) n->lo[i] = INFINITY, n->hi[i] = -INFINITY;
        for (int i = 0; i < count; i++) grow(n->lo, n->hi, c->bounds[t->idx[first + i]]);
    }
    if (count <= LEAF_MAX) {
        n->a = first;
        n->n = count;
        return;
    }
    if (c->tasks && count <= TASK_MAX) {
        /* a subtree for the build's threads (trace_float_bvh_build) */
        if (c->ntasks == c->cap)
            c->tasks = xreallocarray(c->tasks, (size_t)(c->cap *= 2), sizeof *c->tasks);
        bvh_task *k = &c->tasks[c->ntasks++];
        *k = (bvh_task){.id = id, .first = first, .count = count, .depth = depth,
                        .has_cbox = cbox != NULL};
        memcpy(k->box, n->lo, sizeof n->lo);
        memcpy(k->box + 3, n->hi, sizeof n->hi);
        if (cbox) memcpy(k->cbox, cbox, sizeof k->cbox);
        return;
    }
    int mid = 0;
    double area = area_of(n->lo, n->hi);
    float lbox[6], rbox[6], lc[6], rc[6];
    bool split = depth < SAH_DEPTH && isfinite(area) &&
                 sah_split(c, first, count, area, &mid, lbox, rbox, cbox, lc, rc);
    if (!split) {
        /* no split worth its cost (or too deep, or boxes without end):
         * halves by index, so the depth stays logarithmic */
        mid = count / 2;
    }
    int left = t->nnodes;
    t->nnodes += 2;
    n = &t->nodes[id];
    n->a = left;
    n->n = 0;
    build_node(c, left, first, mid, depth + 1, split ? lbox : NULL, split ? lc : NULL);
    build_node(c, left + 1, first + mid, count - mid, depth + 1, split ? rbox : NULL,
               split ? rc : NULL);
}

/* Step q (0..255) of a leaf's grid along an axis from lo over width w
 * (hi - lo, exact in double): lo itself at 0, and at 255 hi itself
 * (255 * (1.0 / 255.0) is 1 exactly). The build and the walk decode with
 * this one function (no contraction: -ffp-contract=off), so a box the walk
 * tests is the box the build checked. */
static inline double grid_at(double lo, double w, int q)
{
    return lo + w * (q * (1.0 / 255.0));
}

/* The leaf's elements' boxes on its grid, rounded outward: the largest
 * step at or below each lo, the smallest at or above each hi, each
 * checked by decoding it. A leaf of no finite width on an axis is not
 * culled by its elements' boxes (trace_float_bvh_walk), nor is an
 * element whose box is NaN there (it keeps the leaf's extent). */
static void quantize_leaf(struct trace_mesh_bvh *t, const mesh_node *leaf,
                          const float (*bounds)[6])
{
    assert(255 * (1.0 / 255.0) == 1.0);
    for (int i = 0; i < leaf->n; i++) {
        const float *b = bounds[t->idx[leaf->a + i]];
        uint8_t *q = t->q[leaf->a + i];
        for (int a = 0; a < 3; a++) {
            double l = leaf->lo[a], w = (double)leaf->hi[a] - leaf->lo[a];
            int lo = 0, hi = 255;
            if (isfinite(w) && w > 0) {
                /* a first guess; the checks make it hold */
                double f = ((double)b[a] - l) / w * 255.0;
                double g = ((double)b[3 + a] - l) / w * 255.0;
                lo = f > 0 ? (f < 255 ? (int)f : 255) : 0;
                hi = g < 255 ? (g > 0 ? (int)ceil(g) : 0) : 255;
                while (lo > 0 && !(grid_at(l, w, lo) <= b[a])) lo--;
                while (hi < 255 && !(grid_at(l, w, hi) >= b[3 + a])) hi++;
            }
            q[a] = (uint8_t)lo;
            q[3 + a] = (uint8_t)hi;
        }
    }
}

/* One thread's share of the tasks: every stride-th from k. */
typedef struct task_share {
    const build_ctx *c;
    int k, stride;
} task_share;

static void *build_tasks(void *arg)
{
    task_share *sh = arg;
    const build_ctx *c = sh->c;
    for (int i = sh->k; i < c->ntasks; i += sh->stride) {
        bvh_task *k = &c->tasks[i];
        /* the subtree's own nodes; its elements are its own range of idx */
        struct trace_mesh_bvh sub = {.nodes = xmalloc(sizeof *sub.nodes * (size_t)(2 * k->count)),
                                     .nnodes = 1, .idx = c->bvh->idx};
        build_ctx lc = {c->bounds, c->centres, &sub, NULL, 0, 0};
        build_node(&lc, 0, k->first, k->count, k->depth, k->box, k->has_cbox ? k->cbox : NULL);
        /* its leaves' boxes on their grids (its own slots of q) */
        for (int j = 0; j < sub.nnodes; j++)
            if (sub.nodes[j].n > 0) quantize_leaf(c->bvh, &sub.nodes[j], c->bounds);
        k->nodes = sub.nodes;
        k->nnodes = sub.nnodes;
    }
    return NULL;
}

/* The tasks' subtrees joined to the top of the tree, in task order: a
 * task's root in its place, its other nodes after the tree's (a subtree's
 * node i >= 1 at off + i - 1, so children stay side by side). */
static void join_tasks(build_ctx *c)
{
    struct trace_mesh_bvh *t = c->bvh;
    int total = t->nnodes;
    for (int i = 0; i < c->ntasks; i++) total += c->tasks[i].nnodes - 1;
    t->nodes = xreallocarray(t->nodes, (size_t)total, sizeof *t->nodes);
    int off = t->nnodes;
    for (int i = 0; i < c->ntasks; i++) {
        const bvh_task *k = &c->tasks[i];
        for (int j = 0; j < k->nnodes; j++) {
            mesh_node nd = k->nodes[j];
            if (nd.n == 0) nd.a = off + nd.a - 1;      /* interior: its children moved */
            t->nodes[j == 0 ? k->id : off + j - 1] = nd;
        }
        off += k->nnodes - 1;
        free(k->nodes);
    }
    assert(off == total);
    t->nnodes = total;
}

struct trace_mesh_bvh *trace_float_bvh_build(const float (*bounds)[6], int n, int threads)
{
    struct trace_mesh_bvh *t = xcalloc(1, sizeof *t);
    t->idx = xmalloc(sizeof *t->idx * (size_t)(n > 0 ? n : 1));
    for (int i = 0; i < n; i++) t->idx[i] = i;
    /* a binary tree with leaves of >= 1 piece: at most 2n - 1 nodes */
    t->nodes = xmalloc(sizeof *t->nodes * (size_t)(2 * n > 0 ? 2 * n : 1));
    t->q = xmalloc(sizeof *t->q * (size_t)(n > 0 ? n : 1));
    build_ctx c = {bounds, xmalloc(sizeof *c.centres * (size_t)(n > 0 ? n : 1)), t, NULL, 0, 0};
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) c.centres[i][a] = (float)centre(bounds[i], a);
    if (n > 0) {
        /* the top of the tree here, its subtrees of up to TASK_MAX
         * elements over the threads */
        c.cap = 16;
        c.tasks = xmalloc(sizeof *c.tasks * (size_t)c.cap);
        t->nnodes = 1;
        build_node(&c, 0, 0, n, 0, NULL, NULL);
        int top = t->nnodes;           /* the top's nodes; the tasks' join after */
        if (threads > c.ntasks) threads = c.ntasks;
        if (threads < 1) threads = 1;
        task_share *share = xmalloc(sizeof *share * (size_t)threads);
        for (int i = 0; i < threads; i++) share[i] = (task_share){&c, i, threads};
        trace_run_shares(share, sizeof *share, threads, build_tasks);
        free(share);
        join_tasks(&c);
        free(c.tasks);
        /* the top's leaves on their grids (the tasks' are: build_tasks;
         * a task's root, in the top's place, is never a leaf) */
        for (int i = 0; i < top; i++)
            if (t->nodes[i].n > 0) quantize_leaf(t, &t->nodes[i], bounds);
    }
    free(c.centres);
    t->nodes = xreallocarray(t->nodes, (size_t)(t->nnodes > 0 ? t->nnodes : 1), sizeof *t->nodes);
    return t;
}

void trace_float_box(const trace_box *b, float f[6])
{
    f[0] = trace_float_down(b->lo.x), f[1] = trace_float_down(b->lo.y);
    f[2] = trace_float_down(b->lo.z);
    f[3] = trace_float_up(b->hi.x), f[4] = trace_float_up(b->hi.y), f[5] = trace_float_up(b->hi.z);
}

void trace_mesh_piece_bounds(const geom_surface *s, float out[6])
{
    trace_box root;
    geom_bounds(s, &root.lo, &root.hi);
    trace_float_box(&root, out);
}

void trace_float_bvh_free(struct trace_mesh_bvh **t)
{
    if (!*t) return;
    free((*t)->nodes);
    free((*t)->idx);
    free((*t)->q);
    free(*t);
    *t = NULL;
}

size_t trace_float_bvh_bytes(const struct trace_mesh_bvh *t, int n)
{
    return t ? (size_t)t->nnodes * sizeof(mesh_node) + (size_t)n * (sizeof *t->idx + sizeof *t->q)
             : 0;
}

bool trace_float_bvh_equal(const struct trace_mesh_bvh *a, const struct trace_mesh_bvh *b, int n)
{
    if (!a || !b) return a == b;
    return a->nnodes == b->nnodes &&
           !memcmp(a->nodes, b->nodes, sizeof *a->nodes * (size_t)a->nnodes) &&
           !memcmp(a->idx, b->idx, sizeof *a->idx * (size_t)n) &&
           !memcmp(a->q, b->q, sizeof *a->q * (size_t)n);
}

bool trace_float_bvh_root(const struct trace_mesh_bvh *t, trace_box *out)
{
    *out = (trace_box){.lo = v3(INFINITY, INFINITY, INFINITY),
                       .hi = v3(-INFINITY, -INFINITY, -INFINITY), .flags = 0};
    trace_box_no_slab(out);
    if (!t || t->nnodes == 0) return false;
    const mesh_node *r = &t->nodes[0];
    out->lo = v3(r->lo[0], r->lo[1], r->lo[2]);
    out->hi = v3(r->hi[0], r->hi[1], r->hi[2]);
    return true;
}

/* ---- a displaced mesh's boxes (issue 23) -------------------------------
 *
 * A displaced mesh's pieces' root boxes are made when a ray first reaches
 * them, not all when the world is built (17 us a piece for a height map:
 * 35 s of CPU for a 1M-face terrain before its first ray). The BVH needs
 * boxes that hold the displaced pieces before their own boxes exist:
 *
 *   1. each piece's undisplaced box over its (u,v) square (no shader), and
 *      a BVH over those;
 *   2. the BVH's subtrees of at most REGION_MAX pieces are regions
 *      (trace/region.h): one pass over a region's pieces, without their
 *      shader, gives the enclosures of its globals, and ONE affine run of
 *      the shader over them (Heidrich & Seidel 1998 §3.1, §4.2) bounds the
 *      displacement P' - P of every point of its pieces by `shift`, and
 *      the region's displaced box; a piece's box is its undisplaced box
 *      plus `shift`, met with the region's box (both hold every displaced
 *      point of the piece);
 *   3. the tree's boxes made again from those, bottom-up (its shape stays).
 *
 * A region the shader's inputs cannot be bound over (trace_region_add), or
 * whose run fails, or whose displacement comes out wider than the whole
 * mesh (a filter width from Du(s) on "st": boxes that large would send
 * every ray to every leaf), has its pieces' root boxes made at once
 * instead, and they are the pieces' boxes (as every piece's was before);
 * so are all with world option lazy_roots off.
 *
 * Every box is a pure function of the scene (made by whichever thread
 * first, the same bits), and the regions are the tree's, which is the
 * same for any thread count: so is the result. */
enum { REGION_MAX = 64 };

/* The elements idx[first, first + count) of node id's subtree */
static void node_range(const struct trace_mesh_bvh *t, int id, int *first, int *count)
{
    int l = id, r = id;
    while (t->nodes[l].n == 0) l = t->nodes[l].a;
    while (t->nodes[r].n == 0) r = t->nodes[r].a + 1;
    *first = t->nodes[l].a;
    *count = t->nodes[r].a + t->nodes[r].n - *first;
}

/* The regions: the largest subtrees of at most REGION_MAX elements, as
 * ranges of idx, in the tree's order */
static int regions_of(const struct trace_mesh_bvh *t, int (*out)[2])
{
    int n = 0, stack[MESH_STACK], sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        int id = stack[--sp], first, count;
        node_range(t, id, &first, &count);
        if (count <= REGION_MAX || t->nodes[id].n > 0) {
            out[n][0] = first;
            out[n++][1] = count;
            continue;
        }
        assert(sp + 2 <= MESH_STACK);
        stack[sp++] = t->nodes[id].a + 1;
        stack[sp++] = t->nodes[id].a;
    }
    return n;
}

/* One thread's share of the regions: every stride-th from i0 */
typedef struct region_share {
    trace_thread *th;
    const trace_object *obj;
    const struct trace_mesh_bvh *bvh;
    float (*bounds)[6];
    const int (*regions)[2];
    int nregions, i0, stride;
    double extent;                     /* the mesh's undisplaced extent */
    bool dudv;                         /* the shader reads du or dv */
} region_share;

/* Region [first, first + count) of idx: its pieces' boxes (above) */
static void region_boxes(region_share *b, int first, int count, trace_view *v)
{
    trace_thread *th = b->th;
    const int32_t *idx = b->bvh->idx + first;
    trace_box box;
    ia_interval shift[3];
    bool lazy = th->world->options.lazy_roots;
    if (lazy) {
        trace_region *region = trace_region_new();
        for (int i = 0; lazy && i < count; i++) {
            /* du, dv: enclosures (their bounds from a 3 x 3 grid, or any
             * value for a shader that never reads them), not the 9 x 9
             * grid's values */
            ia_interval dudv[2] = {ia_make(0x1p-16, 1.0), ia_make(0x1p-16, 1.0)};
            lazy = make(th, b->obj, idx[i], false, false, v);
            if (lazy && b->dudv)       /* (the bounds are never under 2^-16) */
                trace_object_grid_spacing_max(th->world, &v->obj, &dudv[0].hi, &dudv[1].hi);
            lazy = lazy && trace_region_add(th, region, &v->obj, dudv);
        }
        lazy = lazy && trace_region_run(th, b->obj, region, &box, shift);
        trace_region_destroy(&region);
        for (int a = 0; a < 3; a++) lazy = lazy && shift[a].hi - shift[a].lo <= b->extent;
    }
    if (th->failed) return;
    if (!lazy) {
        /* the pieces' own root boxes, now (published in the mesh's store) */
        for (int i = 0; i < count; i++) {
            if (!make(th, b->obj, idx[i], true, true, v)) return;
            trace_float_box(&v->obj.root, b->bounds[idx[i]]);
        }
        return;
    }
    const double blo[3] = {box.lo.x, box.lo.y, box.lo.z}, bhi[3] = {box.hi.x, box.hi.y, box.hi.z};
    for (int i = 0; i < count; i++) {
        float *f = b->bounds[idx[i]];
        for (int a = 0; a < 3; a++) {
            /* its undisplaced box plus the shift, rounded outward, met with
             * the region's box */
            ia_interval x = ia_add(ia_make(f[a], f[3 + a]), shift[a]);
            f[a] = trace_float_down(fmax(x.lo, blo[a]));
            f[3 + a] = trace_float_up(fmin(x.hi, bhi[a]));
        }
    }
}

static void *region_range(void *arg)
{
    region_share *b = arg;
    trace_view *v = xmalloc(sizeof *v);
    for (int i = b->i0; i < b->nregions && !b->th->failed; i += b->stride) {
        if (trace_thread_cancelled(b->th)) break;
        region_boxes(b, b->regions[i][0], b->regions[i][1], v);
    }
    free(v);
    return NULL;
}

/* The tree's boxes made again, bottom-up, from new element boxes (a
 * node's children come after it); its shape stays */
static void refit(struct trace_mesh_bvh *t, const float (*bounds)[6])
{
    for (int i = t->nnodes - 1; i >= 0; i--) {
        mesh_node *n = &t->nodes[i];
        for (int a = 0; a < 3; a++) n->lo[a] = INFINITY, n->hi[a] = -INFINITY;
        if (n->n > 0) {
            for (int j = 0; j < n->n; j++) grow(n->lo, n->hi, bounds[t->idx[n->a + j]]);
            continue;
        }
        assert(n->a > i);
        for (int c = 0; c < 2; c++) {
            const mesh_node *ch = &t->nodes[n->a + c];
            float cb[6] = {ch->lo[0], ch->lo[1], ch->lo[2], ch->hi[0], ch->hi[1], ch->hi[2]};
            grow(n->lo, n->hi, cb);
        }
    }
    for (int i = 0; i < t->nnodes; i++)
        if (t->nodes[i].n > 0) quantize_leaf(t, &t->nodes[i], bounds);
}

/* The threads worth starting for `work` pieces */
static int build_threads_for(const trace_thread *th, long work)
{
    int threads = th->world->options.build_threads;
    /* a thread is worth its start for a few thousand pieces of work */
    if (threads > work / 2048) threads = (int)(work / 2048);
    return threads < 1 ? 1 : threads;
}

/* The threads made for shares 1.. (share 0 is the caller's), failures
 * passed to th, then freed */
static void end_threads(trace_thread *th, trace_thread **made, int threads)
{
    for (int i = 1; i < threads; i++) {
        if (made[i]->failed && !th->failed) trace_thread_fail(th, made[i]->error);
        trace_thread_destroy(&made[i]);
    }
}

/* Mesh m's share of the world's root-box budget (trace_options.roots_bytes;
 * 0: unlimited): in proportion to its pieces among the displaced meshes'
 * (a mesh placed by two objects counted twice: a smaller share) */
static size_t roots_share(const trace_world *world, const trace_mesh *m)
{
    size_t budget = world->options.roots_bytes;
    if (budget == 0) return 0;
    double pieces = 0.0;
    for (int i = 0; i < world->nobjects; i++) {
        const trace_object *o = &world->objects[i];
        if (o->mesh && o->displacement) pieces += o->mesh->npieces;
        /* a displaced mesh's placements with meshes of their own */
        if (o->group && o->group->own_meshes)
            pieces += (double)o->group->nown * world->objects[o->group->proto].mesh->npieces;
    }
    if (pieces <= m->npieces) return budget;
    size_t share = (size_t)((double)budget * m->npieces / pieces);
    return share > 0 ? share : 1;
}

/* The displaced mesh's BVH over boxes that hold its pieces (above) */
static void build_displaced(trace_thread *th, const trace_object *obj)
{
    trace_mesh *m = obj->mesh;
    size_t n = (size_t)(m->npieces > 0 ? m->npieces : 1);
    /* the pieces' undisplaced boxes (trace_world_prepare's pass) */
    float (*bounds)[6] = m->bounds;
    m->bounds = NULL;
    m->bvh = trace_float_bvh_build((const float (*)[6])bounds, m->npieces,
                                   th->world->options.build_threads);
    m->lazy = trace_lazy_roots_new(m->npieces, roots_share(th->world, m));
    if (m->npieces == 0) {             /* no piece: an empty tree */
        free(bounds);
        return;
    }
    int threads = build_threads_for(th, m->npieces);
    trace_thread **made = xcalloc((size_t)threads, sizeof *made);
    for (int i = 0; i < threads; i++) made[i] = i == 0 ? th : trace_thread_new(th->world);
    const mesh_node *root = &m->bvh->nodes[0];
    double extent = 0.0;
    for (int a = 0; a < 3; a++) extent = fmax(extent, (double)root->hi[a] - root->lo[a]);
    int (*regions)[2] = xmalloc(sizeof *regions * n);
    int nregions = regions_of(m->bvh, regions);
    const sl_program *dp = sl_instance_program(obj->displacement);
    bool dudv = sl_program_reads_global(dp, SL_G_du) || sl_program_reads_global(dp, SL_G_dv);
    region_share *rs = xcalloc((size_t)threads, sizeof *rs);
    for (int i = 0; i < threads; i++)
        rs[i] = (region_share){made[i], obj, m->bvh, bounds, (const int (*)[2])regions,
                               nregions, i, threads, extent, dudv};
    trace_run_shares(rs, sizeof *rs, threads, region_range);
    free(rs);
    free(regions);
    refit(m->bvh, (const float (*)[6])bounds);
    end_threads(th, made, threads);
    free(made);
    free(bounds);
    if (th->failed || trace_thread_cancelled(th)) {
        /* a failure, or a signal: no tree (the boxes may be unfinished) */
        trace_lazy_roots_destroy(&m->lazy);
        trace_float_bvh_free(&m->bvh);
    }
}

bool trace_mesh_build(trace_thread *th, trace_object *obj)
{
    trace_mesh *m = obj->mesh;
    assert(m);
    if (!m->bvh) {                     /* not yet made for another object sharing m */
        /* trace_world_prepare's pass over the pieces made the bounds */
        assert(!m->lazy && m->bounds);
        if (obj->displacement) {
            build_displaced(th, obj);
        } else {
            m->bvh = trace_float_bvh_build((const float (*)[6])m->bounds, m->npieces,
                                           th->world->options.build_threads);
            free(m->bounds);           /* the tree keeps them, quantized */
            m->bounds = NULL;
        }
        if (th->failed) return false;
    }
    /* the root: the union of the pieces' boxes (object space), the
     * bound: its camera-space box, as any object's */
    trace_float_bvh_root(m->bvh, &obj->root);
    trace_object_camera_bound(obj, &obj->root, &obj->bound);
    return true;
}

/* the ray against a float box (lo, hi), as trace_box_hit */
static bool float_box_hit(const float lo[3], const float hi[3], const trace_ray *ray,
                          double tmax, double *t0)
{
    trace_box b = {.lo = v3(lo[0], lo[1], lo[2]), .hi = v3(hi[0], hi[1], hi[2])};
    double t1;
    return trace_box_hit(&b, ray, ray->tmin, tmax, t0, &t1, NULL);
}

static bool node_hit(const mesh_node *n, const trace_ray *ray, double tmax, double *t0)
{
    return float_box_hit(n->lo, n->hi, ray, tmax, t0);
}

bool trace_float_bvh_walk(const struct trace_mesh_bvh *t, const trace_ray *ray, trace_hit *best,
                          bool any, trace_float_bvh_leaf leaf, void *ctx)
{
    if (!t || t->nnodes == 0) return false;
    struct { int node; double t0; } stack[MESH_STACK];
    int sp = 0;
    double t0;
    if (!node_hit(&t->nodes[0], ray, best->t, &t0)) return false;
    stack[sp].node = 0;
    stack[sp++].t0 = t0;
    bool found = false;
    while (sp > 0) {
        sp--;
        if (!(stack[sp].t0 < best->t)) continue;
        const mesh_node *n = &t->nodes[stack[sp].node];
        if (n->n > 0) {
            /* the leaf's grid; elements of a leaf without a finite width
             * are not culled by their boxes */
            double l[3], w[3];
            for (int a = 0; a < 3; a++) l[a] = n->lo[a], w[a] = (double)n->hi[a] - n->lo[a];
            bool cull = isfinite(w[0] + w[1] + w[2]);
            for (int i = 0; i < n->n; i++) {
                const uint8_t *q = t->q[n->a + i];
                if (cull) {
                    trace_box b = {.lo = v3(grid_at(l[0], w[0], q[0]), grid_at(l[1], w[1], q[1]),
                                            grid_at(l[2], w[2], q[2])),
                                   .hi = v3(grid_at(l[0], w[0], q[3]), grid_at(l[1], w[1], q[4]),
                                            grid_at(l[2], w[2], q[5]))};
                    double r0, r1;
                    if (!trace_box_hit(&b, ray, ray->tmin, best->t, &r0, &r1, NULL)) continue;
                }
                int got = leaf(ctx, t->idx[n->a + i]);
                if (got < 0) return found;
                if (got > 0) {
                    found = true;
                    if (any) return true;
                }
            }
            continue;
        }
        double ta = 0, tb = 0;
        bool ha = node_hit(&t->nodes[n->a], ray, best->t, &ta);
        bool hb = node_hit(&t->nodes[n->a + 1], ray, best->t, &tb);
        assert(sp + 2 <= MESH_STACK);
        if (ha && hb) {
            bool a_first = ta <= tb;
            stack[sp].node = a_first ? n->a + 1 : n->a;
            stack[sp++].t0 = a_first ? tb : ta;
            stack[sp].node = a_first ? n->a : n->a + 1;
            stack[sp++].t0 = a_first ? ta : tb;
        } else if (ha) {
            stack[sp].node = n->a;
            stack[sp++].t0 = ta;
        } else if (hb) {
            stack[sp].node = n->a + 1;
            stack[sp++].t0 = tb;
        }
    }
    return found;
}

/* One mesh traversal: the pieces' leaf test (trace_float_bvh_leaf) */
typedef struct mesh_walk {
    trace_thread *th;
    const trace_object *obj;
    const trace_ray *cam_ray, *ray;    /* camera space, object space */
    const trace_tolerance *tol;
    bool any;
    trace_hit *best;
} mesh_walk;

static int mesh_leaf(void *ctx, int k)
{
    mesh_walk *w = ctx;
    const trace_mesh *m = w->obj->mesh;
    double r0, r1, dudv[2];
    /* a displaced piece's root box, as its walk tests it (when held) */
    trace_box root;
    if (m->lazy && trace_lazy_root(m->lazy, k, &root, dudv) &&
        !trace_box_hit(&root, w->ray, w->ray->tmin, w->best->t, &r0, &r1, NULL))
        return 0;
    const trace_object *v = trace_mesh_view(w->th, w->obj, k);
    if (!v) return -1;
    if (!trace_intersect_object(w->th, v, w->cam_ray, w->tol, w->any, w->best)) return 0;
    trace_view_hit(w->th, v, w->best);
    return 1;
}

bool trace_mesh_intersect(trace_thread *th, const trace_object *obj, const trace_ray *cam_ray,
                          const trace_tolerance *tol, bool any, trace_hit *best)
{
    /* a moved placement is walked as its prototype (group.c) */
    assert(!obj->box_proto);
    const trace_mesh *m = obj->mesh;
    /* the boxes are in object space: so is the ray (an affine map keeps
     * its parameter t); the pieces take the camera-space ray */
    trace_ray oray;
    trace_ray_init(&oray, mat4_xform_point(&obj->from_camera, cam_ray->o),
                   mat4_xform_vector(&obj->from_camera, cam_ray->d), cam_ray->tmin, cam_ray->tmax);
    mesh_walk w = {th, obj, cam_ray, &oray, tol, any, best};
    return trace_float_bvh_walk(m->bvh, &oray, best, any, mesh_leaf, &w);
}

/* ---- shared edges ----------------------------------------------------- */

/* A piece's bits 8-63: the pieces with more than 8 corners are few, so
 * their wide bits are a list by piece (a piece may appear once per
 * marked edge until trace_mesh_edges_done merges them). */
struct trace_mesh_edges {
    int32_t k;
    uint64_t bits;
};

uint64_t trace_mesh_shared_edges(const trace_mesh *m, int k)
{
    assert(k >= 0 && k < m->npieces);
    uint64_t e = m->shared_edges ? m->shared_edges[k] : 0;
    int lo = 0, hi = m->nwide;         /* the first entry of piece >= k */
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (m->wide[mid].k < k) lo = mid + 1; else hi = mid;
    }
    if (lo < m->nwide && m->wide[lo].k == k) e |= m->wide[lo].bits;
    return e;
}

void trace_mesh_mark_edge(trace_mesh *m, int k, int edge)
{
    assert(k >= 0 && k < m->npieces && edge >= 0 && edge < 64 && m->shared_edges);
    if (edge < 8) {
        m->shared_edges[k] |= (uint8_t)(1u << edge);
        return;
    }
    /* a power-of-two capacity: grown when nwide reaches one */
    if (m->nwide == 0 || (m->nwide & (m->nwide - 1)) == 0)
        m->wide = xreallocarray(m->wide, (size_t)(m->nwide > 0 ? 2 * m->nwide : 1), sizeof *m->wide);
    m->wide[m->nwide++] = (struct trace_mesh_edges){k, (uint64_t)1 << edge};
}

static int edges_cmp(const void *a, const void *b)
{
    int32_t x = ((const struct trace_mesh_edges *)a)->k, y = ((const struct trace_mesh_edges *)b)->k;
    return (x > y) - (x < y);
}

void trace_mesh_edges_done(trace_mesh *m)
{
    if (m->nwide == 0) return;
    qsort(m->wide, (size_t)m->nwide, sizeof *m->wide, edges_cmp);
    int n = 0;
    for (int i = 0; i < m->nwide; i++) {
        if (n > 0 && m->wide[n - 1].k == m->wide[i].k) m->wide[n - 1].bits |= m->wide[i].bits;
        else m->wide[n++] = m->wide[i];
    }
    m->nwide = n;
    m->wide = xreallocarray(m->wide, (size_t)n, sizeof *m->wide);
}

void trace_mesh_clear(trace_mesh *self)
{
    free(self->shared_edges);
    free(self->wide);
    self->wide = NULL;
    self->nwide = 0;
    free(self->bounds);
    trace_lazy_roots_destroy(&self->lazy);
    trace_float_bvh_free(&self->bvh);
    self->shared_edges = NULL;
    self->bounds = NULL;
}

size_t trace_mesh_bytes(const trace_mesh *self)
{
    size_t n = (size_t)self->npieces;
    size_t b = 0;
    if (self->shared_edges) b += n * sizeof *self->shared_edges;
    b += (size_t)self->nwide * sizeof *self->wide;
    if (self->bounds) b += n * sizeof *self->bounds;
    b += trace_lazy_roots_bytes(self->lazy);
    return b + trace_float_bvh_bytes(self->bvh, self->npieces);
}

/* FNV-1a over n bytes, from h */
static uint64_t digest_bytes(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

uint64_t trace_mesh_digest(const trace_mesh *self)
{
    uint64_t h = 0xcbf29ce484222325ull;
    const struct trace_mesh_bvh *t = self->bvh;
    size_t n = (size_t)self->npieces;
    if (t) {
        h = digest_bytes(h, &t->nnodes, sizeof t->nnodes);
        h = digest_bytes(h, t->nodes, sizeof *t->nodes * (size_t)t->nnodes);
        h = digest_bytes(h, t->idx, sizeof *t->idx * n);
        h = digest_bytes(h, t->q, sizeof *t->q * n);
    }
    for (int k = 0; k < self->npieces; k++) {
        uint64_t e = trace_mesh_shared_edges(self, k);
        h = digest_bytes(h, &e, sizeof e);
    }
    return h;
}

/*
 * bvh.c: median-split BVH over object root boxes (see bvh.h).
 */
#include "trace/bvh.h"
#include "trace/group.h"
#include "trace/mesh.h"
#include "util/xalloc.h"

#include <assert.h>
#include <stdlib.h>

typedef struct bvh_node {
    trace_box box;
    int left, right;         /* children, or -1 for a leaf */
    int first, count;        /* leaf: objects idx[first .. first+count) */
} bvh_node;

struct trace_bvh {
    const trace_world *world;
    bvh_node *nodes;
    int nnodes;
    int *idx;
};

enum { BVH_LEAF_SIZE = 2, BVH_STACK = 64 };

/* qsort has no user pointer: the build (once per world, one thread) sets these */
static const trace_world *sort_world;
static int sort_axis;

static double centre(const trace_object *o, int axis)
{
    const trace_box *b = &o->bound;
    return 0.5 * (v3_comp(b->lo, axis) + v3_comp(b->hi, axis));
}

static int cmp_objects(const void *a, const void *b)
{
    double ca = centre(&sort_world->objects[*(const int *)a], sort_axis);
    double cb = centre(&sort_world->objects[*(const int *)b], sort_axis);
    if (ca < cb) return -1;
    if (ca > cb) return 1;
    return *(const int *)a - *(const int *)b;
}

static int build(trace_bvh *self, int first, int count)
{
    /* node ranges: a non-empty run of idx, inside it */
    assert(count > 0 && first >= 0 && first + count <= self->world->nobjects);
    assert(self->nnodes < 2 * self->world->nobjects);   /* a binary tree: 2n - 1 nodes */
    int id = self->nnodes++;
    bvh_node *n = &self->nodes[id];
    n->box = self->world->objects[self->idx[first]].bound;
    for (int i = 1; i < count; i++)
        trace_box_union(&n->box, &self->world->objects[self->idx[first + i]].bound);
    n->left = n->right = -1;
    n->first = first;
    n->count = count;
    if (count <= BVH_LEAF_SIZE) return id;
    vec3 e = v3_sub(n->box.hi, n->box.lo);
    sort_axis = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
    sort_world = self->world;
    qsort(self->idx + first, (size_t)count, sizeof(int), cmp_objects);
    int half = count / 2;
    int l = build(self, first, half);
    int r = build(self, first + half, count - half);
    self->nodes[id].left = l;
    self->nodes[id].right = r;
    assert(self->nodes[l].first == first && self->nodes[r].first + self->nodes[r].count ==
           first + count);
    return id;
}

trace_bvh *trace_bvh_new(const trace_world *world)
{
    trace_bvh *self = xcalloc(1, sizeof *self);
    self->world = world;
    int n = world->nobjects;
    self->idx = xmalloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    self->nodes = xmalloc(sizeof(bvh_node) * (size_t)(2 * n + 1));
    for (int i = 0; i < n; i++) self->idx[i] = i;
    if (n > 0) build(self, 0, n);
    return self;
}

void trace_bvh_destroy(trace_bvh **self_p)
{
    trace_bvh *self = *self_p;
    if (!self) return;
    free(self->nodes);
    free(self->idx);
    free(self);
    *self_p = NULL;
}

bool trace_bvh_intersect(const trace_bvh *self, trace_thread *th,
                         const trace_ray *ray, const trace_tolerance *tol,
                         bool any, trace_hit *best)
{
    if (self->nnodes == 0) return false;
    struct { int node; double t0; } stack[BVH_STACK];
    int sp = 0;
    bool found = false;
    double t0, t1;
    if (!trace_box_hit(&self->nodes[0].box, ray, ray->tmin, best->t, &t0, &t1, NULL))
        return false;
    stack[sp].node = 0;
    stack[sp++].t0 = t0;
    while (sp > 0) {
        sp--;
        const bvh_node *n = &self->nodes[stack[sp].node];
        if (!(stack[sp].t0 < best->t)) continue;
        if (n->left < 0) {
            assert(n->first >= 0 && n->first + n->count <= self->world->nobjects);
            for (int i = 0; i < n->count; i++) {
                const trace_object *o = &self->world->objects[self->idx[n->first + i]];
                if (o->group  ? trace_group_intersect(th, o, ray, tol, any, best)
                    : o->mesh ? trace_mesh_intersect(th, o, ray, tol, any, best)
                              : trace_intersect_object(th, o, ray, tol, any, best)) {
                    found = true;
                    if (any) return true;
                }
            }
            continue;
        }
        double ta0 = 0, ta1 = 0, tb0 = 0, tb1 = 0;
        bool ha = trace_box_hit(&self->nodes[n->left].box, ray, ray->tmin, best->t, &ta0, &ta1, NULL);
        bool hb = trace_box_hit(&self->nodes[n->right].box, ray, ray->tmin, best->t, &tb0, &tb1, NULL);
        assert(sp + 2 <= BVH_STACK);
        /* push the farther first so the nearer is visited first */
        if (ha && hb) {
            bool a_first = ta0 <= tb0;
            stack[sp].node = a_first ? n->right : n->left;
            stack[sp++].t0 = a_first ? tb0 : ta0;
            stack[sp].node = a_first ? n->left : n->right;
            stack[sp++].t0 = a_first ? ta0 : tb0;
        } else if (ha) {
            stack[sp].node = n->left;
            stack[sp++].t0 = ta0;
        } else if (hb) {
            stack[sp].node = n->right;
            stack[sp++].t0 = tb0;
        }
    }
    return found;
}

/*
 * test_corpus_containment.c: issue 9, "the corpus", containment: for every
 * shader of tests/shaders/corpus on each of the six test surfaces, in
 * affine and in interval arithmetic, random (u,v) ranges with sides from
 * the whole domain down to ~1e-3 of it; the OBJECT-space box of each range
 * from the renderer's own code path (trace_surface_box), and dense samples
 * inside the range from the renderer's point path (trace_surface_point_eval,
 * dual mode, camera space, mapped to object space with obj->from_camera).
 * Every sample must lie inside its box up to a rounding slack of a few
 * ulps of the coordinates' magnitude (Heidrich & Seidel §3: the boxes are
 * conservative), no box of a range narrower than WIDE (both sides) may be
 * unbounded (AA_UNBOUNDED or an infinite side), and none may come from a
 * failed shader run (except ranges holding a corner of a subdivision
 * face, see run_cases). Three ranges in four touch the border of the
 * (u,v) square, so that the singular parameter values of every base are
 * sampled exactly (snap_to_border): the sphere's poles, and the surfaces
 * "apex" (a disk's centre, a cone's and a paraboloid's apex) and
 * "collapsed" (patches with a collapsed edge, a hyperboloid from its
 * axis), where Ng = 0 and the shader's N is the limit normal. Wider ranges may give unbounded boxes, counted
 * ("wide-unb"): the dependency problem of range arithmetic in idioms such
 * as 1 / length(ntransform("shader", normalize(N))) or a filter width of
 * distance() at its centre, whose operands' ranges include 0 over a wide
 * range although the values never do; the subdivision splits such ranges
 * (docs/renderer.md, "Shader globals").
 *
 * Where a range's affine run proved decisions (its box's tape: tape
 * pruning, common/sl/tape_plan.c), its four children are boxed as the walk
 * boxes them, taking those decisions (trace_surface_box_tape), and points
 * of each are checked against its box, which must be bounded wherever the
 * whole program's box of the child is, and the same (box and tape) when
 * made again after the thread made another box.
 *
 * Prints one row per shader x surface x arithmetic: cases, points,
 * violations, unbounded boxes, shader errors (box runs / point runs), worst
 * excess, and the smallest range (its larger side, as a fraction of the
 * domain) whose box was unbounded.
 *
 *   AAFARM_CORPUS_CASES  ranges per shader, surface and arithmetic (default 1000)
 *   AAFARM_CORPUS_ONLY   comma-separated shader names to run (default all)
 */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "corpus.h"
#include "geom/surface.h"
#include "trace/mesh.h"
#include "trace/displace.h"

enum { GRID = 4, RANDOM_POINTS = 16 };   /* samples per range: 4x4 grid (corners and
                                          * edges included) + 16 random */

/* ranges with a side at least this wide may be unbounded (counted) */
#define WIDE (1.0 / 32.0)

typedef struct tally {
    long cases, points, violations, unbounded, unbounded_wide, box_errors, point_errors;
    long slab_points;               /* points also checked against a slab (box.h) */
    long restricted_points;         /* checks against restricted bounds (box.h) */
    long split;                     /* boxes narrowed by case splits (trace_surface_box_cases) */
    long split_first;               /* boxes of the cases first (trace_surface_box_split) */
    long split_lin;                 /* of them, with a linear bound for all the cases */
    long split_plain;               /* of its calls, those that split nothing */
    long plain_differ;              /* of them, boxes or linear bounds not the plain run's */
    long undefined;                 /* NaN points on a base's axis (check_point) */
    long taped;                     /* children boxed with their range's tape (tape
                                       pruning: trace_surface_box_tape) */
    long taped_unbounded;           /* of them, unbounded where the whole
                                       program's box is bounded */
    long taped_differ;              /* of them, not the same box or tape when
                                       made again (a pure function) */
    double worst;                   /* largest excess outside the box, object units */
    double unb_side;                /* smallest range (larger side) with an unbounded box */
    char error[512];                /* the first shader error */
} tally;

static corpus C;

static int setup(void **state) { return corpus_group_load(&C, state); }
static int teardown(void **state) { return corpus_group_free(&C, state); }

static void take_error(trace_thread *th, tally *t, long *counter)
{
    if (!th->failed) return;
    (*counter)++;
    if (!t->error[0]) memcpy(t->error, th->error, sizeof t->error);
    th->failed = false;
    th->error[0] = 0;
}

static double vmax_abs(vec3 a)
{
    return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

/* excess of p outside [lo, hi] beyond the slack (0 when inside) */
static double excess(double p, double lo, double hi, double slack)
{
    if (p < lo - slack) return lo - p;
    if (p > hi + slack) return p - hi;
    return 0;
}

/* The restricted bounds of the box's linear bound (box.h, issue 24's lazy
 * children): the point's coordinate k against those of each child cell
 * of r that holds (u, v) (two or four on the cell's middle lines), and of
 * r itself; the largest excess */
static double restricted_excess(const trace_box *b, const trace_lin *lin, const double r[4],
                                double u, double v, vec3 p, double slack, tally *t)
{
    if (!(b->flags & TRACE_BOX_LIN)) return 0;
    /* as the intersector has it: the codes against the box as the cache
     * keeps it (the box itself rounded so, and no wider) */
    trace_fbox f;
    trace_box kept;
    trace_fbox_pack_lin(b, lin, NULL, &f);
    trace_fbox_unpack(&f, NULL, &kept);
    if (!(kept.flags & TRACE_BOX_LIN)) return 0;
    trace_dlin d;
    trace_box_lin(&f.qlin, &kept, &d);
    double um = 0.5 * (r[0] + r[1]), vm = 0.5 * (r[2] + r[3]), e = 0;
    for (int i = 0; i < 5; i++) {
        double c[4] = {r[0], r[1], r[2], r[3]};
        if (i < 4) {                      /* the intersector's child cells */
            if (i & 1) c[0] = um; else c[1] = um;
            if (i & 2) c[2] = vm; else c[3] = vm;
        }
        if (u < c[0] || u > c[1] || v < c[2] || v > c[3]) continue;
        trace_box rb;
        trace_box_restrict(&d, &kept, r, c, &rb);
        t->restricted_points++;
        e = fmax(e, fmax(excess(p.x, rb.lo.x, rb.hi.x, slack),
                         fmax(excess(p.y, rb.lo.y, rb.hi.y, slack),
                              excess(p.z, rb.lo.z, rb.hi.z, slack))));
    }
    return e;
}

static void check_point(trace_thread *th, const trace_object *obj, const trace_box *b,
                        const trace_lin *lin, const trace_box *b2, const trace_lin *lin2,
                        const double r[4], double u, double v, tally *t)
{
    if (!geom_uv_inside(&obj->surf, u, v)) return;     /* not on the polygon */
    trace_surface_point sp;
    trace_surface_point_eval(th, obj, u, v, &sp);
    take_error(th, t, &t->point_errors);
    vec3 p = mat4_xform_point(&obj->from_camera, sp.P);
    double slack = 8 * DBL_EPSILON * (vmax_abs(sp.P) + vmax_abs(p));
    double e = fmax(excess(p.x, b->lo.x, b->hi.x, slack),
                    fmax(excess(p.y, b->lo.y, b->hi.y, slack),
                         excess(p.z, b->lo.z, b->hi.z, slack)));
    if (trace_box_has_slab(b)) {          /* and between the slab's planes */
        double s = (double)b->sn[0] * p.x + (double)b->sn[1] * p.y + (double)b->sn[2] * p.z;
        t->slab_points++;
        e = fmax(e, excess(s, b->slo, b->shi, 2 * slack));
    }
    e = fmax(e, restricted_excess(b, lin, r, u, v, p, slack, t));
    if (b2) {                             /* the box of the cases first (no slab) */
        e = fmax(e, fmax(excess(p.x, b2->lo.x, b2->hi.x, slack),
                         fmax(excess(p.y, b2->lo.y, b2->hi.y, slack),
                              excess(p.z, b2->lo.z, b2->hi.z, slack))));
        e = fmax(e, restricted_excess(b2, lin2, r, u, v, p, slack, t));   /* all the cases' */
    }
    t->points++;
    if (isnan(p.x) || isnan(p.y) || isnan(p.z)) {
        /* the shader's own 0/0 on the z axis of a surface of revolution
         * (atan_ratio's atan(y / x) at a pole or apex, where x = y = 0
         * exactly): undefined there, whatever the normal; counted apart */
        geom_sample g;
        geom_eval(&obj->surf, u, v, &g);
        if (obj->surf.kind <= GEOM_TORUS && fabs(g.P.x) <= 1e-12 && fabs(g.P.y) <= 1e-12) {
            t->undefined++;
            return;
        }
        t->violations++;
        return;
    }
    if (e > 0) {
        t->violations++;
        if (!(e <= t->worst)) t->worst = e;
    }
}

/* Three ranges in four touch the border of the (u,v) square, where the
 * singular parameter values of the bases lie (a sphere's poles at v = 0
 * and 1, a disk's centre and a cone's apex at v = 1, a paraboloid's apex
 * and the collapsed edges of the "collapsed" surface at v = 0, the
 * corners of patches), so that the 4x4 grid samples them exactly: case
 * k % 4 == 1 ends at v = 1, 2 starts at v = 0, 3 holds a corner. */
static void snap_to_border(long k, double su, double sv, double *u0, double *u1, double *v0,
                           double *v1)
{
    switch (k % 4) {
    case 1:
        *v1 = 1;
        *v0 = 1 - sv;
        break;
    case 2:
        *v0 = 0;
        *v1 = sv;
        break;
    case 3:
        if (k % 8 == 3) {
            *u0 = 0;
            *u1 = su;
            *v1 = 1;
            *v0 = 1 - sv;
        } else {
            *u1 = 1;
            *u0 = 1 - su;
            *v0 = 0;
            *v1 = sv;
        }
        break;
    default:
        break;
    }
}

/* A base whose unit normal has no closed form (geom_unit_normal_aa
 * normalises Ng) bounds it by the whole line over a range that holds a
 * point where Ng = 0: the "collapsed" surface's edges at v = 0 (and a
 * paraboloid's apex, where dPdv is unbounded). Such ranges may give
 * unbounded boxes (interval arithmetic: also ranges near it, whose |Ng|
 * bound reaches 0), counted with the wide ones; their points, in the
 * bounded boxes, are checked like any other. */
static bool singular_border(const trace_object *obj, double v0, double v1)
{
    switch (obj->surf.kind) {
    case GEOM_PARABOLOID: case GEOM_HYPERBOLOID: case GEOM_PATCH:
        return v0 < WIDE || v1 > 1 - WIDE;
    case GEOM_BICUBIC:      /* the collapsed dome's interval |Ng| bound reaches 0
                             * on ranges just under WIDE anywhere (seen at
                             * [0.51, 0.53] x [0.40, 0.43]) */
        return true;
    default:
        return false;
    }
}

/* a side between 1 and 1e-3 of the domain, log-uniform */
static double side(corpus_rng *r)
{
    return pow(10.0, -3.0 * corpus_rng_uniform(r));
}

/* The same box, field by field (bit for bit; NaN sides equal) */
static bool same_box(const trace_box *a, const trace_box *b)
{
    return memcmp(&a->lo, &b->lo, sizeof a->lo) == 0 && memcmp(&a->hi, &b->hi, sizeof a->hi) == 0 &&
           a->flags == b->flags && memcmp(&a->bend, &b->bend, sizeof a->bend) == 0 &&
           memcmp(a->sn, b->sn, sizeof a->sn) == 0 && memcmp(&a->slo, &b->slo, sizeof a->slo) == 0 &&
           memcmp(&a->shi, &b->shi, sizeof a->shi) == 0;
}

static bool unbounded_box(const trace_box *b)
{
    return (b->flags & AA_UNBOUNDED) || !isfinite(b->lo.x) || !isfinite(b->lo.y) ||
           !isfinite(b->lo.z) || !isfinite(b->hi.x) || !isfinite(b->hi.y) || !isfinite(b->hi.z);
}

static void run_cases(trace_thread *th, const trace_world *w, long ncases, uint64_t seed,
                      tally *t)
{
    corpus_rng rng = {seed};
    /* every surface: the objects, and each mesh's pieces (views) */
    int nsurf = 0;
    for (int o = 0; o < w->nobjects; o++) nsurf += trace_object_npieces(&w->objects[o]);
    trace_view *view = malloc(sizeof *view);
    for (long k = 0; k < ncases; k++) {
        int s = (int)(k % nsurf), o = 0;
        while (s >= trace_object_npieces(&w->objects[o])) s -= trace_object_npieces(&w->objects[o++]);
        const trace_object *obj = trace_object_piece(th, &w->objects[o], s, view);
        assert_non_null(obj);
        double su = side(&rng), sv = side(&rng);
        double u0 = (1 - su) * corpus_rng_uniform(&rng), v0 = (1 - sv) * corpus_rng_uniform(&rng);
        double u1 = u0 + su, v1 = v0 + sv;
        if (u1 > 1) u1 = 1;
        if (v1 > 1) v1 = 1;
        snap_to_border(k, su, sv, &u0, &u1, &v0, &v1);
        trace_box b;
        trace_lin lin;            /* its linear bound, as the intersector gets it */
        trace_surface_box_lin(th, obj, u0, u1, v0, v1, &b, &lin);
        take_error(th, t, &t->box_errors);
        /* a discontinuous box, narrowed by the cases of its seams as the
         * intersector narrows those that stop shrinking (issue 24): the
         * points must lie in the narrowed box */
        if ((b.flags & AA_DISCONTINUOUS) && trace_surface_box_cases(th, obj, u0, u1, v0, v1, &b, &lin, NULL))
            t->split++;
        take_error(th, t, &t->box_errors);
        /* and as the children of such a box run theirs first
         * (trace_surface_box_split, on any cell: the walk runs it on every
         * child of a split box): the points in the hull of the cases */
        trace_box b2, *split = NULL;
        trace_lin lin2;
        if (trace_surface_box_split(th, obj, u0, u1, v0, v1, &b2, &lin2, NULL)) {
            if (!(b2.flags & AA_UNBOUNDED)) {
                split = &b2;
                t->split_first++;
                t->split_lin += (b2.flags & TRACE_BOX_LIN) != 0;
            }
        } else if (!th->failed) {
            /* nothing split: the plain run's box and linear bound */
            trace_box b3;
            trace_lin lin3;
            trace_surface_box_lin(th, obj, u0, u1, v0, v1, &b3, &lin3);
            t->split_plain++;
            t->plain_differ += !same_box(&b2, &b3) ||
                               ((b3.flags & TRACE_BOX_LIN) && memcmp(&lin2, &lin3, sizeof lin3) != 0);
        }
        take_error(th, t, &t->box_errors);
        t->cases++;
        if (unbounded_box(&b)) {
            /* a subdivision face bounds a range holding one of its
             * corners, which may be an extraordinary point, by the hull of
             * its 1-ring with unbounded derivatives (dP/du is unbounded
             * there at valence > 4; docs/geometry.md): counted with the
             * wide ones */
            bool corner = obj->surf.kind == GEOM_SUBDIV && (u0 == 0 || u1 == 1) &&
                          (v0 == 0 || v1 == 1);
            if (fmax(u1 - u0, v1 - v0) >= WIDE || corner || singular_border(obj, v0, v1))
                t->unbounded_wide++;
            else {
                t->unbounded++;
                printf("    unbounded: %s over [%.9g, %.9g] x [%.9g, %.9g]\n",
                       geom_kind_name(obj->surf.kind), u0, u1, v0, v1);
            }
            if (fmax(u1 - u0, v1 - v0) < t->unb_side) t->unb_side = fmax(u1 - u0, v1 - v0);
            continue;          /* such a box contains everything: nothing to sample */
        }
        double r[4] = {u0, u1, v0, v1};
        for (int j = 0; j < GRID; j++)
            for (int i = 0; i < GRID; i++)
                check_point(th, obj, &b, &lin, split, &lin2, r, u0 + (u1 - u0) * i / (GRID - 1),
                            v0 + (v1 - v0) * j / (GRID - 1), t);
        /* the middle lines, where two or four child cells meet */
        for (int i = 0; i < GRID; i++) {
            double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
            check_point(th, obj, &b, &lin, split, &lin2, r, um, v0 + (v1 - v0) * i / (GRID - 1), t);
            check_point(th, obj, &b, &lin, split, &lin2, r, u0 + (u1 - u0) * i / (GRID - 1), vm, t);
        }
        for (int i = 0; i < RANDOM_POINTS; i++) {
            double u = u0 + (u1 - u0) * corpus_rng_uniform(&rng);
            double v = v0 + (v1 - v0) * corpus_rng_uniform(&rng);
            check_point(th, obj, &b, &lin, split, &lin2, r, u, v, t);
        }
        /* where the range's run proved decisions (its tape, box.h), the
         * children as the walk boxes them, taking those decisions: the
         * points of each quarter in its box */
        if (b.tape != 0)
            for (int q = 0; q < 4; q++) {
                double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
                double c[4] = {q & 1 ? um : u0, q & 1 ? u1 : um, q & 2 ? vm : v0, q & 2 ? v1 : vm};
                trace_box cb;
                trace_lin clin;
                trace_surface_box_tape(th, obj, c[0], c[1], c[2], c[3], b.tape, &cb, &clin);
                take_error(th, t, &t->box_errors);
                t->taped++;
                /* a pure function of (range, tape): once more, after the
                 * thread made one box more, the same box and tape */
                trace_box cb2;
                trace_lin clin2;
                trace_surface_box_tape(th, obj, c[0], c[1], c[2], c[3], b.tape, &cb2, &clin2);
                take_error(th, t, &t->box_errors);
                t->taped_differ += !same_box(&cb, &cb2) || cb.tape != cb2.tape;
                /* and no wider where the whole program's is bounded: a
                 * decided operation that took the dead side (whose values
                 * the plan leaves unbounded) would give an unbounded box,
                 * which holds every point */
                trace_box zb;
                trace_surface_box_lin(th, obj, c[0], c[1], c[2], c[3], &zb, NULL);
                take_error(th, t, &t->box_errors);
                t->taped_unbounded += unbounded_box(&cb) && !unbounded_box(&zb);
                for (int i = 0; i < RANDOM_POINTS / 2; i++) {
                    double u = c[0] + (c[1] - c[0]) * corpus_rng_uniform(&rng);
                    double v = c[2] + (c[3] - c[2]) * corpus_rng_uniform(&rng);
                    check_point(th, obj, &cb, &clin, NULL, NULL, c, u, v, t);
                }
            }
    }
    free(view);
}

static void run_surface(corpus_surface s)
{
    static const trace_arith ariths[] = {TRACE_ARITH_AFFINE, TRACE_ARITH_INTERVAL};
    long ncases = corpus_env_long("AAFARM_CORPUS_CASES", 1000);
    long bad_rows = 0, failed_opens = 0;
    tally total;
    memset(&total, 0, sizeof total);
    printf("%-20s %-9s %-8s %6s %7s %7s %6s %8s %5s %5s %9s %9s\n", "shader", "surface",
           "arith", "cases", "points", "viol", "unbnd", "wide-unb", "berr", "perr", "worst",
           "unb-side");
    for (int i = 0; i < C.nshaders; i++)
        for (int a = 0; a < 2; a++) {
            fixture f;
            if (!corpus_open(&f, &C, &C.shaders[i], s, ariths[a], 64, 48, false)) {
                printf("%-20s %-9s %-8s did not open (see above)\n", C.shaders[i].name,
                       corpus_surface_name(s), trace_arith_name(ariths[a]));
                failed_opens++;
                fixture_close(&f);
                continue;
            }
            trace_thread *th = trace_thread_new(&f.js->world);
            tally t;
            memset(&t, 0, sizeof t);
            t.unb_side = INFINITY;
            run_cases(th, &f.js->world, ncases, 0x5eed0000u + (uint64_t)i * 16 + (uint64_t)s, &t);
            bool bad = t.violations || t.unbounded || t.box_errors || t.point_errors ||
                       t.plain_differ || t.taped_unbounded || t.taped_differ;
            printf("%-20s %-9s %-8s %6ld %7ld %7ld %6ld %8ld %5ld %5ld %9.2e %9.2e%s\n",
                   C.shaders[i].name, corpus_surface_name(s), trace_arith_name(ariths[a]),
                   t.cases, t.points, t.violations, t.unbounded, t.unbounded_wide,
                   t.box_errors, t.point_errors, t.worst,
                   t.unbounded + t.unbounded_wide ? t.unb_side : 0.0, bad ? "  FAIL" : "");
            if (t.error[0]) printf("    first shader error: %s\n", t.error);
            bad_rows += bad;
            total.cases += t.cases;
            total.points += t.points;
            total.slab_points += t.slab_points;
            total.restricted_points += t.restricted_points;
            total.split += t.split;
            total.split_first += t.split_first;
            total.split_lin += t.split_lin;
            total.split_plain += t.split_plain;
            total.plain_differ += t.plain_differ;
            total.violations += t.violations;
            total.unbounded += t.unbounded;
            total.unbounded_wide += t.unbounded_wide;
            total.box_errors += t.box_errors;
            total.point_errors += t.point_errors;
            total.undefined += t.undefined;
            total.taped += t.taped;
            total.taped_unbounded += t.taped_unbounded;
            total.taped_differ += t.taped_differ;
            if (t.worst > total.worst) total.worst = t.worst;
            trace_thread_destroy(&th);
            fixture_close(&f);
        }
    printf("%s total: %ld cases, %ld points (%ld also against a slab, %ld checks against "
           "restricted bounds), %ld boxes narrowed by "
           "case splits (%ld of the cases first, %ld with a linear bound; %ld split nothing, "
           "%ld of them not the plain "
           "box), %ld violations (worst %.2e), %ld unbounded boxes "
           "(+ %ld of ranges wider than 1/32, counted), %ld/%ld shader errors (box/point), "
           "%ld failing rows, %ld scenes not opened, %ld undefined points (NaN on a "
           "base's axis), %ld children boxed with their range's tape (%ld unbounded "
           "where the whole program's box is not, %ld not the same made again)\n",
           corpus_surface_name(s), total.cases, total.points, total.slab_points,
           total.restricted_points, total.split,
           total.split_first, total.split_lin, total.split_plain, total.plain_differ, total.violations, total.worst,
           total.unbounded, total.unbounded_wide, total.box_errors, total.point_errors,
           bad_rows, failed_opens, total.undefined, total.taped, total.taped_unbounded,
           total.taped_differ);
    fflush(stdout);
    assert_int_equal(failed_opens, 0);
    assert_true(total.points > 0);
    assert_true(total.slab_points > total.points / 20);
    assert_true(total.restricted_points > total.points / 2);   /* the lazy children's bounds */
    const char *only = getenv("AAFARM_CORPUS_ONLY");
    if (!only || !*only) {
        assert_true(total.split > 0);      /* the split path is checked */
        assert_true(total.split_lin > 0);  /* and the cases' linear bounds */
        assert_true(total.taped > 0);      /* and tape pruning's children */
    }
    assert_int_equal(total.violations, 0);
    assert_int_equal(total.plain_differ, 0);
    assert_int_equal(total.taped_unbounded, 0);
    assert_int_equal(total.taped_differ, 0);
    assert_int_equal(total.unbounded, 0);
    assert_int_equal(total.box_errors + total.point_errors, 0);
}

static void test_corpus_size(void **state)
{
    (void)state;
    printf("corpus: %d shaders, %d headers\n", C.nshaders, C.nheaders);
    const char *only = getenv("AAFARM_CORPUS_ONLY");
    if (!only || !*only) assert_true(C.nshaders >= 40);
    assert_true(C.nshaders >= 1);
}

static void test_plane(void **state) { (void)state; run_surface(CORPUS_PLANE); }
static void test_sphere(void **state) { (void)state; run_surface(CORPUS_SPHERE); }
static void test_ellipsoid(void **state) { (void)state; run_surface(CORPUS_ELLIPSOID); }
static void test_cylinder(void **state) { (void)state; run_surface(CORPUS_CYLINDER); }
static void test_patch(void **state) { (void)state; run_surface(CORPUS_PATCH); }
static void test_mesh(void **state) { (void)state; run_surface(CORPUS_MESH); }
static void test_subdiv(void **state) { (void)state; run_surface(CORPUS_SUBDIV); }
static void test_nurbs(void **state) { (void)state; run_surface(CORPUS_NURBS); }
static void test_apex(void **state) { (void)state; run_surface(CORPUS_APEX); }
static void test_collapsed(void **state) { (void)state; run_surface(CORPUS_COLLAPSED); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_corpus_size),
        cmocka_unit_test(test_plane),
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_ellipsoid),
        cmocka_unit_test(test_cylinder),
        cmocka_unit_test(test_patch),
        cmocka_unit_test(test_mesh),
        cmocka_unit_test(test_subdiv),
        cmocka_unit_test(test_nurbs),
        cmocka_unit_test(test_apex),
        cmocka_unit_test(test_collapsed),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

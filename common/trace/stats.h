/*
 * stats.h: render statistics (what `--stats` prints and `--stats-json`
 * writes): rays, boxes, shader evaluations per mode, leaves by kind, box
 * cache hits / misses / evictions / peak bytes. Each thread counts its own
 * (thread.h); totals are sums, the peak is the largest thread's.
 */
#ifndef TRACE_STATS_H
#define TRACE_STATS_H

#include <stddef.h>
#include <stdio.h>

typedef struct trace_stats {
    long primary_rays, shadow_rays;
    long boxes;                    /* boxes computed (root + 4 per cache miss) */
    long evals_affine, evals_interval, evals_dual, evals_float;
    long evals_slopes;             /* interval runs with slope bounds (prove.c) */
    long uniform_hits;             /* affine operations the VM's uniform memo
                                      answered (sl_vm_uniform_hits) */
    long normal_hits;              /* box normals the normal memo answered
                                      (normal_memo.c) */
    long tape_runs;                /* box runs that took a tape plan: the
                                      decisions of their node (tape pruning,
                                      displace.c) */
    long tape_plans;               /* tape plans made (tape_memo.c) */
    long leaves, wall_leaves, depth_cap_leaves;
    long proofs;                   /* hit proofs tried (prove.c) */
    long proven_hits;              /* leaves whose hit was proven unique and
                                      placed at the root */
    long proven_misses;            /* cells proven free of any hit */
    long leaf_tests;               /* of the proofs, on leaves whose point did not settle */
    long leaf_starts;              /* leaves whose Newton steps started on their
                                      box's linear bound, not at the cell's
                                      centre (intersect.c, leaf_start) */
    long exact_cells;              /* undisplaced cells intersected exactly
                                      (intersect.c, exact_cell) */
    long offset_cells;             /* of them, cells of the base moved by a
                                      constant (TRACE_BOX_OFFSET) */
    long plane_cells;              /* cells of parallel planes (TRACE_BOX_PLANES)
                                      a ray crossed into (intersect.c, planes_cell) */
    long plane_hits;               /* of them, settled by a hit on the plane
                                      it crossed first */
    long plane_misses;             /* or by passing the cell outside the band */
    long planar_cells;             /* cells of one tilted plane (TRACE_BOX_PLANAR)
                                      intersected exactly (intersect.c, planar_cell) */
    long rejected_leaves;          /* leaves whose surface point was not on the
                                      ray (depth cap) or not finite: no hit */
    long nodes;                    /* quadtree nodes visited by all rays */
    long limited_rays;             /* walks stopped by the work limit */
    long samplings;                /* stagnant boxes sampled (intersect.c,
                                      sample_stagnant), replaced or not */
    long sampled_boxes;            /* of them, boxes replaced by the samples */
    long empty_boxes;              /* boxes that were NaN: no point of the
                                      range is defined (pruned, counted) */
    long views_made;               /* mesh pieces made into objects (mesh.c) */
    long views_asked;              /* views asked of the thread's cache (mesh.c) */
    long lazy_roots;               /* displaced pieces' root boxes this thread
                                      made first and published (mesh.c,
                                      lazy_roots.h) */
    long lazy_bounds;              /* children made as restricted bounds only
                                      (intersect.c, "lazy children") */
    long lazy_met;                 /* times a ray met such a bound and took
                                      the child into its walk's order */
    long lazy_evals;               /* children made as bounds, evaluated when
                                      a walk reached one (their runs count in
                                      boxes too): a bound met beyond the
                                      ray's hit is never evaluated */
    long max_nodes_per_ray;        /* the largest walk (a peak, not a sum) */
    long cache_hits, cache_misses, cache_evictions;
    size_t cache_peak_bytes;
} trace_stats;

void trace_stats_add(trace_stats *into, const trace_stats *from);

/* A readable table (one "name value" line each). */
void trace_stats_print(const trace_stats *s, FILE *out);

/* One JSON object (no trailing newline); extra: more "key": value pairs to
 * put first (already formatted, may be NULL or ""). */
void trace_stats_write_json(const trace_stats *s, const char *extra, FILE *out);

#endif

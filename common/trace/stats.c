/*
 * stats.c: adding, printing and writing render statistics (see stats.h).
 */
#include "trace/stats.h"

#define STATS_FIELDS(X) \
    X(primary_rays) X(shadow_rays) X(boxes) X(evals_affine) X(evals_interval) \
    X(evals_dual) X(evals_float) X(evals_slopes) X(uniform_hits) X(normal_hits) X(tape_runs) X(tape_plans) X(leaves) X(wall_leaves) \
    X(depth_cap_leaves) X(proofs) X(proven_hits) X(proven_misses) X(leaf_tests) X(leaf_starts) \
    X(exact_cells) X(offset_cells) X(plane_cells) X(plane_hits) X(plane_misses) X(planar_cells) X(views_made) X(views_asked) \
    X(lazy_roots) X(lazy_bounds) X(lazy_met) X(lazy_evals) \
    X(rejected_leaves) X(nodes) X(limited_rays) X(samplings) X(sampled_boxes) X(empty_boxes) \
    X(cache_hits) X(cache_misses) X(cache_evictions)

void trace_stats_add(trace_stats *into, const trace_stats *from)
{
#define ADD(f) into->f += from->f;
    STATS_FIELDS(ADD)
#undef ADD
    if (from->max_nodes_per_ray > into->max_nodes_per_ray)
        into->max_nodes_per_ray = from->max_nodes_per_ray;
    if (from->cache_peak_bytes > into->cache_peak_bytes)
        into->cache_peak_bytes = from->cache_peak_bytes;
}

void trace_stats_print(const trace_stats *s, FILE *out)
{
#define PRINT(f) fprintf(out, "  %-18s %ld\n", #f, s->f);
    STATS_FIELDS(PRINT)
#undef PRINT
    fprintf(out, "  %-18s %ld\n", "max_nodes_per_ray", s->max_nodes_per_ray);
    fprintf(out, "  %-18s %zu\n", "cache_peak_bytes", s->cache_peak_bytes);
    long rays = s->primary_rays + s->shadow_rays;
    if (rays > 0)
        fprintf(out, "  %-18s %.2f\n", "boxes_per_ray", (double)s->boxes / (double)rays);
    long lookups = s->cache_hits + s->cache_misses;
    if (lookups > 0)
        fprintf(out, "  %-18s %.1f%%\n", "cache_hit_rate", 100.0 * (double)s->cache_hits / (double)lookups);
}

void trace_stats_write_json(const trace_stats *s, const char *extra, FILE *out)
{
    fputc('{', out);
    if (extra && *extra) fprintf(out, "%s, ", extra);
#define JSON(f) fprintf(out, "\"%s\": %ld, ", #f, s->f);
    STATS_FIELDS(JSON)
#undef JSON
    fprintf(out, "\"max_nodes_per_ray\": %ld, ", s->max_nodes_per_ray);
    fprintf(out, "\"cache_peak_bytes\": %zu}", s->cache_peak_bytes);
}

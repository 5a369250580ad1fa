/*
 * report.c: what the master tells at the end of a render: the summary per
 * worker on stderr (tiles, seconds, bytes; docs/farm.md "Summary") and the
 * statistics file of --stats-json (the same numbers, the farm's counters
 * and the render statistics summed over every tile taken).
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>
#include <sys/resource.h>

#include "farm_internal.h"
#include "json_out.h"
#include "util/err.h"

static const char *state_name(farm_state s)
{
    switch (s) {
    case FARM_DONE: return "done";
    case FARM_FAILED: return "failed";
    case FARM_INTERRUPTED: return "interrupted";
    case FARM_NO_WORKERS: return "no workers";
    default: return "running";
    }
}

/* The state column: connected, blocklisted (connected, given nothing), or
 * why it was retired. */
static const char *worker_state(const farm_worker *w)
{
    return !w->alive       ? w->gone
           : w->blocked    ? "blocklisted"
           : w->benched    ? "benched"
           : w->other_pool ? "not in the job's pool"
                           : "connected";
}

static void human_bytes(uint64_t b, char *buf, size_t n)
{
    if (b < 10u * 1024) snprintf(buf, n, "%llu B", (unsigned long long)b);
    else if (b < 10u * 1024 * 1024) snprintf(buf, n, "%.1f KB", (double)b / 1024.0);
    else snprintf(buf, n, "%.1f MB", (double)b / (1024.0 * 1024.0));
}

void farm_report_summary(const farm *f)
{
    if (f->opt->verbosity < 0 || registry_count(f->reg) == 0) return;
    fprintf(stderr, "aafarm-master: summary per worker\n");
    bool files = f->frames[0].jb->nfiles > 0;   /* the file columns only for a job with files */
    fprintf(stderr, "  %-20s %-14s %6s %5s %5s %9s %9s %10s %10s", "worker", "host", "tiles",
            "dup", "fail", "render s", "cpu s", "bytes in", "bytes out");
    if (files) fprintf(stderr, " %10s %9s", "file bytes", "hit/miss");
    fprintf(stderr, "  %s\n", "state");
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        const farm_worker *w = registry_at(f->reg, i);
        char in[32], out[32], fb[32], hm[32];
        human_bytes(w->bytes_in, in, sizeof in);
        human_bytes(w->bytes_out, out, sizeof out);
        fprintf(stderr, "  %-20.20s %-14.14s %6llu %5llu %5llu %9.2f %9.2f %10s %10s",
                w->name, w->host, (unsigned long long)w->tiles, (unsigned long long)w->duplicates,
                (unsigned long long)w->failures, w->render_seconds, w->cpu_seconds, in, out);
        if (files) {
            human_bytes(w->file_bytes, fb, sizeof fb);
            snprintf(hm, sizeof hm, "%llu/%llu", (unsigned long long)w->file_hits,
                     (unsigned long long)w->file_misses);
            fprintf(stderr, " %10s %9s", fb, w->files_ready ? hm : "-");
        }
        fprintf(stderr, "  %s\n", worker_state(w));
    }
    scheduler_counts c;
    scheduler_counts_get(f->sched, &c);
    fprintf(stderr, "  job %zu bytes per worker; %llu grants (%llu duplicates), %llu requeued, "
            "%llu failed, %llu malformed messages dropped\n", f->job_bytes,
            (unsigned long long)c.grants, (unsigned long long)c.duplicate_grants,
            (unsigned long long)c.requeued, (unsigned long long)c.failures,
            (unsigned long long)f->wstats.dropped);
    if (files) {
        char total[32], sent[32];
        human_bytes(job_files_bytes(f->frames[0].jb), total, sizeof total);
        human_bytes(f->file_bytes_sent, sent, sizeof sent);
        fprintf(stderr, "  files: %d of %s in the job, %s sent in %llu chunks (once per host; "
                "a hit is a file the host's store had)\n", f->frames[0].jb->nfiles, total, sent,
                (unsigned long long)f->file_chunks_sent);
    }
}

static void json_worker(FILE *out, const farm_worker *w)
{
    fputs("    {\"name\": ", out);
    json_out_string(out, w->name);
    fputs(", \"host\": ", out);
    json_out_string(out, w->host);
    fprintf(out, ", \"pid\": %u, \"threads\": %u, \"local\": %s, \"tiles\": %llu, "
            "\"duplicates\": %llu, \"failures\": %llu, \"invalid_tiles\": %llu, "
            "\"render_seconds\": %.6f, \"cpu_seconds\": %.6f, \"bytes_in\": %llu, "
            "\"bytes_out\": %llu, \"job_bytes\": %llu, \"file_bytes\": %llu, "
            "\"file_chunks\": %llu, \"file_hits\": %llu, \"file_misses\": %llu, "
            "\"file_seconds\": %.3f, \"state\": ",
            w->pid, w->threads, w->local ? "true" : "false", (unsigned long long)w->tiles,
            (unsigned long long)w->duplicates, (unsigned long long)w->failures,
            (unsigned long long)w->invalid_tiles, w->render_seconds, w->cpu_seconds,
            (unsigned long long)w->bytes_in, (unsigned long long)w->bytes_out,
            (unsigned long long)w->job_bytes, (unsigned long long)w->file_bytes,
            (unsigned long long)w->file_chunks, (unsigned long long)w->file_hits,
            (unsigned long long)w->file_misses,
            w->file_chunks && w->files_ready ? (double)(w->file_ready_ms - w->file_first_ms) / 1000.0
                                              : 0.0);
    json_out_string(out, worker_state(w));
    fputc('}', out);
}

static void json_totals(FILE *out, const farm *f)
{
    uint64_t rays = 0, boxes = 0, evals = 0, hits = 0, misses = 0, evictions = 0, peak = 0;
    double render = 0, cpu = 0;
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        const farm_worker *w = registry_at(f->reg, i);
        rays += w->rays;
        boxes += w->boxes;
        evals += w->shader_evals;
        hits += w->cache_hits;
        misses += w->cache_misses;
        evictions += w->cache_evictions;
        if (w->peak_cache_bytes > peak) peak = w->peak_cache_bytes;
        render += w->render_seconds;
        cpu += w->cpu_seconds;
    }
    fprintf(out, "  \"render\": {\"rays\": %llu, \"boxes\": %llu, \"shader_evals\": %llu, "
            "\"cache_hits\": %llu, \"cache_misses\": %llu, \"cache_evictions\": %llu, "
            "\"peak_cache_bytes\": %llu, \"render_seconds\": %.6f, \"cpu_seconds\": %.6f},\n",
            (unsigned long long)rays, (unsigned long long)boxes, (unsigned long long)evals,
            (unsigned long long)hits, (unsigned long long)misses, (unsigned long long)evictions,
            (unsigned long long)peak, render, cpu);
}

/* CPU seconds of the master process itself (user + system). */
static double master_cpu_seconds(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
    return (double)ru.ru_utime.tv_sec + (double)ru.ru_utime.tv_usec * 1e-6 +
           (double)ru.ru_stime.tv_sec + (double)ru.ru_stime.tv_usec * 1e-6;
}

/* The master's peak resident memory (KiB). */
static long master_peak_rss_kb(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_maxrss : 0;
}

static void json_farm(FILE *out, const farm *f)
{
    scheduler_counts c;
    scheduler_counts_get(f->sched, &c);
    double per_grant = c.grants ? (double)f->grant_bytes / (double)c.grants : 0;
    uint64_t job_bytes_sent = 0;   /* every Job sent, of every frame */
    for (size_t i = 0; i < registry_count(f->reg); i++)
        job_bytes_sent += registry_at(f->reg, i)->job_bytes;
    fprintf(out, "  \"farm\": {\"job_bytes\": %zu, \"job_bytes_sent\": %llu, "
            "\"jobs_sent\": %llu, \"grant_bytes_per_tile\": "
            "%.1f, \"result_bytes\": %llu, \"bytes_sent\": %llu, \"grants\": %llu, "
            "\"duplicate_grants\": %llu, \"requeued\": %llu, \"expired_leases\": %llu, "
            "\"duplicate_results\": %llu, \"stale_results\": %llu, \"failures\": %llu, "
            "\"invalid_tiles\": %llu, \"malformed_messages\": %llu, \"rejects_sent\": %llu, "
            "\"version_mismatches\": %llu, \"disconnects\": %llu, \"nonfinite_samples\": %llu, "
            "\"handshake_failures\": %llu, \"auth_refusals\": %llu, \"max_bulk_bytes\": %zu, "
            "\"master_cpu_seconds\": %.3f, \"master_peak_rss_kb\": %ld, \"files\": %d, "
            "\"files_bytes\": %llu, \"file_bytes_sent\": %llu, \"file_chunks_sent\": %llu},\n",
            f->job_bytes, (unsigned long long)job_bytes_sent, (unsigned long long)f->jobs_sent,
            per_grant,
            (unsigned long long)f->result_bytes, (unsigned long long)f->sent_bytes,
            (unsigned long long)c.grants, (unsigned long long)c.duplicate_grants,
            (unsigned long long)c.requeued, (unsigned long long)c.expired,
            (unsigned long long)c.duplicate_results, (unsigned long long)c.stale_results,
            (unsigned long long)c.failures, (unsigned long long)f->invalid_tiles,
            (unsigned long long)f->wstats.dropped, (unsigned long long)f->rejects_sent,
            (unsigned long long)f->version_mismatches, (unsigned long long)f->wstats.disconnects,
            (unsigned long long)f->nonfinite_samples,
            (unsigned long long)f->wstats.handshake_failures,
            (unsigned long long)zap_refused(f->zap), f->limits.max_bulk_bytes,
            master_cpu_seconds(), master_peak_rss_kb(), f->frames[0].jb->nfiles,
            (unsigned long long)job_files_bytes(f->frames[0].jb), (unsigned long long)f->file_bytes_sent,
            (unsigned long long)f->file_chunks_sent);
}

bool farm_report_json(const farm *f, const char *path, char *err, size_t errsz)
{
    FILE *out = fopen(path, "w");
    if (!out) {
        err_set(err, errsz, "cannot write %s: %s", path, strerror(errno));
        return false;
    }
    fputs("{\n  \"scene\": ", out);
    json_out_string(out, f->opt->scene_path);
    fputs(", \"output\": ", out);
    json_out_string(out, f->frames[0].output);
    fprintf(out, ", \"status\": \"%s\", \"error\": ", state_name(f->state));
    json_out_string(out, f->state == FARM_FAILED ? f->failure : "");
    fprintf(out, ",\n  \"width\": %d, \"height\": %d, \"tile_size\": %d, \"tiles\": %d, "
            "\"tiles_done\": %d, \"resumed_tiles\": %d, \"seconds\": %.6f, "
            "\"job_hash\": \"%s\", \"frames\": %d, \"frames_written\": %d,\n",
            f->fmt.width, f->fmt.height, f->fmt.tile_size, f->ntiles,
            scheduler_tiles_done(f->sched), f->resumed_tiles, (double)(f->end_ms - f->start_ms) / 1000.0, f->frames[0].jb->hash,
            f->nframes, f->frames_written);
    json_farm(out, f);
    json_totals(out, f);
    fputs("  \"workers\": [\n", out);
    for (size_t i = 0; i < registry_count(f->reg); i++) {
        json_worker(out, registry_at(f->reg, i));
        fputs(i + 1 < registry_count(f->reg) ? ",\n" : "\n", out);
    }
    fputs("  ]\n}\n", out);
    bool failed = ferror(out) != 0;
    if (fclose(out) != 0 || failed) {
        err_set(err, errsz, "cannot write %s: %s", path,
                strerror(errno ? errno : EIO));
        unlink(path);   /* no half-written statistics file */
        return false;
    }
    return true;
}

/*
 * main.c: the aafarm-master command line (docs/farm.md).
 *
 *   aafarm-master SCENE.rib -o OUT.exr [--bind ENDPOINT] [--local-workers N] ...
 *
 * Everything is read, parsed and compiled here, before any worker is
 * started or contacted (job_load: the same diagnostics as the standalone
 * renderer, exit 3); farm_run() does the rest.
 */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "curve_cert.h"
#include "farm.h"
#include "http_access.h"
#include "job/frames.h"
#include "message.h"
#include "serve.h"
#include "util/cli.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "util/parse_num.h"
#include "util/xalloc.h"

static void usage(FILE *out)
{
    fprintf(out,
        "usage: aafarm-master SCENE.rib [-o OUT.exr] [--frames LIST] [options]\n"
        "       aafarm-master --serve [--db FILE] --http [ADDR:]PORT [options]\n"
        "\n"
        "Renders a RenderMan scene with procedural displacement shaders on a farm of\n"
        "aafarm-worker processes (ZeroMQ) and stitches their EXR tiles into OUT.exr.\n"
        "With no --bind it starts its own local workers and stops them at the end.\n"
        "\n"
        "  -o, --output OUT.exr       output file (tiled OpenEXR, written via a temporary\n"
        "                             file, renamed only when complete); default: the\n"
        "                             frame's Display name. A file of several frames\n"
        "                             writes one EXR per frame: %%04d in the name is the\n"
        "                             frame number, else it goes before the extension\n"
        "  --frames LIST              frames to render by FrameBegin number: 3, 1-10,\n"
        "                             1,3,5-7 (default: all; their tiles share one queue)\n"
        "  --bind ENDPOINT            also wait for remote workers, e.g. tcp://*:5555\n"
        "  --local-workers N          worker processes to start here (default: the number\n"
        "                             of cores without --bind, 0 with it)\n"
        "  --threads-per-worker N     --threads of each local worker (default 1)\n"
        "  --tile S                   tile size in pixels (default 32)\n"
        "  --arith affine|interval    bounding arithmetic (default affine)\n"
        "  --budget N                 shader instruction budget per evaluation (default 1000000)\n"
        "  --preview OUT.png          also write an sRGB PNG preview\n"
        "  --stats-json FILE          write the summary and statistics as JSON\n"
        "  --heartbeat MS             heartbeat interval announced to workers (default 1000)\n"
        "  --liveness N               a worker is dead after N silent intervals (default 3)\n"
        "  --retries N                failures of one tile before the job fails (default 3)\n"
        "  --lease S                  the longest a leased tile waits before it is handed\n"
        "                             out again (120 s)\n"
        "  --lease-factor N           a lease lasts N x its worker's measured time per tile\n"
        "                             (at least 2 s, at most --lease; default 4, 0: --lease)\n"
        "  --duplicates N             end-game duplicate leases per tile (default 1, 0: off)\n"
        "  --worker-binary PATH       aafarm-worker to start (default: next to this program)\n"
        "  --max-workers N            workers served at a time; more are refused (1024)\n"
        "  --pool NAME                only workers started with --pool NAME get tiles (with\n"
        "                             --bind; local workers have no pool)\n"
        "  --min-workers N            grant no tile before N workers have joined (alive at\n"
        "                             once); says \"K of N joined\" meanwhile (default 1)\n"
        "  --wait-timeout S           give up with exit status 4 when fewer than\n"
        "                             --min-workers (or no worker at all) joined within S\n"
        "                             seconds, or no worker was alive for S seconds\n"
        "                             (default: wait for ever; the journal is kept)\n"
        "  --curve-secret FILE        CurveZMQ on --bind: this master's NAME.key_secret\n"
        "                             (aafarm-keygen NAME); needs --allow-keys\n"
        "  --allow-keys DIR           the workers' public keys (NAME.key files) that may\n"
        "                             connect; others are refused and logged\n"
        "  --insecure                 allow --bind on a network address without CURVE\n"
        "                             (anyone who reaches it can join; not recommended)\n"
        "  --http [ADDR:]PORT         serve a live monitor of the render (a web page and a\n"
        "                             JSON API: docs/farm.md) on 127.0.0.1:PORT, or ADDR\n"
        "                             (0.0.0.0 or *: every interface; needs a token); port\n"
        "                             0: any free one, named in the log\n"
        "  --http-token-file FILE     the monitor's token, on the first line of FILE (16 to\n"
        "                             256 printable characters); requests carry it as\n"
        "                             ?token=TOKEN or Authorization: Bearer TOKEN\n"
        "  --http-token TOKEN         the same on the command line (visible in ps)\n"
        "  --http-linger S            keep serving the monitor S seconds after the end\n"
        "  --resume                   continue an unfinished render of the same job: the\n"
        "                             tiles in OUT.exr.journal are kept, only the others\n"
        "                             are rendered (every render journals its tiles there)\n"
        "  --serve                    keep the workers and render a queue of jobs, submitted\n"
        "                             with aafarm-submit --master http://ADDR:PORT (or POST\n"
        "                             /api/jobs), one after another by priority (the next\n"
        "                             job's tiles go out while the last ones of the job\n"
        "                             before are rendered), until SIGINT/SIGTERM\n"
        "                             (docs/farm.md, \"A job queue\")\n"
        "  --db FILE                  --serve: the queue's SQLite database (default\n"
        "                             aafarm-queue.db); a master restarted on it resumes\n"
        "                             every unfinished job\n"
        "  -q, --quiet                only errors;  -v, --verbose  every grant and tile\n"
        "  -h, --help                 this text\n"
        "\n"
        "At the end it prints a summary per worker: tiles taken, duplicates dropped,\n"
        "failures, render and CPU seconds, bytes received (tiles) and sent (job, grants).\n"
        "\n"
        "Exit status: 0 the image is complete, 1 the render failed (a tile failed on\n"
        "--retries workers, no workers left, output not writable), 2 usage (bad options\n"
        "or endpoint), 3 bad scene or shader (diagnostics printed, no worker contacted),\n"
        "4 --wait-timeout passed without enough workers (the journal is kept), 130\n"
        "interrupted by SIGINT/SIGTERM (no output file is left behind; the journal\n"
        "is, for --resume). --resume with another job's journal is a usage error (2).\n");
}

typedef struct cli {
    farm_options farm;
    char http_token[HTTP_TOKEN_MAX + 2];   /* --http-token(-file) */
    job_options job;
    bool local_given;
    bool serve;                            /* --serve */
    const char *db;                        /* --db */
} cli;

/* optarg as a whole number of lo..hi into *n; false after printing
 * "aafarm-master: OPT wants [NOUN ]LO..HI, got 'TEXT'". */
static bool number_arg(const char *opt, const char *noun, long lo, long hi, long *n)
{
    char err[ERR_LEN];
    if (parse_option_long(opt, noun, optarg, lo, hi, n, err, sizeof err)) return true;
    fprintf(stderr, "aafarm-master: %s\n", err);
    return false;
}

/* optarg as the job option opt (--tile, --arith, --budget) into *opts;
 * false after printing why. */
static bool job_arg(job_options *opts, const char *opt)
{
    char err[ERR_LEN];
    if (job_options_parse_arg(opts, opt, optarg, err, sizeof err)) return true;
    fprintf(stderr, "aafarm-master: %s\n", err);
    return false;
}

/* --http: a valid address; a token for one other hosts can reach (as
 * --bind wants CURVE). False after printing why. */
static bool check_http(const farm_options *f)
{
    if (!f->http) {
        if (f->http_token || f->http_linger_ms)
            fprintf(stderr, "aafarm-master: --http-token, --http-token-file and --http-linger go "
                    "with --http [ADDR:]PORT\n");
        return !f->http_token && !f->http_linger_ms;
    }
    http_addr addr;
    char err[ERR_LEN];
    if (!http_addr_parse(f->http, &addr, err, sizeof err)) {
        fprintf(stderr, "aafarm-master: %s\n", err);
        return false;
    }
    if (!addr.loopback && !f->http_token) {
        fprintf(stderr, "aafarm-master: --http %s is reachable from other hosts, and without a "
                "token anyone there could watch the render and take the image: give "
                "--http-token-file FILE (a line of 16 or more random characters: head -c 24 "
                "/dev/urandom | base64 > FILE), or serve a loopback address (--http "
                "127.0.0.1:%d)\n", f->http, addr.port);
        return false;
    }
    return true;
}

/* Returns -1 to go on, or an exit code. */
static int parse(int argc, char **argv, cli *c)
{
    enum { O_BIND = 256, O_LOCAL, O_TPW, O_TILE, O_ARITH, O_BUDGET, O_PREVIEW, O_STATS_JSON,
           O_HEARTBEAT, O_LIVENESS, O_RETRIES, O_LEASE, O_DUPS, O_WORKER_BIN, O_RESUME, O_MAX_WORKERS, O_FRAMES,
           O_CURVE_SECRET, O_ALLOW_KEYS, O_INSECURE, O_LEASE_FACTOR, O_HTTP, O_HTTP_TOKEN,
           O_HTTP_TOKEN_FILE, O_HTTP_LINGER, O_SERVE, O_DB, O_POOL, O_MIN_WORKERS,
           O_WAIT_TIMEOUT };
    static const struct option longopts[] = {
        {"output", required_argument, 0, 'o'},
        {"bind", required_argument, 0, O_BIND},
        {"local-workers", required_argument, 0, O_LOCAL},
        {"threads-per-worker", required_argument, 0, O_TPW},
        {"tile", required_argument, 0, O_TILE},
        {"arith", required_argument, 0, O_ARITH},
        {"budget", required_argument, 0, O_BUDGET},
        {"preview", required_argument, 0, O_PREVIEW},
        {"stats-json", required_argument, 0, O_STATS_JSON},
        {"heartbeat", required_argument, 0, O_HEARTBEAT},
        {"liveness", required_argument, 0, O_LIVENESS},
        {"retries", required_argument, 0, O_RETRIES},
        {"lease", required_argument, 0, O_LEASE},
        {"lease-factor", required_argument, 0, O_LEASE_FACTOR},
        {"duplicates", required_argument, 0, O_DUPS},
        {"worker-binary", required_argument, 0, O_WORKER_BIN},
        {"resume", no_argument, 0, O_RESUME},
        {"frames", required_argument, 0, O_FRAMES},
        {"max-workers", required_argument, 0, O_MAX_WORKERS},
        {"curve-secret", required_argument, 0, O_CURVE_SECRET},
        {"allow-keys", required_argument, 0, O_ALLOW_KEYS},
        {"insecure", no_argument, 0, O_INSECURE},
        {"http", required_argument, 0, O_HTTP},
        {"http-token", required_argument, 0, O_HTTP_TOKEN},
        {"http-token-file", required_argument, 0, O_HTTP_TOKEN_FILE},
        {"http-linger", required_argument, 0, O_HTTP_LINGER},
        {"serve", no_argument, 0, O_SERVE},
        {"db", required_argument, 0, O_DB},
        {"pool", required_argument, 0, O_POOL},
        {"min-workers", required_argument, 0, O_MIN_WORKERS},
        {"wait-timeout", required_argument, 0, O_WAIT_TIMEOUT},
        {"quiet", no_argument, 0, 'q'},
        {"verbose", no_argument, 0, 'v'},
        {"help", no_argument, 0, 'h'},
        {"version", no_argument, 0, 'V'},
        {0, 0, 0, 0}};
    farm_options *f = &c->farm;
    int ch;
    long n;
    opterr = 0;
    while ((ch = getopt_long(argc, argv, ":o:qvh", longopts, NULL)) != -1) {
        switch (ch) {
        case 'o': f->output = optarg; break;
        case O_BIND: f->bind = optarg; break;
        case O_LOCAL:
            if (!number_arg("--local-workers", NULL, 0, 1024, &n)) return AAFARM_EXIT_USAGE;
            f->local_workers = (int)n;
            c->local_given = true;
            break;
        case O_TPW:
            if (!number_arg("--threads-per-worker", NULL, 1, 1024, &n)) return AAFARM_EXIT_USAGE;
            f->threads_per_worker = (int)n;
            break;
        case O_TILE: if (!job_arg(&c->job, "--tile")) return AAFARM_EXIT_USAGE; break;
        case O_ARITH: if (!job_arg(&c->job, "--arith")) return AAFARM_EXIT_USAGE; break;
        case O_BUDGET: if (!job_arg(&c->job, "--budget")) return AAFARM_EXIT_USAGE; break;
        case O_PREVIEW: f->preview = optarg; break;
        case O_STATS_JSON: f->stats_json = optarg; break;
        case O_HEARTBEAT:
            if (!number_arg("--heartbeat", "milliseconds", 10, 3600000, &n)) return AAFARM_EXIT_USAGE;
            f->heartbeat_ms = (int)n;
            break;
        case O_LIVENESS:
            if (!number_arg("--liveness", NULL, 1, 1000, &n)) return AAFARM_EXIT_USAGE;
            f->liveness = (int)n;
            break;
        case O_RETRIES:
            if (!number_arg("--retries", NULL, 1, 1000, &n)) return AAFARM_EXIT_USAGE;
            f->max_attempts = (int)n;
            break;
        case O_LEASE:
            if (!number_arg("--lease", "seconds", 1, 86400, &n)) return AAFARM_EXIT_USAGE;
            f->lease_ms = n * 1000;
            break;
        case O_LEASE_FACTOR:
            if (!number_arg("--lease-factor", NULL, 0, 1000, &n)) return AAFARM_EXIT_USAGE;
            f->lease_factor = (int)n;
            break;
        case O_DUPS:
            if (!number_arg("--duplicates", NULL, 0, 100, &n)) return AAFARM_EXIT_USAGE;
            f->max_duplicates = (int)n;
            break;
        case O_WORKER_BIN: f->worker_binary = optarg; break;
        case O_RESUME: f->resume = true; break;
        case O_FRAMES: {
            frame_spec spec;
            char err[ERR_LEN];
            if (!frame_spec_parse(optarg, &spec, err, sizeof err)) {
                fprintf(stderr, "aafarm-master: %s\n", err);
                return AAFARM_EXIT_USAGE;
            }
            frame_spec_clear(&spec);
            f->frames = optarg;
            break;
        }
        case O_MAX_WORKERS:
            if (!number_arg("--max-workers", NULL, 1, 65536, &n)) return AAFARM_EXIT_USAGE;
            f->max_workers = (int)n;
            break;
        case O_CURVE_SECRET: f->curve_secret = optarg; break;
        case O_ALLOW_KEYS: f->allow_keys = optarg; break;
        case O_INSECURE: f->insecure = true; break;
        case O_HTTP: f->http = optarg; break;
        case O_HTTP_TOKEN:
        case O_HTTP_TOKEN_FILE: {
            char err[ERR_LEN];
            if (!http_token_option(optarg, ch == O_HTTP_TOKEN_FILE, c->http_token,
                                   sizeof c->http_token, err, sizeof err)) {
                fprintf(stderr, "aafarm-master: %s\n", err);
                return AAFARM_EXIT_USAGE;
            }
            f->http_token = c->http_token;
            break;
        }
        case O_HTTP_LINGER:
            if (!number_arg("--http-linger", "seconds", 0, 86400, &n)) return AAFARM_EXIT_USAGE;
            f->http_linger_ms = n * 1000;
            break;
        case O_SERVE: c->serve = true; break;
        case O_DB: c->db = optarg; break;
        case O_POOL: {
            char err[ERR_LEN];
            if (!proto_pool_name_check(optarg, err, sizeof err)) {
                fprintf(stderr, "aafarm-master: --pool: %s\n", err);
                return AAFARM_EXIT_USAGE;
            }
            f->pool = optarg;
            break;
        }
        case O_MIN_WORKERS:
            if (!number_arg("--min-workers", NULL, 1, 65536, &n)) return AAFARM_EXIT_USAGE;
            f->min_workers = (int)n;
            break;
        case O_WAIT_TIMEOUT:
            if (!number_arg("--wait-timeout", "seconds", 1, 31536000L, &n)) return AAFARM_EXIT_USAGE;
            f->wait_timeout_ms = n * 1000;
            break;
        case 'q': f->verbosity = -1; break;
        case 'v': f->verbosity = 1; break;
        case 'h': usage(stdout); return AAFARM_EXIT_OK;
        case 'V': printf("aafarm-master %s\n", cli_version()); return AAFARM_EXIT_OK;
        default: {
            char line[512];
            cli_option_problem(ch, optind, optopt, argv, line, sizeof line);
            fprintf(stderr, "aafarm-master: %s\n", line);
            return AAFARM_EXIT_USAGE;
        }
        }
    }
    if (optind < argc) f->scene_path = argv[optind++];
    if (optind < argc) {
        fprintf(stderr, "aafarm-master: unexpected argument '%s' (see --help)\n", argv[optind]);
        return AAFARM_EXIT_USAGE;
    }
    if (c->db && !c->serve) {
        fprintf(stderr, "aafarm-master: --db FILE goes with --serve (the job queue's database)\n");
        return AAFARM_EXIT_USAGE;
    }
    if (c->serve) {
        const char *what = f->scene_path ? f->scene_path : f->output ? "-o" : f->frames ? "--frames"
                           : f->resume ? "--resume" : f->preview ? "--preview"
                           : f->stats_json ? "--stats-json" : f->http_linger_ms ? "--http-linger"
                           : f->pool ? "--pool" : NULL;
        if (what) {
            fprintf(stderr, "aafarm-master: --serve renders the jobs submitted to it: '%s' goes "
                    "with one scene (aafarm-submit --master URL SCENE.rib -o OUT.exr sends "
                    "one)\n", what);
            return AAFARM_EXIT_USAGE;
        }
        if (!c->db) c->db = "aafarm-queue.db";
    } else if (!f->scene_path) {
        fprintf(stderr, "aafarm-master: which scene? usage: aafarm-master SCENE.rib -o OUT.exr "
                "(see --help)\n");
        return AAFARM_EXIT_USAGE;
    }
    if (!f->curve_secret != !f->allow_keys) {
        fprintf(stderr, "aafarm-master: --curve-secret and --allow-keys go together (the "
                "master's key, and the workers' keys it admits)\n");
        return AAFARM_EXIT_USAGE;
    }
    if (f->curve_secret && !f->bind) {
        fprintf(stderr, "aafarm-master: --curve-secret secures --bind ENDPOINT; without --bind "
                "the local workers use a private ipc:// socket\n");
        return AAFARM_EXIT_USAGE;
    }
    if (f->curve_secret && f->insecure) {
        fprintf(stderr, "aafarm-master: --insecure and --curve-secret exclude each other\n");
        return AAFARM_EXIT_USAGE;
    }
    if (f->bind && !f->curve_secret && !f->insecure && !curve_endpoint_is_local(f->bind)) {
        fprintf(stderr, "aafarm-master: --bind %s is reachable from other hosts, and without "
                "CURVE anyone there could take the job and send tiles: give --curve-secret "
                "FILE --allow-keys DIR (docs/cluster.md), bind a loopback address "
                "(tcp://127.0.0.1:PORT), or say --insecure\n", f->bind);
        return AAFARM_EXIT_USAGE;
    }
    if (!check_http(f)) return AAFARM_EXIT_USAGE;
    if (f->bind && !c->local_given) f->local_workers = 0;
    if (f->local_workers > f->max_workers) {
        fprintf(stderr, "aafarm-master: --local-workers %d is more than --max-workers %d\n",
                f->local_workers, f->max_workers);
        return AAFARM_EXIT_USAGE;
    }
    if (f->min_workers > f->max_workers) {
        fprintf(stderr, "aafarm-master: --min-workers %d is more than --max-workers %d: the "
                "render could never start\n", f->min_workers, f->max_workers);
        return AAFARM_EXIT_USAGE;
    }
    if (!f->bind && f->min_workers > f->local_workers) {
        fprintf(stderr, "aafarm-master: --min-workers %d without --bind: only the %d local "
                "workers can join, so the render could never start (give --bind ENDPOINT for "
                "remote workers, or --local-workers %d)\n", f->min_workers, f->local_workers,
                f->min_workers);
        return AAFARM_EXIT_USAGE;
    }
    if (!f->bind && f->local_workers == 0) {
        fprintf(stderr, "aafarm-master: --local-workers 0 without --bind: no worker could "
                "ever connect\n");
        return AAFARM_EXIT_USAGE;
    }
    return -1;
}

/* The loaded frames and their outputs. */
typedef struct loaded {
    frame_sequence *seq;
    farm_frame_in *frames;
    char **previews;
} loaded;

static void loaded_free(loaded *l)
{
    for (int i = 0; l->seq && l->previews && i < l->seq->count; i++) free(l->previews[i]);
    free(l->previews);
    free(l->frames);
    frame_sequence_destroy(&l->seq);
}

/* The scene text travels in the job message, whose limit a peer enforces
 * (proto_limits): a file over it is refused here, from its size, before
 * minutes of parsing, with the way out. false with the message in err. */
static bool scene_fits_the_job(const char *path, char *err, size_t errsz)
{
    struct stat st;
    size_t limit = proto_limits_default().max_text_bytes;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode) || (uint64_t)st.st_size <= limit)
        return true;   /* not there or not a file: job_load says so */
    return err_set(err, errsz,
                   "%s: %llu bytes of scene text, the farm ships at most %zu (%zu MiB) in a job: "
                   "render it on one host with aafarm-worker --standalone, which has no such "
                   "limit, or make the file smaller",
                   path, (unsigned long long)st.st_size, limit, limit >> 20);
}

/* Loads and checks the job of every chosen frame; finds their image
 * sizes. Exit code or -1. */
static int load(cli *c, loaded *l)
{
    sl_diag *diag = sl_diag_new();
    bool usage = false;
    char too_big[ERR_LEN];
    if (!scene_fits_the_job(c->farm.scene_path, too_big, sizeof too_big)) {
        sl_diag_error(diag, (sl_pos){0}, "%s", too_big);
        sl_diag_print(diag, stderr);
        sl_diag_destroy(&diag);
        return AAFARM_EXIT_INPUT;
    }
    const atomic_int *stop = farm_catch_signals();
    l->seq = frame_sequence_load(c->farm.scene_path, &c->job, c->farm.frames, c->farm.output,
                                 &usage, stop, diag);
    if (atomic_load(stop)) {   /* while reading, compiling, checking */
        sl_diag_destroy(&diag);
        fprintf(stderr, "aafarm-master: interrupted while loading %s; nothing written\n",
                c->farm.scene_path);
        return AAFARM_EXIT_INTERRUPTED;
    }
    int n = l->seq ? l->seq->count : 0;
    l->frames = xcalloc((size_t)(n ? n : 1), sizeof *l->frames);
    l->previews = xcalloc((size_t)(n ? n : 1), sizeof *l->previews);
    bool ok = l->seq != NULL;
    for (int i = 0; i < n && ok; i++) {
        const job *jb = l->seq->jobs[i];
        farm_frame_in *fr = &l->frames[i];
        fr->jb = jb;
        fr->output = l->seq->outputs[i];
        fr->fmt = (image_format){jb->xres, jb->yres, c->job.tile_size, 0};   /* job_load's */
        char err[ERR_LEN];
        if (!image_format_check(&fr->fmt, err, sizeof err)) {
            sl_diag_error(diag, (sl_pos){0}, "%s: %s", c->farm.scene_path, err);
            ok = false;
            break;
        }
        if (c->farm.preview) {
            l->previews[i] = frame_output_name(c->farm.preview, jb->frame_number,
                                               l->seq->nframes, false, err, sizeof err);
            if (!l->previews[i]) {
                sl_diag_error(diag, (sl_pos){0}, "--preview: %s", err);
                ok = false;
                break;
            }
            fr->preview = l->previews[i];
        }
    }
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    if (ok && l->seq->numbered && c->farm.verbosity >= 0)
        fprintf(stderr, "aafarm-master: %s has %d frames: each one's number goes before the "
                "extension of %s (%s ...; put %%04d in the name to place it)\n",
                c->farm.scene_path, l->seq->nframes, l->seq->numbered, l->seq->outputs[0]);
    return ok ? -1 : usage && !l->seq ? AAFARM_EXIT_USAGE : AAFARM_EXIT_INPUT;
}

/* AAFARM_WAIT_REPORT_MS: how often a master with --bind and no worker says
 * it still waits (30 s); a testing aid, not in --help. */
static void wait_report_from_env(farm_options *opt)
{
    const char *text = getenv("AAFARM_WAIT_REPORT_MS");
    if (!text || !*text) return;
    long n;
    char err[ERR_LEN];
    if (parse_option_long("AAFARM_WAIT_REPORT_MS", "milliseconds", text, 100, 86400000L, &n, err,
                          sizeof err))
        opt->wait_report_ms = n;
    else
        fprintf(stderr, "aafarm-master: %s (ignored)\n", err);
}

int main(int argc, char **argv)
{
    cli c;
    memset(&c, 0, sizeof c);
    farm_options_default(&c.farm);
    wait_report_from_env(&c.farm);
    job_options_default(&c.job);
    int rc = parse(argc, argv, &c);
    if (rc >= 0) return rc;
    if (c.serve) return farm_serve(&c.farm, c.db);
    loaded l = {0};
    rc = load(&c, &l);
    if (rc < 0) rc = farm_run(&c.farm, l.frames, l.seq->count);
    loaded_free(&l);
    return rc;
}

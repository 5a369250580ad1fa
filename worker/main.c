/*
 * main.c: the aafarm-worker command line.
 *
 *   aafarm-worker --standalone SCENE.rib [-o OUT.exr] [--frames 1-3] [options]
 *   aafarm-worker --connect ENDPOINT [options]          (the farm: docs/farm.md)
 */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "job/frames.h"
#include "curve_cert.h"
#include "message.h"
#include "tex/tex.h"
#include "standalone.h"
#include "util/cli.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "util/parse_num.h"
#include "worker_loop.h"

static void usage(FILE *out)
{
    fprintf(out,
        "usage: aafarm-worker --standalone SCENE.rib [-o OUT.exr] [--frames LIST] [options]\n"
        "       aafarm-worker --connect ENDPOINT [options]\n"
        "\n"
        "Renders RenderMan scenes with procedural displacement shaders, ray-traced\n"
        "directly with affine arithmetic (Heidrich & Seidel 1998).\n"
        "\n"
        "  --standalone SCENE.rib  render the whole image in this process (the\n"
        "                          reference a farm render equals pixel for pixel)\n"
        "  -o, --output OUT.exr    output file (tiled OpenEXR: RGBA half + Z float);\n"
        "                          default: the frame's Display name. In a file of\n"
        "                          several frames, %%04d in the name is the frame\n"
        "                          number, else it is put before the extension\n"
        "  --frames LIST           frames to render by FrameBegin number: 3, 1-10,\n"
        "                          1,3,5-7 (default: all; one EXR per frame)\n"
        "  --connect ENDPOINT      serve a master, e.g. tcp://render1:5555; serves one\n"
        "                          job after another, reconnects when the master goes\n"
        "                          away (docs/farm.md)\n"
        "  --curve-secret FILE     CurveZMQ: this worker's NAME.key_secret (aafarm-keygen\n"
        "                          NAME; the master must allow NAME.key); needs --master-key\n"
        "  --master-key FILE       CurveZMQ: the master's public key (its NAME.key)\n"
        "  --name NAME             worker name in the master's logs (default host:pid)\n"
        "  --pool NAME             (--connect) this worker's pool: a job submitted to a\n"
        "                          pool goes only to its workers; one without a pool, to any\n"
        "  -t, --threads N         rendering threads (default: number of cores)\n"
        "  --tile S                tile size in pixels (standalone; default 32)\n"
        "  --cache-bytes B         box cache budget per thread, e.g. 40K, 400K, 4M,\n"
        "                          0 = unlimited (default 4M: memory stays flat as\n"
        "                          the image grows); displaced meshes' root boxes,\n"
        "                          shared by the threads, get as much again a thread\n"
        "  --arith affine|interval bounding arithmetic (default affine)\n"
        "  --budget N              shader instruction budget per evaluation (default 1000000)\n"
        "  --preview OUT.png       also write an sRGB PNG preview\n"
        "  --stats                 print render statistics\n"
        "  --stats-json FILE       write render statistics as JSON\n"
        "  --texture-bytes B       memory for texture tiles read on demand (maps made by\n"
        "                          aafarm-maketx; least recently used tiles are evicted\n"
        "                          beyond it; 0 = unlimited; default 512M)\n"
        "  --file-cache DIR        (--connect) the host's store of job files (textures),\n"
        "                          shared by its workers (default $XDG_CACHE_HOME/aafarm/\n"
        "                          files, else /var/tmp/aafarm-$UID/files)\n"
        "  --file-cache-bytes B    its byte budget: least recently used files not in use\n"
        "                          are removed beyond it (default 0 = unlimited)\n"
        "  --file-chunk B          (--connect) bytes asked per file chunk (default 1M)\n"
        "  --file-inflight B       (--connect) file bytes asked and not yet received, at\n"
        "                          most (default 8M, at most 64M)\n"
        "  --file-delay MS         (--connect) wait MS between two file chunks asked: a\n"
        "                          testing aid that makes transfers slow enough to interrupt\n"
        "  --tile-delay MS          (--connect) sleep MS before each tile: a testing aid\n"
        "                          that makes renders slow enough to interrupt\n"
        "  --prepare-delay MS       (--connect) sleep MS before compiling each job: a\n"
        "                          testing aid for slow preparations (heartbeats go on)\n"
        "  --fail-tiles             (--connect) answer every tile with a failure: a testing\n"
        "                          aid for the master's benching of failing workers\n"
        "  -q, --quiet             only errors;  -v, --verbose  more detail\n"
        "  -h, --help              this text\n"
        "\n"
        "Exit status: 0 done, 1 render failed, 2 usage, 3 bad scene or shader,\n"
        "130 interrupted (no output file is left behind).\n"
        "With --connect: 0 after the master's Shutdown, 2 bad endpoint or refused by\n"
        "the master (protocol version mismatch), 130 after SIGINT/SIGTERM.\n");
}

/* optarg as a whole number of lo..hi into *n; false after printing
 * "aafarm-worker: OPT wants NOUN LO..HI, got 'TEXT'". */
static bool number_arg(const char *opt, const char *noun, long lo, long hi, long *n)
{
    char err[ERR_LEN];
    if (parse_option_long(opt, noun, optarg, lo, hi, n, err, sizeof err)) return true;
    fprintf(stderr, "aafarm-worker: %s\n", err);
    return false;
}

/* optarg as the job option opt (--tile, --arith, --budget) into *opts;
 * false after printing why. */
static bool job_arg(job_options *opts, const char *opt)
{
    char err[ERR_LEN];
    if (job_options_parse_arg(opts, opt, optarg, err, sizeof err)) return true;
    fprintf(stderr, "aafarm-worker: %s\n", err);
    return false;
}

/* The box cache budget per render thread when --cache-bytes is not given:
 * bounded, so a worker's memory does not grow with the image (unlimited
 * grows ~140 bytes per pixel), and large enough that the boxes computed
 * stay within a few % of unlimited on the paper's scenes (render_bench,
 * docs/benchmarks.md). It changes speed, never pixels. */
#define WORKER_DEFAULT_CACHE_BYTES ((size_t)4 << 20)

/* A texture tile that cannot be read (tex_tiles_set_warn). */
static void print_texture_warning(void *ctx, const char *message)
{
    (void)ctx;
    fprintf(stderr, "aafarm: %s\n", message);
}

int main(int argc, char **argv)
{
    tex_tiles_set_warn(tex_tiles_process(), print_texture_warning, NULL);
    standalone_options so = {0};
    worker_loop_options wo = {0};
    job_options_default(&so.job);
    so.cache_bytes = wo.cache_bytes = WORKER_DEFAULT_CACHE_BYTES;
    const char *connect = NULL;
    enum { O_STANDALONE = 256, O_CONNECT, O_NAME, O_TILE, O_CACHE, O_ARITH, O_BUDGET,
           O_PREVIEW, O_STATS, O_STATS_JSON, O_TILE_DELAY, O_PREPARE_DELAY,
           O_CURVE_SECRET, O_MASTER_KEY, O_FRAMES, O_FILE_CACHE, O_FILE_CACHE_BYTES,
           O_FILE_CHUNK, O_FILE_INFLIGHT, O_FILE_DELAY, O_TEXTURE_BYTES, O_POOL, O_FAIL_TILES };
    static const struct option longopts[] = {
        {"standalone", required_argument, 0, O_STANDALONE},
        {"output", required_argument, 0, 'o'},
        {"connect", required_argument, 0, O_CONNECT},
        {"name", required_argument, 0, O_NAME},
        {"pool", required_argument, 0, O_POOL},
        {"fail-tiles", no_argument, 0, O_FAIL_TILES},
        {"threads", required_argument, 0, 't'},
        {"tile", required_argument, 0, O_TILE},
        {"cache-bytes", required_argument, 0, O_CACHE},
        {"arith", required_argument, 0, O_ARITH},
        {"budget", required_argument, 0, O_BUDGET},
        {"preview", required_argument, 0, O_PREVIEW},
        {"stats", no_argument, 0, O_STATS},
        {"stats-json", required_argument, 0, O_STATS_JSON},
        {"tile-delay", required_argument, 0, O_TILE_DELAY},
        {"prepare-delay", required_argument, 0, O_PREPARE_DELAY},
        {"curve-secret", required_argument, 0, O_CURVE_SECRET},
        {"master-key", required_argument, 0, O_MASTER_KEY},
        {"frames", required_argument, 0, O_FRAMES},
        {"file-cache", required_argument, 0, O_FILE_CACHE},
        {"file-cache-bytes", required_argument, 0, O_FILE_CACHE_BYTES},
        {"file-chunk", required_argument, 0, O_FILE_CHUNK},
        {"file-inflight", required_argument, 0, O_FILE_INFLIGHT},
        {"file-delay", required_argument, 0, O_FILE_DELAY},
        {"texture-bytes", required_argument, 0, O_TEXTURE_BYTES},
        {"quiet", no_argument, 0, 'q'},
        {"verbose", no_argument, 0, 'v'},
        {"help", no_argument, 0, 'h'},
        {"version", no_argument, 0, 'V'},
        {0, 0, 0, 0}};
    int c;
    long n;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":o:t:qvh", longopts, NULL)) != -1) {
        switch (c) {
        case O_STANDALONE: so.scene_path = optarg; break;
        case 'o': so.output = optarg; break;
        case O_CONNECT: connect = optarg; break;
        case O_NAME: wo.name = optarg; break;
        case O_POOL: {
            char err[ERR_LEN];
            if (!proto_pool_name_check(optarg, err, sizeof err)) {
                fprintf(stderr, "aafarm-worker: --pool: %s\n", err);
                return AAFARM_EXIT_USAGE;
            }
            wo.pool = optarg;
            break;
        }
        case O_FAIL_TILES: wo.fail_tiles = true; break;
        case 't':
            if (!number_arg("--threads", "a number", 1, 1024, &n)) return AAFARM_EXIT_USAGE;
            so.threads = wo.threads = (int)n;
            break;
        case O_TILE: if (!job_arg(&so.job, "--tile")) return AAFARM_EXIT_USAGE; break;
        case O_CACHE:
            if (!parse_byte_count(optarg, &so.cache_bytes)) {
                fprintf(stderr, "aafarm-worker: --cache-bytes wants e.g. 40K, 4M or 0, got '%s'\n", optarg);
                return AAFARM_EXIT_USAGE;
            }
            wo.cache_bytes = so.cache_bytes;
            break;
        case O_ARITH: if (!job_arg(&so.job, "--arith")) return AAFARM_EXIT_USAGE; break;
        case O_BUDGET: if (!job_arg(&so.job, "--budget")) return AAFARM_EXIT_USAGE; break;
        case O_PREVIEW: so.preview = optarg; break;
        case O_STATS: so.stats = true; break;
        case O_STATS_JSON: so.stats_json = optarg; break;
        case O_TILE_DELAY:
            if (!number_arg("--tile-delay", "milliseconds", 0, 600000, &n)) return AAFARM_EXIT_USAGE;
            wo.tile_delay_ms = (int)n;
            break;
        case O_PREPARE_DELAY:
            if (!number_arg("--prepare-delay", "milliseconds", 0, 600000, &n)) return AAFARM_EXIT_USAGE;
            wo.prepare_delay_ms = (int)n;
            break;
        case O_CURVE_SECRET: wo.curve_secret = optarg; break;
        case O_MASTER_KEY: wo.master_key = optarg; break;
        case O_FRAMES: {
            frame_spec spec;
            char err[ERR_LEN];
            if (!frame_spec_parse(optarg, &spec, err, sizeof err)) {
                fprintf(stderr, "aafarm-worker: %s\n", err);
                return AAFARM_EXIT_USAGE;
            }
            frame_spec_clear(&spec);
            so.frames = optarg;
            break;
        }
        case O_FILE_CACHE: wo.file_cache = optarg; break;
        case O_FILE_CACHE_BYTES:
        case O_FILE_INFLIGHT: {
            size_t b;
            if (!parse_byte_count(optarg, &b)) {
                fprintf(stderr, "aafarm-worker: --%s wants e.g. 400K, 4M, 2G or 0, got '%s'\n",
                        c == O_FILE_INFLIGHT ? "file-inflight" : "file-cache-bytes", optarg);
                return AAFARM_EXIT_USAGE;
            }
            if (c == O_FILE_INFLIGHT && (b < 1024 || b > (64u << 20))) {
                fprintf(stderr, "aafarm-worker: --file-inflight wants 1K..64M (the master sends "
                        "no more), got '%s'\n", optarg);
                return AAFARM_EXIT_USAGE;
            }
            if (c == O_FILE_INFLIGHT) wo.file_inflight = b;
            else wo.file_cache_bytes = b;
            break;
        }
        case O_FILE_CHUNK: {
            size_t b;
            if (!parse_byte_count(optarg, &b) || b < 1024 || b > (16u << 20)) {
                fprintf(stderr, "aafarm-worker: --file-chunk wants 1K..16M, got '%s'\n", optarg);
                return AAFARM_EXIT_USAGE;
            }
            wo.file_chunk = (uint32_t)b;
            break;
        }
        case O_FILE_DELAY:
            if (!number_arg("--file-delay", "milliseconds", 0, 600000, &n)) return AAFARM_EXIT_USAGE;
            wo.file_delay_ms = (int)n;
            break;
        case O_TEXTURE_BYTES: {
            size_t b;
            if (!parse_byte_count(optarg, &b)) {
                fprintf(stderr, "aafarm-worker: --texture-bytes wants e.g. 64M, 2G or 0, got '%s'\n", optarg);
                return AAFARM_EXIT_USAGE;
            }
            tex_tiles_set_budget(tex_tiles_process(), b);   /* this process's textures */
            break;
        }
        case 'q': so.verbosity = wo.verbosity = -1; break;
        case 'v': so.verbosity = wo.verbosity = 1; break;
        case 'h': usage(stdout); return AAFARM_EXIT_OK;
        case 'V': printf("aafarm-worker %s\n", cli_version()); return AAFARM_EXIT_OK;
        default: {
            char line[512];
            cli_option_problem(c, optind, optopt, argv, line, sizeof line);
            fprintf(stderr, "aafarm-worker: %s\n", line);
            return AAFARM_EXIT_USAGE;
        }
        }
    }
    if (optind < argc) {
        fprintf(stderr, "aafarm-worker: unexpected argument '%s' (see --help)\n", argv[optind]);
        return AAFARM_EXIT_USAGE;
    }
    if (so.scene_path && connect) {
        fprintf(stderr, "aafarm-worker: --standalone and --connect exclude each other\n");
        return AAFARM_EXIT_USAGE;
    }
    if (so.frames && !so.scene_path) {
        fprintf(stderr, "aafarm-worker: --frames goes with --standalone (a farm's frames are "
                "chosen by aafarm-master --frames)\n");
        return AAFARM_EXIT_USAGE;
    }
    if (so.scene_path)
        return worker_standalone(&so);
    if (!wo.curve_secret != !wo.master_key) {
        fprintf(stderr, "aafarm-worker: --curve-secret and --master-key go together (this "
                "worker's key pair, and the master's public key)\n");
        return AAFARM_EXIT_USAGE;
    }
    if (wo.master_key) {
        /* the master's secret file holds its public key too, so it would
         * work: warn (the secret is not used, but it should not be here);
         * a file that cannot be read is reported by the loop */
        curve_cert mkey;
        if (curve_cert_read(wo.master_key, false, &mkey, NULL, 0) && mkey.secret_key[0])
            fprintf(stderr, "aafarm-worker: warning: --master-key %s is a secret key (a "
                    "NAME.key_secret); give the master's public key NAME.key\n", wo.master_key);
        memset(&mkey, 0, sizeof mkey);
    }
    if (connect) {
        wo.endpoint = connect;
        /* how often a worker that cannot reach its master says so again
         * (30 s); a testing aid, not in --help */
        const char *report = getenv("AAFARM_WAIT_REPORT_MS");
        if (report && *report) {
            char err[ERR_LEN];
            if (parse_option_long("AAFARM_WAIT_REPORT_MS", "milliseconds", report, 100, 86400000L,
                                  &n, err, sizeof err))
                wo.unreachable_report_ms = (int)n;
            else
                fprintf(stderr, "aafarm-worker: %s (ignored)\n", err);
        }
        return worker_loop_run(&wo);
    }
    usage(stderr);
    return AAFARM_EXIT_USAGE;
}

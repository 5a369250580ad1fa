/*
 * farm.h: one render on the farm, from a loaded job to the stitched EXR
 * (the master of docs/protocol.md and docs/farm.md).
 *
 * farm_run() binds the ROUTER, optionally starts local worker processes,
 * and runs the master's single-threaded loop: zmq_poll on the socket with
 * a short timeout, then the timers (heartbeats, dead workers, lease
 * deadlines, local children, progress), then grants. Tiles that come back
 * are validated and their compressed chunks copied into the output file
 * (image_writer); the file is renamed into place only when complete.
 */
#ifndef MASTER_FARM_H
#define MASTER_FARM_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image/format.h"
#include "job/job.h"

typedef struct farm_options {
    const char *scene_path;
    const char *output;            /* -o: OUT.exr or a pattern (job/frames.h) */
    const char *frames;            /* --frames "1,3,5-7", NULL: all */
    const char *preview;           /* OUT.png or NULL */
    const char *stats_json;        /* FILE or NULL */
    const char *bind;              /* endpoint; NULL: embedded (private ipc://) */
    int local_workers;             /* processes to start (embedded default: cores) */
    int threads_per_worker;        /* --threads of each local worker (1) */
    const char *worker_binary;     /* NULL: aafarm-worker next to this program */
    int heartbeat_ms;              /* Welcome.heartbeat_ms (1000) */
    int liveness;                  /* Welcome.heartbeat_liveness (3) */
    int max_attempts;              /* failures of one tile that fail the job (3) */
    int max_duplicates;            /* end-game duplicate leases per tile (1) */
    int64_t lease_ms;              /* the longest lease (120000) */
    int lease_factor;              /* leases last this x the measured time per tile (4) */
    int verbosity;                 /* -1 quiet, 0 normal, 1 verbose */
    bool resume;                   /* --resume: take the tiles in OUT.exr.journal */
    int max_workers;               /* live workers at most; more are refused (1024) */
    const char *curve_secret;      /* --curve-secret: the master's NAME.key_secret, or NULL */
    const char *allow_keys;        /* --allow-keys: folder of workers' NAME.key files */
    bool insecure;                 /* --insecure: plaintext on a network endpoint */
    int64_t wait_report_ms;        /* --bind, no worker alive: said again this often (30000;
                                    * AAFARM_WAIT_REPORT_MS, a testing aid) */
    const char *http;              /* --http ADDR:PORT: the live monitor, or NULL */
    const char *http_token;        /* its token (checked by main.c), or NULL */
    int64_t http_linger_ms;        /* --http-linger: serve this long after the end */
    const char *pool;              /* --pool NAME: only workers of that pool (NULL: any) */
    int min_workers;               /* --min-workers: no tile granted before this many
                                    * workers are alive at once (0: the first one) */
    int64_t wait_timeout_ms;       /* --wait-timeout: give up (AAFARM_EXIT_NO_WORKERS) when
                                    * too few workers joined, or none is alive, this
                                    * long (0: wait for ever) */
} farm_options;

void farm_options_default(farm_options *opt);

/* One frame of the render: its job (loaded and checked by job_load, its
 * options.frame telling which FrameBegin block), its image format, and
 * the files it goes to (job/frames.h names them). */
typedef struct farm_frame_in {
    const job *jb;
    image_format fmt;
    const char *output;            /* OUT.exr (or OUT.0002.exr ...) */
    const char *preview;           /* its PNG, or NULL */
} farm_frame_in;

/* Renders the frames (at least one) with the tiles of all of them in one
 * queue; each frame's EXR is renamed into place when its last tile is in.
 * opt->output is not used here. Returns an AAFARM_EXIT_* code
 * (util/exitcodes.h): OK, FAILURE (a tile failed too often, no workers
 * left, output not writable), USAGE (an endpoint ZeroMQ cannot bind),
 * NO_WORKERS (--wait-timeout passed: too few workers joined, or none was
 * alive that long; the journal is kept),
 * INTERRUPTED (SIGINT/SIGTERM: nothing written but the frames already
 * complete). */
int farm_run(const farm_options *opt, const farm_frame_in *frames, int nframes);

/* Installs the master's SIGINT/SIGTERM handler (and ignores SIGPIPE);
 * returns the flag it sets, for the job loading that comes before
 * farm_run (which installs it too; calling both is fine). */
const atomic_int *farm_catch_signals(void);

#endif

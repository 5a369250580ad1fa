/*
 * farm_internal.h: the state of one farm render, shared by the files of
 * the master's loop (not a public interface):
 *
 *   farm.c           set-up, the poll loop, timers, the end of the job
 *   farm_messages.c  what each message from a worker does; sending
 *                    (NeedFile: file_server.c reads the chunk)
 *   report.c         the summary per worker and the statistics file
 *   farm_monitor.c   what the live monitor shows (--http)
 */
#ifndef MASTER_FARM_INTERNAL_H
#define MASTER_FARM_INTERNAL_H

#include <limits.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include "console.h"
#include "file_server.h"
#include "farm.h"
#include "image/writer.h"
#include "job_message.h"
#include "journal.h"
#include "local_workers.h"
#include "monitor.h"
#include "registry.h"
#include "scheduler.h"
#include "wire.h"
#include "zap.h"

typedef enum farm_state {
    FARM_RUNNING,
    FARM_DONE,           /* every tile is in */
    FARM_FAILED,         /* a tile failed too often, or no workers are left */
    FARM_INTERRUPTED,    /* SIGINT / SIGTERM */
    FARM_CANCELLED,      /* a serving master's job, cancelled (serve.c) */
    FARM_REQUEUED,       /* a serving master's job lost every worker: back in the
                            queue, its journal kept (serve.c) */
    FARM_NO_WORKERS      /* --wait-timeout passed without enough workers: the
                            master gives up (its journals kept) */
} farm_state;

/* One frame of the sequence: its tiles are the scheduler's tiles
 * first .. first + ntiles - 1 (all frames in one queue). */
typedef struct farm_frame {
    const job *jb;
    image_format fmt;
    const char *output, *preview;
    int tiles_x, ntiles, first;
    job_message *jobmsg;
    file_server *files;            /* its job's files, served from disk */
    size_t job_bytes;              /* packed size of its Job envelope */
    image_writer *writer;
    journal *jnl;                  /* OUT.exr.journal: its tiles taken so far */
    int done;                      /* its tiles in the output */
    bool written;                  /* complete and renamed into place */
    int job_first, job_frames;     /* its job's frames in the farm's (a serving master's
                                      run holds the frames of several jobs) */
    /* a serving master (serve.c), whose frames may belong to several jobs */
    bool keep_journal;             /* at the end: its job resumes later (requeued,
                                      interrupted), so its journal stays */
    farm_state end;                /* its job's end for JobDone (FARM_RUNNING: the
                                      farm's state) */
} farm_frame;

/* A tile one worker alone gave up on (SCHEDULER_AWAIT_OTHER): the words
 * of its failure, for the render's failure if no other worker comes. */
typedef struct farm_given_up {
    int tile;
    char failure[2 * ERR_LEN];
} farm_given_up;

struct http_jobs;

typedef struct farm {
    const farm_options *opt;
    farm_frame *frames;
    int nframes, frames_written;
    image_format fmt;              /* the first frame's (tile size, limits) */
    int ntiles;                    /* of all frames */
    void *ctx, *router;
    wire_monitor *monitor;
    zap *zap;                      /* CURVE: the key check (NULL: plaintext) */
    uint64_t handshakes_logged;    /* handshake failures logged so far */
    int64_t handshake_logged_ms;
    wire_stats wstats;
    proto_limits limits;           /* what workers may send (bounded per tile: farm.c) */
    proto_limits send_limits;      /* what the master sends (the Job may be large) */
    char endpoint[PATH_MAX + 64];  /* what the local workers connect to */
    char ipc_dir[PATH_MAX];        /* embedded mode's private folder, or "" */
    scheduler *sched;
    registry *reg;
    int resumed_tiles;             /* tiles replayed from the journal (--resume) */
    local_workers *locals;
    console *con;
    size_t job_bytes;              /* packed sizes of the frames' Job envelopes */
    uint64_t file_bytes_sent, file_chunks_sent;
    uint64_t session;              /* Welcome.master_session */
    char host[128];
    int64_t start_ms, end_ms;
    farm_state state;
    char failure[2 * ERR_LEN];     /* a prefix (frame, tile, worker) and a message */
    int failed_tile;               /* the tile (of all frames) the failure is about, or
                                      -1 (the master's own: every frame's) */
    farm_given_up *given_up;       /* tiles waiting for a second worker */
    size_t ngiven_up;
    /* counters beyond the scheduler's and the socket's */
    uint64_t invalid_tiles, rejects_sent, version_mismatches, jobs_sent;
    uint64_t grant_bytes, result_bytes, sent_bytes;
    uint64_t drops_unlogged;       /* malformed messages not logged yet */
    uint64_t nonfinite_samples;    /* NaN/Inf samples in the tiles taken */
    int nonfinite_tiles;
    int64_t drop_logged_ms;
    console_tally expired;         /* leases past their deadline, one line per interval */
    /* --bind: saying what the master waits for while no worker is alive */
    char bound[600];               /* the endpoint bound (the real port for '*') */
    int joined;                    /* workers that said Hello (ever) */
    bool waiting;                  /* no worker alive since waiting_since_ms */
    int64_t waiting_since_ms, wait_said_ms;
    /* --min-workers: no grant until that many are alive at once (the gate
     * opens once for the master's life); --wait-timeout bounds the wait */
    bool gate_open;
    int gate_said;                 /* workers alive when the gate's wait was last said */
    int64_t gate_since_ms, gate_said_ms;
    /* --http: the live monitor (farm_monitor.c) */
    monitor *mon;                  /* NULL without --http */
    struct http_server *http;
    int *tile_slot;                /* per tile: the slot of the worker whose result was taken */
    int64_t published_ms;
    int mon_base;                  /* the monitor's index of frames[0] (a serving master's
                                      monitor holds the frames of every job) */
    const char *pool;              /* the job's pool: only its workers get tiles (NULL: any) */
    /* --serve (serve.c): the job queue */
    bool serving;                  /* the render is one job of a queue */
    void (*tick)(struct farm *f, int64_t now);   /* called once a loop turn, or NULL */
    void *serve;                   /* serve.c's state */
    int64_t restart_at_ms;         /* every local worker exited: started again then (0: not
                                      planned) */
    int64_t restart_backoff_ms;    /* the wait before the next restart (1 s, doubling to 30 s) */
    int restarts;                  /* times the local workers were started again */
} farm;

/* At most one line per interval for a repeated warning (console_tally). */
enum { FARM_WARN_INTERVAL_MS = 10000 };

/* A worker is benched for the job (no more of its tiles) once this many
 * tiles it failed were finished by other workers. */
enum { FARM_BENCH_AFTER = 2 };

/* Can the worker take the job's tiles (its pool; farm_messages.c)? Gives
 * a worker that cannot a slot that gets nothing. */
void farm_worker_fit(farm *f, farm_worker *w);

int64_t farm_now_ms(void);

/* The frame of scheduler tile `tile`, and its tile index in that frame. */
farm_frame *farm_frame_of(farm *f, int tile, int *local);
/* Its last tile is in: finish its EXR (rename into place), preview. */
void farm_frame_complete(farm *f, farm_frame *fr);

/* farm_messages.c */
/* f's console (opt's verbosity, stderr) and its tally of leases that
 * passed their deadlines (farm.c): one setup for the one-shot master and
 * the serving one. */
void farm_console_open(farm *f, const farm_options *opt);

void farm_handle(farm *f, wire_msg *m, int64_t now);
void farm_grant_all(farm *f, int64_t now);
void farm_send_heartbeat(farm *f, farm_worker *w, int64_t now);
void farm_send_job_done(farm *f, farm_worker *w, int64_t now);
void farm_send_shutdown(farm *f, farm_worker *w, const char *reason, int64_t now);
/* Retires the worker and requeues its tiles (logged at INFO). */
void farm_lose_worker(farm *f, farm_worker *w, const char *why, int64_t now);
void farm_fail(farm *f, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The same for a failure of one tile (of all frames), or of one frame's
 * output (its first tile): a serving master fails that tile's job only. */
void farm_fail_tile(farm *f, int tile, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* A tile one worker alone gave up on waited for another worker for the
 * whole join window (--lease) in vain: the render fails with its words. */
void farm_fail_given_up(farm *f, int tile);

/* farm_monitor.c (each a no-op without --http) */
/* The monitor and the frames from .. nframes - 1 (a serving master's next
 * job adds its own), before any of their tiles (the journal's included). */
void farm_monitor_open(farm *f, int from);
/* Starts the HTTP server and says where: AAFARM_EXIT_OK or an exit code
 * with the message in err. */
int farm_monitor_serve(farm *f, const struct http_jobs *jobs, char *err, size_t errsz);
/* The tile's chunk was taken from w (NULL: replayed from the journal). */
void farm_monitor_tile(farm *f, farm_frame *fr, int local, const void *chunk, size_t len,
                       const farm_worker *w);
/* Every tile of the frame is in. */
void farm_monitor_frame_complete(farm *f, const farm_frame *fr);
/* Publishes the status and the workers, at most every 250 ms unless force. */
void farm_monitor_publish(farm *f, int64_t now, bool force);
/* After the end: keeps serving for --http-linger, or until *interrupted. */
void farm_monitor_linger(farm *f, const atomic_int *interrupted);
/* Stops the server (its thread has ended on return), frees the monitor. */
void farm_monitor_close(farm *f);

/* farm.c, for a serving master (serve.c): the socket, the local workers
 * and the registry once; then each job (nframes 0: idle, waiting for
 * one) opened, run until its state is no longer FARM_RUNNING, and ended
 * (its journals removed unless interrupted, JobDone to its workers, its
 * frames freed, the workers kept); at the end the local workers stopped
 * and everything freed. */
int farm_serve_open(farm *f, char *err, size_t errsz);
int farm_serve_job(farm *f, const farm_frame_in *frames, int nframes, char *err, size_t errsz);
/* Another job's frames join the running one's (their tiles after its
 * tiles in the one queue: workers take them while its last tiles are
 * out); an error (their output, their journal) is the caller's to fail. */
int farm_serve_append(farm *f, const farm_frame_in *frames, int nframes, char *err, size_t errsz);
void farm_serve_loop(farm *f);
void farm_serve_end_job(farm *f);
void farm_serve_close(farm *f);
/* The flag SIGINT/SIGTERM set. */
const atomic_int *farm_interrupted(void);

/* report.c */
void farm_report_summary(const farm *f);
bool farm_report_json(const farm *f, const char *path, char *err, size_t errsz);

#endif

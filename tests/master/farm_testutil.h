/*
 * farm_testutil.h: helpers of the farm's integration tests: a temporary
 * folder with a small scene and its shaders, child processes started and
 * always stopped by PID (even when an assertion fails: call
 * ft_stop_all() from the teardown), log files to wait on, free loopback
 * ports, and the pixel comparison of two EXR files.
 *
 * The tests get the programs on their command line:
 *     test_farm_x AAFARM_MASTER AAFARM_WORKER
 */
#ifndef TESTS_FARM_TESTUTIL_H
#define TESTS_FARM_TESTUTIL_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

extern const char *ft_master;   /* path of aafarm-master */
extern const char *ft_worker;   /* path of aafarm-worker */

/* Reads argv[1] and argv[2] into ft_master and ft_worker; false (with a
 * message) when they are missing. */
bool ft_init(int argc, char **argv);

/* A new temporary folder (removed by ft_rmtree, unless the environment
 * has AAFARM_TEST_KEEP: then it is kept and named on stderr). */
char *ft_tempdir(void);
void ft_rmtree(const char *dir);

/* Scenes the tests render, written into dir as scene.rib with its
 * shaders in dir/shaders:
 *   FT_SCENE_WAVE    a displaced square and a matte floor, 64x48
 *   FT_SCENE_BUDGET  the same with a shader that loops far beyond any
 *                    instruction budget
 *   FT_SCENE_BROKEN  a shader with a syntax error (line 3)
 *   FT_SCENE_NAN     the wave with a surface shader writing NaN, +Inf
 *                    and -Inf into Ci on half of the square
 *   FT_SCENE_NONE    nothing (the folder is left empty) */
typedef enum { FT_SCENE_WAVE, FT_SCENE_BUDGET, FT_SCENE_BROKEN, FT_SCENE_NAN, FT_SCENE_NONE }
    ft_scene_kind;
void ft_write_scene(const char *dir, ft_scene_kind kind);

/* "dir/name" in a static ring of buffers (valid for a few calls). */
const char *ft_path(const char *dir, const char *name);

/* Starts argv (NULL-terminated) with stdout and stderr appended to log.
 * The pid is remembered until it is reaped by ft_wait or ft_stop_all. */
pid_t ft_spawn(const char *log, const char *const *argv);

/* Waits up to timeout_s for pid to exit. Returns its exit status, 128 +
 * signal when killed, or -1 on timeout (the process is left running). */
int ft_wait(pid_t pid, double timeout_s);

/* True while pid runs (not exited, not a zombie). */
bool ft_running(pid_t pid);

/* SIGKILLs and reaps every child still remembered. */
void ft_stop_all(void);

/* The whole file as a string (malloc'd), "" when missing. */
char *ft_read(const char *path);

/* Occurrences of needle in the file now. */
int ft_count(const char *path, const char *needle);

/* Where needle first is in the file, in bytes (-1: not there). */
long ft_position(const char *path, const char *needle);

/* Waits until the file holds at least n occurrences of needle; false on
 * timeout. */
/* Seconds on the monotonic clock. */
double ft_now(void);
bool ft_wait_for(const char *path, const char *needle, int n, double timeout_s);

/* The endpoint from a master's "listening on ENDPOINT" log line, into
 * buf; false when it does not appear within timeout_s. */
bool ft_master_endpoint(const char *log, char *buf, size_t bufsz, double timeout_s);

/* A master rendering dir/scene.rib into dir/NAME.exr in tiles of `tile`,
 * bound to loopback on a free port, its log dir/NAME.log; its endpoint
 * into ep. The pid (ft_spawn: stopped by ft_stop_all), or -1 when it said
 * no endpoint within 30 s. */
pid_t ft_start_master(const char *dir, const char *name, const char *tile, char *ep,
                      size_t epsz);

/* The number after "\"key\": " in a JSON file (the master's
 * --stats-json), or -1 when the key is missing. */
long ft_json_number(const char *path, const char *key);

/* A TCP port on 127.0.0.1 that was free a moment ago, below the kernel's
 * ephemeral range (no connect or listen of another program is handed it). */
int ft_free_port(void);

/* Samples that differ between two EXR files (0: equal), -1 when they
 * cannot be read or compared (the reason is printed). */
long ft_exr_diff(const char *a, const char *b);

/* Renders dir/scene.rib with aafarm-worker --standalone into dir/ref.exr
 * (tile size `tile`); returns its exit status (when not 0, its log
 * dir/standalone.log is printed). */
int ft_standalone(const char *dir, int tile);

/* Runs a shell command line (fmt, printf-style; no single quotes in it)
 * under /bin/sh, bounded by timeout -k 2 120, its output appended to
 * dir/log; returns its exit status (-1 when it outlived 130 s). */
int ft_sh(const char *dir, const char *log, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
int ft_shv(const char *dir, const char *log, const char *fmt, va_list ap)
    __attribute__((format(printf, 3, 0)));

/* Files in dir whose name starts with prefix. */
int ft_count_files(const char *dir, const char *prefix);

void ft_sleep_ms(int ms);

/* Writes dir/slow-worker.sh, which runs aafarm-worker with --tile-delay
 * delay_ms and its own arguments (exec: the same pid), for a master's
 * --worker-binary; returns its path (an ft_path buffer). */
const char *ft_slow_worker(const char *dir, int delay_ms);

/* The folder of aafarm-master's real path (symbolic links resolved) into
 * buf, where the build put the other programs too; false when it cannot be
 * resolved or does not fit. */
bool ft_program_dir(char *buf, size_t bufsz);

/* ---- a test group's folder ----
 * A group's setup calls ft_group_begin(&dir, ...) on its own static
 * `char *dir`; the group's teardown is ft_group_teardown (or a function
 * ending with it), each test's ft_teardown. */

/* *dir_p becomes a new temporary folder (ft_tempdir) with the scene kind
 * written into it; when ref_tile > 0 the standalone render of it is made
 * into dir/ref.exr with tiles of ref_tile (ft_standalone). 0, or -1 when that render failed: what a cmocka group
 * setup returns. ft_group_teardown frees the folder of the last call. */
int ft_group_begin(char **dir_p, ft_scene_kind kind, int ref_tile);

/* A cmocka group teardown: every child stopped (ft_stop_all), the folder
 * of ft_group_begin removed (ft_rmtree), freed and its pointer NULL. */
int ft_group_teardown(void **state);

/* A cmocka test teardown: every child stopped (ft_stop_all). */
int ft_teardown(void **state);

#endif

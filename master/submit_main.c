/*
 * submit_main.c: aafarm-submit, the client of a serving master's job queue
 * (aafarm-master --serve; docs/farm.md "A job queue"), over its HTTP API
 * with libcurl:
 *
 *   aafarm-submit --master URL SCENE.rib -o OUT.exr [--priority N] [--frames LIST]
 *                 [--pool NAME] [--wait]
 *   aafarm-submit --master URL --list
 *   aafarm-submit --master URL --cancel ID
 *
 * A submission is loaded here as the one-shot master loads a scene
 * (frame_sequence_load: the same diagnostics, exit 3, the files the
 * shaders read collected) and sent whole (bundle.h), so that paths on
 * this host work whatever host the master runs on.
 */
#include <curl/curl.h>
#include <getopt.h>
#include <json-c/json.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bundle.h"
#include "http_access.h"
#include "job/frames.h"
#include "util/cli.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "util/parse_num.h"
#include "util/xalloc.h"

static void usage(FILE *out)
{
    fprintf(out,
        "usage: aafarm-submit --master URL SCENE.rib -o OUT.exr [--priority N] [--frames LIST]\n"
        "                     [--pool NAME] [--wait] [options]\n"
        "       aafarm-submit --master URL --list\n"
        "       aafarm-submit --master URL --cancel ID\n"
        "\n"
        "Submits a scene to a serving master's job queue (aafarm-master --serve --http\n"
        "ADDR:PORT), lists the queue, or cancels a job. A submission carries the scene,\n"
        "its shaders and the files they read, so paths on this host work; OUT.exr is\n"
        "written by the master, on its host (a relative name is made absolute here).\n"
        "\n"
        "  --master URL               the master's --http address: http://HOST:PORT\n"
        "  -o, --output OUT.exr       output file (default: the frame's Display name;\n"
        "                             several frames: as aafarm-master names them)\n"
        "  --priority N               higher runs first (default 0; -1000000..1000000);\n"
        "                             equal priorities run in the order submitted\n"
        "  --frames LIST              frames to render by FrameBegin number: 3, 1-10, 1,3,5-7\n"
        "  --pool NAME                only workers started with --pool NAME render it\n"
        "                             (default: any worker)\n"
        "  --tile S                   tile size in pixels (default 32)\n"
        "  --arith affine|interval    bounding arithmetic (default affine)\n"
        "  --budget N                 shader instruction budget per evaluation (default 1000000)\n"
        "  --wait                     return when the job ends, with its exit status (0 done,\n"
        "                             1 failed, 130 cancelled); waits through a master restart\n"
        "  --list                     the queue: id, state, priority, progress, scene, output\n"
        "  --cancel ID                cancel a queued or running job\n"
        "  --token-file FILE          the master's --http token (first line of FILE): needed\n"
        "                             when it serves a non-loopback address\n"
        "  --token TOKEN              the same on the command line (visible in ps)\n"
        "  -q, --quiet                print only the job id and errors\n"
        "  -h, --help                 this text\n"
        "\n"
        "Exit status: 0 submitted (with --wait: the job is done), 1 the master refused or\n"
        "could not be reached (or the job failed), 2 usage, 3 bad scene or shader\n"
        "(diagnostics printed, nothing sent), 130 the job was cancelled (--wait).\n");
}

typedef struct cli {
    const char *master, *scene, *output, *frames, *pool;
    char url[512];
    char token[HTTP_TOKEN_MAX + 2];
    bool has_token, wait, list, quiet;
    long priority, cancel;
    job_options job;
} cli;

/* ---- HTTP ---- */

typedef struct buf {
    char *data;
    size_t len;
} buf;

static size_t on_data(char *p, size_t size, size_t n, void *arg)
{
    buf *b = arg;
    size_t add = size * n;
    b->data = xrealloc(b->data, b->len + add + 1);
    memcpy(b->data + b->len, p, add);
    b->len += add;
    b->data[b->len] = '\0';
    return add;
}

/* path on the master: the HTTP status (*out its body), or -1 when the
 * master cannot be reached (err says why). */
static long request(const cli *c, const char *path, const void *body, size_t len, bool post,
                    buf *out, char *err, size_t errsz)
{
    char url[700];
    snprintf(url, sizeof url, "%s%s", c->url, path);
    out->data = xstrdup("");
    out->len = 0;
    CURL *h = curl_easy_init();
    if (!h) return err_set(err, errsz, "libcurl did not start") ? 0 : -1;
    struct curl_slist *headers = NULL;
    char auth[HTTP_TOKEN_MAX + 40];
    if (c->has_token) {
        snprintf(auth, sizeof auth, "Authorization: Bearer %s", c->token);
        headers = curl_slist_append(headers, auth);
    }
    headers = curl_slist_append(headers, "Content-Type: application/octet-stream");
    headers = curl_slist_append(headers, "Expect:");
    curl_easy_setopt(h, CURLOPT_URL, url);
    curl_easy_setopt(h, CURLOPT_HTTPHEADER, headers);
    curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, on_data);
    curl_easy_setopt(h, CURLOPT_WRITEDATA, out);
    curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT, 10L);
    curl_easy_setopt(h, CURLOPT_TIMEOUT, 300L);
    curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);
    if (post) {
        curl_easy_setopt(h, CURLOPT_POST, 1L);
        curl_easy_setopt(h, CURLOPT_POSTFIELDS, body ? body : "");
        curl_easy_setopt(h, CURLOPT_POSTFIELDSIZE_LARGE, (curl_off_t)len);
    }
    CURLcode rc = curl_easy_perform(h);
    long status = -1;
    if (rc == CURLE_OK) curl_easy_getinfo(h, CURLINFO_RESPONSE_CODE, &status);
    else err_set(err, errsz, "%s: %s (is aafarm-master --serve --http running there?)", url,
                 curl_easy_strerror(rc));
    curl_slist_free_all(headers);
    curl_easy_cleanup(h);
    return status;
}

/* The "error" of a JSON answer, or the text itself; for a refused token
 * (401, 403) what to do about it. */
static void answer_error(const cli *c, const buf *b, long status, char *err, size_t errsz)
{
    if (status == 401 || status == 403) {
        if (c->has_token)
            err_set(err, errsz, "the master at %s refused the token (answer %ld): give the "
                    "line of its --http-token-file with --token-file FILE", c->url, status);
        else
            err_set(err, errsz, "the master at %s needs a token (answer %ld): give the line "
                    "of its --http-token-file with --token-file FILE", c->url, status);
        return;
    }
    json_object *o = json_tokener_parse(b->data);
    json_object *e = NULL;
    if (o && json_object_object_get_ex(o, "error", &e))
        err_set(err, errsz, "the master answered %ld: %s", status, json_object_get_string(e));
    else
        err_set(err, errsz, "the master answered %ld: %.200s", status, b->data);
    json_object_put(o);
}

static const char *jstr(json_object *o, const char *key)
{
    json_object *v = NULL;
    return json_object_object_get_ex(o, key, &v) && v ? json_object_get_string(v) : "";
}

static long jlong(json_object *o, const char *key, long dflt)
{
    json_object *v = NULL;
    return json_object_object_get_ex(o, key, &v) && v ? (long)json_object_get_int64(v) : dflt;
}

/* ---- the commands ---- */

static int list(const cli *c)
{
    buf b;
    char err[ERR_LEN];
    long status = request(c, "/api/jobs", NULL, 0, false, &b, err, sizeof err);
    int rc = AAFARM_EXIT_FAILURE;
    json_object *o = status == 200 ? json_tokener_parse(b.data) : NULL;
    json_object *jobs = NULL;
    if (status < 0) {
        fprintf(stderr, "aafarm-submit: %s\n", err);
    } else if (!o || !json_object_object_get_ex(o, "jobs", &jobs)) {
        answer_error(c, &b, status, err, sizeof err);
        fprintf(stderr, "aafarm-submit: %s\n", err);
    } else {
        printf("%6s  %-9s  %8s  %9s  %s\n", "ID", "STATE", "PRIORITY", "PROGRESS", "SCENE -> OUTPUT");
        for (size_t i = 0; i < json_object_array_length(jobs); i++) {
            json_object *j = json_object_array_get_idx(jobs, i);
            json_object *outs = NULL;
            json_object_object_get_ex(j, "outputs", &outs);
            long tiles = jlong(j, "tiles", 0), done = jlong(j, "tiles_done", 0);
            char progress[32] = "-";
            if (tiles > 0) snprintf(progress, sizeof progress, "%ld%%", done * 100 / tiles);
            size_t nout = outs ? json_object_array_length(outs) : 0;
            printf("%6ld  %-9s  %8ld  %9s  %s -> %s%s\n", jlong(j, "id", 0), jstr(j, "state"),
                   jlong(j, "priority", 0), progress, jstr(j, "scene"),
                   nout ? json_object_get_string(json_object_array_get_idx(outs, 0)) : "",
                   nout > 1 ? " ..." : "");
        }
        rc = AAFARM_EXIT_OK;
    }
    json_object_put(o);
    free(b.data);
    return rc;
}

static int cancel(const cli *c)
{
    char path[64], err[ERR_LEN];
    snprintf(path, sizeof path, "/api/jobs/%ld/cancel", c->cancel);
    buf b;
    long status = request(c, path, NULL, 0, true, &b, err, sizeof err);
    int rc = AAFARM_EXIT_FAILURE;
    if (status < 0) {
        fprintf(stderr, "aafarm-submit: %s\n", err);
    } else if (status == 200 || status == 202) {
        if (!c->quiet)
            printf("job %ld %s\n", c->cancel, status == 200 ? "cancelled"
                                                            : "is running: its master stops it");
        rc = AAFARM_EXIT_OK;
    } else {
        answer_error(c, &b, status, err, sizeof err);
        fprintf(stderr, "aafarm-submit: %s\n", err);
    }
    free(b.data);
    return rc;
}

static void sleep_ms(long ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* Polls the job until it ends; its exit status. */
static int wait_for(const cli *c, long id)
{
    char path[64], err[ERR_LEN];
    snprintf(path, sizeof path, "/api/jobs/%ld", id);
    bool said = false;
    for (;;) {
        buf b;
        long status = request(c, path, NULL, 0, false, &b, err, sizeof err);
        if (status < 0) {   /* a master restarting: it resumes the job */
            if (!said && !c->quiet)
                fprintf(stderr, "aafarm-submit: %s; still waiting for job %ld\n", err, id);
            said = true;
        } else if (status != 200) {
            answer_error(c, &b, status, err, sizeof err);
            fprintf(stderr, "aafarm-submit: %s\n", err);
            free(b.data);
            return AAFARM_EXIT_FAILURE;
        } else {
            said = false;
            json_object *o = json_tokener_parse(b.data);
            const char *state = o ? jstr(o, "state") : "";
            if (strcmp(state, "done") == 0 || strcmp(state, "failed") == 0 ||
                strcmp(state, "cancelled") == 0) {
                int rc = (int)jlong(o, "exit_status", AAFARM_EXIT_FAILURE);
                const char *e = jstr(o, "error");
                if (!c->quiet || rc != 0)
                    fprintf(rc ? stderr : stdout, "job %ld %s%s%s\n", id, state, *e ? ": " : "", e);
                json_object_put(o);
                free(b.data);
                return rc;
            }
            json_object_put(o);
        }
        free(b.data);
        sleep_ms(300);
    }
}

static int submit(cli *c)
{
    sl_diag *diag = sl_diag_new();
    bool usage_error = false;
    frame_sequence *seq = frame_sequence_load(c->scene, &c->job, c->frames, c->output,
                                              &usage_error, NULL, diag);
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    if (!seq) return usage_error ? AAFARM_EXIT_USAGE : AAFARM_EXIT_INPUT;
    char err[2 * ERR_LEN];
    size_t len = 0;
    uint8_t *body = job_bundle_encode(seq, c->scene, (int)c->priority, c->pool, &len, err,
                                      sizeof err);
    int nframes = seq->count;
    frame_sequence_destroy(&seq);
    if (!body) {
        fprintf(stderr, "aafarm-submit: %s\n", err);
        return AAFARM_EXIT_INPUT;
    }
    buf b;
    long status = request(c, "/api/jobs", body, len, true, &b, err, sizeof err);
    free(body);
    long id = -1;
    if (status == 201) {
        json_object *o = json_tokener_parse(b.data);
        id = o ? jlong(o, "id", -1) : -1;
        json_object_put(o);
    }
    if (id < 0) {
        if (status >= 0) answer_error(c, &b, status, err, sizeof err);
        fprintf(stderr, "aafarm-submit: %s\n", err);
        free(b.data);
        return AAFARM_EXIT_FAILURE;
    }
    free(b.data);
    if (c->quiet) printf("%ld\n", id);
    else printf("%ld\n", id), fprintf(stderr, "aafarm-submit: job %ld queued (%d frame%s, %zu "
                                      "bytes, priority %ld)\n", id, nframes,
                                      nframes == 1 ? "" : "s", len, c->priority);
    fflush(stdout);
    return c->wait ? wait_for(c, id) : AAFARM_EXIT_OK;
}

/* ---- the command line ---- */

static bool number_arg(const char *opt, long lo, long hi, long *n)
{
    char err[ERR_LEN];
    if (parse_option_long(opt, NULL, optarg, lo, hi, n, err, sizeof err)) return true;
    fprintf(stderr, "aafarm-submit: %s\n", err);
    return false;
}

/* optarg as the job option opt (--tile, --arith, --budget) into *opts;
 * false after printing why. */
static bool job_arg(job_options *opts, const char *opt)
{
    char err[ERR_LEN];
    if (job_options_parse_arg(opts, opt, optarg, err, sizeof err)) return true;
    fprintf(stderr, "aafarm-submit: %s\n", err);
    return false;
}

static int parse(int argc, char **argv, cli *c)
{
    enum { O_MASTER = 256, O_PRIORITY, O_FRAMES, O_WAIT, O_LIST, O_CANCEL, O_TOKEN,
           O_TOKEN_FILE, O_TILE, O_ARITH, O_BUDGET, O_POOL };
    static const struct option longopts[] = {
        {"master", required_argument, 0, O_MASTER},
        {"output", required_argument, 0, 'o'},
        {"priority", required_argument, 0, O_PRIORITY},
        {"pool", required_argument, 0, O_POOL},
        {"frames", required_argument, 0, O_FRAMES},
        {"wait", no_argument, 0, O_WAIT},
        {"list", no_argument, 0, O_LIST},
        {"cancel", required_argument, 0, O_CANCEL},
        {"token", required_argument, 0, O_TOKEN},
        {"token-file", required_argument, 0, O_TOKEN_FILE},
        {"tile", required_argument, 0, O_TILE},
        {"arith", required_argument, 0, O_ARITH},
        {"budget", required_argument, 0, O_BUDGET},
        {"quiet", no_argument, 0, 'q'},
        {"help", no_argument, 0, 'h'},
        {"version", no_argument, 0, 'V'},
        {0, 0, 0, 0}};
    int ch;
    char err[ERR_LEN];
    opterr = 0;
    while ((ch = getopt_long(argc, argv, ":o:qh", longopts, NULL)) != -1) {
        switch (ch) {
        case O_MASTER: c->master = optarg; break;
        case 'o': c->output = optarg; break;
        case O_PRIORITY:
            if (!number_arg("--priority", -1000000, 1000000, &c->priority)) return AAFARM_EXIT_USAGE;
            break;
        case O_FRAMES: c->frames = optarg; break;
        case O_POOL:
            if (!proto_pool_name_check(optarg, err, sizeof err)) {
                fprintf(stderr, "aafarm-submit: --pool: %s\n", err);
                return AAFARM_EXIT_USAGE;
            }
            c->pool = optarg;
            break;
        case O_WAIT: c->wait = true; break;
        case O_LIST: c->list = true; break;
        case O_CANCEL:
            if (!number_arg("--cancel", 1, 1000000000000L, &c->cancel)) return AAFARM_EXIT_USAGE;
            break;
        case O_TOKEN:
        case O_TOKEN_FILE:
            if (!http_token_option(optarg, ch == O_TOKEN_FILE, c->token, sizeof c->token, err,
                                   sizeof err)) {
                fprintf(stderr, "aafarm-submit: %s\n", err);
                return AAFARM_EXIT_USAGE;
            }
            c->has_token = true;
            break;
        case O_TILE: if (!job_arg(&c->job, "--tile")) return AAFARM_EXIT_USAGE; break;
        case O_ARITH: if (!job_arg(&c->job, "--arith")) return AAFARM_EXIT_USAGE; break;
        case O_BUDGET: if (!job_arg(&c->job, "--budget")) return AAFARM_EXIT_USAGE; break;
        case 'q': c->quiet = true; break;
        case 'h': usage(stdout); return AAFARM_EXIT_OK;
        case 'V': printf("aafarm-submit %s\n", cli_version()); return AAFARM_EXIT_OK;
        default: {
            char line[512];
            cli_option_problem(ch, optind, optopt, argv, line, sizeof line);
            fprintf(stderr, "aafarm-submit: %s\n", line);
            return AAFARM_EXIT_USAGE;
        }
        }
    }
    if (optind < argc) c->scene = argv[optind++];
    if (optind < argc) {
        fprintf(stderr, "aafarm-submit: unexpected argument '%s' (see --help)\n", argv[optind]);
        return AAFARM_EXIT_USAGE;
    }
    if (!c->master) {
        fprintf(stderr, "aafarm-submit: which master? --master http://HOST:PORT (its --http "
                "address; see --help)\n");
        return AAFARM_EXIT_USAGE;
    }
    int modes = (c->scene != NULL) + c->list + (c->cancel > 0);
    if (modes != 1) {
        fprintf(stderr, "aafarm-submit: give one of SCENE.rib (submit), --list or --cancel ID "
                "(see --help)\n");
        return AAFARM_EXIT_USAGE;
    }
    if (!c->scene && (c->wait || c->output || c->frames || c->pool)) {
        fprintf(stderr, "aafarm-submit: --wait, -o, --frames and --pool go with a scene to "
                "submit\n");
        return AAFARM_EXIT_USAGE;
    }
    const char *m = c->master;
    bool scheme = strncmp(m, "http://", 7) == 0 || strncmp(m, "https://", 8) == 0;
    size_t l = strlen(m);
    while (l && m[l - 1] == '/') l--;
    snprintf(c->url, sizeof c->url, "%s%.*s", scheme ? "" : "http://", (int)l, m);
    return -1;
}

int main(int argc, char **argv)
{
    cli c;
    memset(&c, 0, sizeof c);
    job_options_default(&c.job);
    int rc = parse(argc, argv, &c);
    if (rc >= 0) return rc;
    if (curl_global_init(CURL_GLOBAL_DEFAULT) != 0) {
        fprintf(stderr, "aafarm-submit: libcurl did not start\n");
        return AAFARM_EXIT_FAILURE;
    }
    rc = c.list ? list(&c) : c.cancel > 0 ? cancel(&c) : submit(&c);
    curl_global_cleanup();
    memset(c.token, 0, sizeof c.token);
    return rc;
}

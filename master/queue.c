/*
 * queue.c: the serving master's jobs in SQLite (see queue.h). One table;
 * times are Unix seconds (REAL); outputs one per line.
 */
#include "queue.h"

#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "json_out.h"
#include "util/err.h"
#include "util/exitcodes.h"
#include "util/xalloc.h"

struct queue {
    sqlite3 *db;
    char path[512];
};

static const char schema[] =
    "CREATE TABLE IF NOT EXISTS jobs ("
    " id INTEGER PRIMARY KEY AUTOINCREMENT,"
    " state TEXT NOT NULL,"            /* queued running done failed cancelled */
    " priority INTEGER NOT NULL,"
    " scene TEXT NOT NULL,"
    " outputs TEXT NOT NULL,"
    " frames INTEGER NOT NULL,"
    " submitted REAL NOT NULL, started REAL, ended REAL,"
    " tiles INTEGER NOT NULL DEFAULT 0, tiles_done INTEGER NOT NULL DEFAULT 0,"
    " cancel INTEGER NOT NULL DEFAULT 0,"
    " exit_status INTEGER, error TEXT,"
    " bundle BLOB NOT NULL,"
    " pool TEXT NOT NULL DEFAULT '');";

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

static bool db_error(queue *self, const char *what, char *err, size_t errsz)
{
    return err_set(err, errsz, "job database %s: %s: %s", self->path, what,
                   sqlite3_errmsg(self->db));
}

/* A database made before pools has no pool column: added (empty). */
static bool add_pool_column(queue *self)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(self->db, "SELECT pool FROM jobs LIMIT 0", -1, &st, NULL) == SQLITE_OK) {
        sqlite3_finalize(st);
        return true;
    }
    return sqlite3_exec(self->db, "ALTER TABLE jobs ADD COLUMN pool TEXT NOT NULL DEFAULT ''",
                        NULL, NULL, NULL) == SQLITE_OK;
}

queue *queue_open(const char *path, char *err, size_t errsz)
{
    queue *self = xcalloc(1, sizeof *self);
    snprintf(self->path, sizeof self->path, "%s", path);
    if (sqlite3_open_v2(path, &self->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE |
                        SQLITE_OPEN_FULLMUTEX, NULL) != SQLITE_OK ||
        sqlite3_busy_timeout(self->db, 10000) != SQLITE_OK ||
        sqlite3_exec(self->db, "PRAGMA journal_mode=WAL;", NULL, NULL, NULL) != SQLITE_OK ||
        sqlite3_exec(self->db, schema, NULL, NULL, NULL) != SQLITE_OK ||
        !add_pool_column(self)) {
        db_error(self, "cannot open it (is it an aafarm job database, and its folder writable?)",
                 err, errsz);
        queue_destroy(&self);
        return NULL;
    }
    return self;
}

void queue_destroy(queue **self_p)
{
    queue *self = *self_p;
    if (!self) return;
    sqlite3_close(self->db);
    free(self);
    *self_p = NULL;
}

static sqlite3_stmt *prepare(queue *self, const char *sql, char *err, size_t errsz)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(self->db, sql, -1, &st, NULL) != SQLITE_OK) {
        db_error(self, "prepare", err, errsz);
        return NULL;
    }
    return st;
}

long queue_submit(queue *self, int priority, const char *pool, const char *scene,
                  const char *outputs, int frames, const void *bundle, size_t len, char *err,
                  size_t errsz)
{
    sqlite3_stmt *st = prepare(self, "INSERT INTO jobs (state, priority, scene, outputs, frames, "
                               "submitted, bundle, pool) VALUES ('queued', ?, ?, ?, ?, ?, ?, ?)",
                               err, errsz);
    if (!st) return -1;
    sqlite3_bind_int(st, 1, priority);
    sqlite3_bind_text(st, 2, scene, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 3, outputs, -1, SQLITE_STATIC);
    sqlite3_bind_int(st, 4, frames);
    sqlite3_bind_double(st, 5, now_s());
    sqlite3_bind_blob64(st, 6, bundle, len, SQLITE_STATIC);
    sqlite3_bind_text(st, 7, pool ? pool : "", -1, SQLITE_STATIC);
    long id = -1;
    if (sqlite3_step(st) == SQLITE_DONE) id = (long)sqlite3_last_insert_rowid(self->db);
    else db_error(self, "insert", err, errsz);
    sqlite3_finalize(st);
    return id;
}

/* UPDATE ... WHERE id = ?1: rows changed, -1 on error. */
static int update(queue *self, const char *sql, long id, char *err, size_t errsz)
{
    sqlite3_stmt *st = prepare(self, sql, err, errsz);
    if (!st) return -1;
    sqlite3_bind_int64(st, 1, id);
    sqlite3_bind_double(st, 2, now_s());
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        db_error(self, "update", err, errsz);
        return -1;
    }
    return sqlite3_changes(self->db);
}

queue_cancel_result queue_cancel(queue *self, long id, char *err, size_t errsz)
{
    char sql[200];
    snprintf(sql, sizeof sql, "UPDATE jobs SET state = 'cancelled', ended = ?2, exit_status = %d, "
             "error = 'cancelled before it started' WHERE id = ?1 AND state = 'queued'",
             AAFARM_EXIT_INTERRUPTED);
    int n = update(self, sql, id, err, errsz);
    if (n < 0) return QUEUE_ERROR;
    if (n > 0) return QUEUE_CANCELLED;
    n = update(self, "UPDATE jobs SET cancel = 1 WHERE id = ?1 AND state = 'running' AND ?2 > 0",
               id, err, errsz);
    if (n < 0) return QUEUE_ERROR;
    if (n > 0) return QUEUE_CANCEL_ASKED;
    sqlite3_stmt *st = prepare(self, "SELECT state FROM jobs WHERE id = ?", err, errsz);
    if (!st) return QUEUE_ERROR;
    sqlite3_bind_int64(st, 1, id);
    queue_cancel_result r = QUEUE_NO_SUCH_JOB;
    if (sqlite3_step(st) == SQLITE_ROW) {
        err_set(err, errsz, "job %ld has ended (%s)", id, (const char *)sqlite3_column_text(st, 0));
        r = QUEUE_ALREADY_ENDED;
    } else {
        err_set(err, errsz, "no job %ld in this master's queue", id);
    }
    sqlite3_finalize(st);
    return r;
}

static void json_time(FILE *out, sqlite3_stmt *st, int col)
{
    if (sqlite3_column_type(st, col) == SQLITE_NULL) fputs("null", out);
    else fprintf(out, "%.3f", sqlite3_column_double(st, col));
}

static void json_job(FILE *out, sqlite3_stmt *st)
{
    fprintf(out, "{\"id\": %lld, \"state\": ", (long long)sqlite3_column_int64(st, 0));
    json_out_string(out, (const char *)sqlite3_column_text(st, 1));
    fprintf(out, ", \"priority\": %d, \"scene\": ", sqlite3_column_int(st, 2));
    json_out_string(out, (const char *)sqlite3_column_text(st, 3));
    fputs(", \"outputs\": [", out);
    const char *o = (const char *)sqlite3_column_text(st, 4);
    for (bool first = true; o && *o; first = false) {
        const char *nl = strchr(o, '\n');
        size_t n = nl ? (size_t)(nl - o) : strlen(o);
        char *one = xstrndup(o, n);
        if (!first) fputs(", ", out);
        json_out_string(out, one);
        free(one);
        o += n + (nl ? 1 : 0);
    }
    fprintf(out, "], \"frames\": %d, \"submitted\": ", sqlite3_column_int(st, 5));
    json_time(out, st, 6);
    fputs(", \"started\": ", out);
    json_time(out, st, 7);
    fputs(", \"ended\": ", out);
    json_time(out, st, 8);
    fprintf(out, ", \"tiles\": %d, \"tiles_done\": %d, \"cancel_asked\": %s, \"exit_status\": ",
            sqlite3_column_int(st, 9), sqlite3_column_int(st, 10),
            sqlite3_column_int(st, 11) ? "true" : "false");
    if (sqlite3_column_type(st, 12) == SQLITE_NULL) fputs("null", out);
    else fprintf(out, "%d", sqlite3_column_int(st, 12));
    fputs(", \"error\": ", out);
    if (sqlite3_column_type(st, 13) == SQLITE_NULL) fputs("null", out);
    else json_out_string(out, (const char *)sqlite3_column_text(st, 13));
    fputs(", \"pool\": ", out);
    json_out_string(out, (const char *)sqlite3_column_text(st, 14));
    fputc('}', out);
}

char *queue_json(queue *self, long id, size_t *len, bool *missing, char *err, size_t errsz)
{
    *missing = false;
    const char *cols = "SELECT id, state, priority, scene, outputs, frames, submitted, started, "
                       "ended, tiles, tiles_done, cancel, exit_status, error, pool FROM jobs";
    char sql[400];
    snprintf(sql, sizeof sql, "%s%s", cols, id < 0 ? " ORDER BY id" : " WHERE id = ?");
    sqlite3_stmt *st = prepare(self, sql, err, errsz);
    if (!st) return NULL;
    if (id >= 0) sqlite3_bind_int64(st, 1, id);
    char *text = NULL;
    FILE *out = open_memstream(&text, len);
    if (!out) {
        sqlite3_finalize(st);
        err_set(err, errsz, "out of memory");
        return NULL;
    }
    if (id < 0) fputs("{\"jobs\": [", out);
    int rc, n = 0;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (id < 0) fputs(n ? ",\n  " : "\n  ", out);
        json_job(out, st);
        n++;
    }
    if (id < 0) fputs("]}", out);
    fputc('\n', out);
    sqlite3_finalize(st);
    fclose(out);
    if (rc != SQLITE_DONE || (id >= 0 && n == 0)) {
        if (rc != SQLITE_DONE) db_error(self, "select", err, errsz);
        else {
            *missing = true;
            err_set(err, errsz, "no job %ld in this master's queue", id);
        }
        free(text);
        return NULL;
    }
    return text;
}

long queue_next(queue *self, bool *resume, char *err, size_t errsz)
{
    return queue_next_except(self, NULL, 0, resume, err, errsz);
}

long queue_next_except(queue *self, const long *skip, int nskip, bool *resume, char *err,
                       size_t errsz)
{
    char sql[600], *at = sql;
    at += snprintf(sql, sizeof sql, "SELECT id, state FROM jobs WHERE state IN ('running', "
                   "'queued')");
    for (int i = 0; i < nskip && at < sql + sizeof sql - 200; i++)
        at += snprintf(at, (size_t)(sql + sizeof sql - at), " AND id != %ld", skip[i]);
    snprintf(at, (size_t)(sql + sizeof sql - at), " ORDER BY state = 'running' DESC, priority "
             "DESC, id LIMIT 1");
    sqlite3_stmt *st = prepare(self, sql, err, errsz);
    if (!st) return -1;
    long id = -1;
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        id = (long)sqlite3_column_int64(st, 0);
        *resume = strcmp((const char *)sqlite3_column_text(st, 1), "running") == 0;
    } else if (rc != SQLITE_DONE) {
        db_error(self, "select", err, errsz);
    }
    sqlite3_finalize(st);
    return id;
}

bool queue_bundle(queue *self, long id, uint8_t **data, size_t *len, char *err, size_t errsz)
{
    sqlite3_stmt *st = prepare(self, "SELECT bundle FROM jobs WHERE id = ?", err, errsz);
    if (!st) return false;
    sqlite3_bind_int64(st, 1, id);
    bool ok = sqlite3_step(st) == SQLITE_ROW;
    if (ok) {
        *len = (size_t)sqlite3_column_bytes(st, 0);
        *data = xmalloc(*len ? *len : 1);
        if (*len) memcpy(*data, sqlite3_column_blob(st, 0), *len);
    } else {
        db_error(self, "reading a job", err, errsz);
    }
    sqlite3_finalize(st);
    return ok;
}

bool queue_start(queue *self, long id, int tiles, char *err, size_t errsz)
{
    char sql[200];
    snprintf(sql, sizeof sql, "UPDATE jobs SET state = 'running', started = coalesce(started, ?2), "
             "tiles = %d WHERE id = ?1 AND state IN ('queued', 'running')", tiles);
    return update(self, sql, id, err, errsz) > 0;
}

bool queue_requeue(queue *self, long id, char *err, size_t errsz)
{
    return update(self, "UPDATE jobs SET state = 'queued' WHERE id = ?1 AND state = 'running' "
                  "AND ?2 > 0", id, err, errsz) > 0;
}

bool queue_progress(queue *self, long id, int done, char *err, size_t errsz)
{
    char sql[120];
    snprintf(sql, sizeof sql, "UPDATE jobs SET tiles_done = %d WHERE id = ?1 AND ?2 > 0", done);
    return update(self, sql, id, err, errsz) >= 0;
}

bool queue_cancel_asked(queue *self, long id)
{
    sqlite3_stmt *st = prepare(self, "SELECT cancel FROM jobs WHERE id = ?", NULL, 0);
    if (!st) return false;
    sqlite3_bind_int64(st, 1, id);
    bool asked = sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int(st, 0) != 0;
    sqlite3_finalize(st);
    return asked;
}

bool queue_end(queue *self, long id, const char *state, int exit_status, const char *error,
               char *err, size_t errsz)
{
    sqlite3_stmt *st = prepare(self, "UPDATE jobs SET state = ?, exit_status = ?, error = ?, "
                               "ended = ? WHERE id = ?", err, errsz);
    if (!st) return false;
    sqlite3_bind_text(st, 1, state, -1, SQLITE_STATIC);
    sqlite3_bind_int(st, 2, exit_status);
    if (error && *error) sqlite3_bind_text(st, 3, error, -1, SQLITE_STATIC);
    else sqlite3_bind_null(st, 3);
    sqlite3_bind_double(st, 4, now_s());
    sqlite3_bind_int64(st, 5, id);
    bool ok = sqlite3_step(st) == SQLITE_DONE;
    if (!ok) db_error(self, "update", err, errsz);
    sqlite3_finalize(st);
    return ok;
}

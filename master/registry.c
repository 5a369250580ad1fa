/*
 * registry.c: the master's list of workers and the HELLO_FIRST rate
 * limit (see registry.h). Farms have tens to hundreds of workers, so a
 * plain array searched linearly is enough and keeps the code obvious.
 */
#include "registry.h"
#include "util/xalloc.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    REJECT_TABLE = 64,
    KEEP_RETIRED = 4096    /* retired workers kept for the summary */
};

typedef struct reject_entry {
    uint8_t id[REGISTRY_MAX_ID];
    size_t id_len;
    int64_t at_ms;
} reject_entry;

struct registry {
    farm_worker **workers;
    size_t count, cap;
    reject_entry rejects[REJECT_TABLE];
    size_t next_reject;
};

registry *registry_new(void)
{
    registry *self = xcalloc(1, sizeof *self);
    return self;
}

void registry_destroy(registry **self_p)
{
    registry *self = *self_p;
    if (!self) return;
    for (size_t i = 0; i < self->count; i++) free(self->workers[i]);
    free(self->workers);
    free(self);
    *self_p = NULL;
}

/* Forgets the oldest retired worker when too many are kept: a peer that
 * says Hello over and over must not grow the master without bound. */
static void drop_old_retired(registry *self)
{
    size_t retired = 0, first = self->count;
    for (size_t i = 0; i < self->count; i++)
        if (!self->workers[i]->alive && retired++ == 0) first = i;
    if (retired < KEEP_RETIRED) return;
    assert(first < self->count && !self->workers[first]->alive);   /* never a live one */
    free(self->workers[first]);
    memmove(&self->workers[first], &self->workers[first + 1],
            sizeof *self->workers * (self->count - first - 1));
    self->count--;
}

farm_worker *registry_add(registry *self, const uint8_t *id, size_t id_len, int64_t now_ms)
{
    if (id_len == 0 || id_len > REGISTRY_MAX_ID) return NULL;
    /* one live worker per routing id: the old one was retired first */
    assert(registry_find(self, id, id_len) == NULL);
    drop_old_retired(self);
    if (self->count == self->cap) {
        self->cap = self->cap ? self->cap * 2 : 16;
        self->workers = xrealloc(self->workers, sizeof *self->workers * self->cap);
    }
    farm_worker *w = xcalloc(1, sizeof *w);
    memcpy(w->id, id, id_len);
    w->id_len = id_len;
    w->alive = true;
    w->slot = -1;
    w->joined_ms = w->last_seen_ms = w->last_sent_ms = now_ms;
    self->workers[self->count++] = w;
    return w;
}

farm_worker *registry_find(const registry *self, const uint8_t *id, size_t id_len)
{
    for (size_t i = 0; i < self->count; i++) {
        farm_worker *w = self->workers[i];
        if (w->alive && w->id_len == id_len && memcmp(w->id, id, id_len) == 0) return w;
    }
    return NULL;
}

void registry_retire(registry *self, farm_worker *w, const char *why, int64_t now_ms)
{
    (void)self;
    assert(w->alive);   /* a worker is retired once (its slot's leases requeued once) */
    w->alive = false;
    w->credits = 0;
    w->left_ms = now_ms;
    snprintf(w->gone, sizeof w->gone, "%s", why);
}

size_t registry_count(const registry *self) { return self->count; }

farm_worker *registry_at(const registry *self, size_t i)
{
    return i < self->count ? self->workers[i] : NULL;
}

int registry_alive(const registry *self)
{
    int n = 0;
    for (size_t i = 0; i < self->count; i++) n += self->workers[i]->alive;
    return n;
}

bool registry_reject_due(registry *self, const uint8_t *id, size_t id_len, int64_t now_ms,
                         int64_t interval_ms)
{
    if (id_len == 0 || id_len > REGISTRY_MAX_ID) return false;
    for (size_t i = 0; i < REJECT_TABLE; i++) {
        reject_entry *e = &self->rejects[i];
        if (e->id_len != id_len || memcmp(e->id, id, id_len) != 0) continue;
        if (now_ms - e->at_ms < interval_ms) return false;
        e->at_ms = now_ms;
        return true;
    }
    reject_entry *e = &self->rejects[self->next_reject];
    self->next_reject = (self->next_reject + 1) % REJECT_TABLE;
    memcpy(e->id, id, id_len);
    e->id_len = id_len;
    e->at_ms = now_ms;
    return true;
}

const char *registry_id_hex(const uint8_t *id, size_t id_len, char *buf, size_t bufsz)
{
    size_t n = 0, max = (bufsz - 4) / 2;
    if (bufsz < 24) {
        if (bufsz) buf[0] = '\0';
        return buf;
    }
    for (size_t i = 0; i < id_len && i < max; i++) n += (size_t)snprintf(buf + n, bufsz - n, "%02x", id[i]);
    if (id_len > max) snprintf(buf + n, bufsz - n, "...");
    return buf;
}

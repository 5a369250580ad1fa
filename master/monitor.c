/*
 * monitor.c: the live monitor's state between the master's loop and the
 * HTTP thread (see monitor.h).
 */
#include "monitor.h"

#include <assert.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "image/preview.h"
#include "util/err.h"
#include "util/xalloc.h"

typedef struct monitor_frame {
    int width, height;             /* the frame's */
    int step;                      /* every step-th pixel is kept */
    int w, h;                      /* the kept image's */
    uint8_t *rgb;                  /* w * h * 3, NULL before its first tile */
    bool complete, dropped;
    int complete_order;            /* 1, 2, ... in order of completion */
    uint64_t version;              /* tiles put so far */
    void *png;                     /* cached PNG of version png_version */
    size_t png_len;
    uint64_t png_version;
} monitor_frame;

struct monitor {
    pthread_mutex_t lock;
    char *docs[MONITOR_NDOCS];
    size_t doc_len[MONITOR_NDOCS];
    monitor_frame *frames;
    int nframes, images, completed;
};

monitor *monitor_new(void)
{
    monitor *self = xcalloc(1, sizeof *self);
    pthread_mutex_init(&self->lock, NULL);
    return self;
}

void monitor_destroy(monitor **self_p)
{
    monitor *self = *self_p;
    if (!self) return;
    for (int i = 0; i < MONITOR_NDOCS; i++) free(self->docs[i]);
    for (int i = 0; i < self->nframes; i++) {
        free(self->frames[i].rgb);
        free(self->frames[i].png);
    }
    free(self->frames);
    pthread_mutex_destroy(&self->lock);
    free(self);
    *self_p = NULL;
}

int monitor_add_frame(monitor *self, int width, int height)
{
    pthread_mutex_lock(&self->lock);
    self->frames = xreallocarray(self->frames, (size_t)self->nframes + 1, sizeof *self->frames);
    monitor_frame *fr = &self->frames[self->nframes];
    memset(fr, 0, sizeof *fr);
    fr->width = width;
    fr->height = height;
    int side = width > height ? width : height;
    fr->step = (side + MONITOR_MAX_SIDE - 1) / MONITOR_MAX_SIDE;
    if (fr->step < 1) fr->step = 1;
    fr->w = (width + fr->step - 1) / fr->step;
    fr->h = (height + fr->step - 1) / fr->step;
    int index = self->nframes++;
    pthread_mutex_unlock(&self->lock);
    return index;
}

/* Makes room for one more image: drops the earliest complete frame's
 * when MONITOR_MAX_IMAGES are held. Under the lock. */
static void make_room(monitor *self)
{
    if (self->images < MONITOR_MAX_IMAGES) return;
    monitor_frame *oldest = NULL;
    for (int i = 0; i < self->nframes; i++) {
        monitor_frame *fr = &self->frames[i];
        if (fr->rgb && fr->complete && (!oldest || fr->complete_order < oldest->complete_order))
            oldest = fr;
    }
    if (!oldest) return;   /* every held frame is in progress: keep them all */
    free(oldest->rgb);
    free(oldest->png);
    oldest->rgb = NULL;
    oldest->png = NULL;
    oldest->dropped = true;
    self->images--;
}

void monitor_put_tile(monitor *self, int frame, image_rect r, const float *rgba)
{
    pthread_mutex_lock(&self->lock);
    assert(frame >= 0 && frame < self->nframes);
    monitor_frame *fr = &self->frames[frame];
    if (!fr->rgb && !fr->dropped) {
        make_room(self);
        fr->rgb = xcalloc((size_t)fr->w * (size_t)fr->h, 3);
        self->images++;
    }
    if (fr->rgb) {
        int s = fr->step;
        /* the kept pixels inside r: multiples of step */
        for (int y = (r.y0 + s - 1) / s * s; y < r.y0 + r.h; y += s)
            for (int x = (r.x0 + s - 1) / s * s; x < r.x0 + r.w; x += s) {
                const float *p = rgba + 4 * ((size_t)(y - r.y0) * (size_t)r.w + (size_t)(x - r.x0));
                uint8_t *q = fr->rgb + 3 * ((size_t)(y / s) * (size_t)fr->w + (size_t)(x / s));
                for (int c = 0; c < 3; c++) q[c] = image_preview_srgb8(p[c]);
            }
        fr->version++;
    }
    pthread_mutex_unlock(&self->lock);
}

void monitor_frame_complete(monitor *self, int frame)
{
    pthread_mutex_lock(&self->lock);
    assert(frame >= 0 && frame < self->nframes);
    if (!self->frames[frame].complete) {
        self->frames[frame].complete = true;
        self->frames[frame].complete_order = ++self->completed;
    }
    pthread_mutex_unlock(&self->lock);
}

void monitor_publish(monitor *self, monitor_doc doc, char *text, size_t len)
{
    assert(doc >= 0 && doc < MONITOR_NDOCS);
    pthread_mutex_lock(&self->lock);
    char *old = self->docs[doc];
    self->docs[doc] = text;
    self->doc_len[doc] = len;
    pthread_mutex_unlock(&self->lock);
    free(old);
}

char *monitor_doc_copy(monitor *self, monitor_doc doc, size_t *len)
{
    assert(doc >= 0 && doc < MONITOR_NDOCS);
    char *copy = NULL;
    pthread_mutex_lock(&self->lock);
    if (self->docs[doc]) {
        *len = self->doc_len[doc];
        copy = xmalloc(*len + 1);
        memcpy(copy, self->docs[doc], *len);
        copy[*len] = '\0';
    }
    pthread_mutex_unlock(&self->lock);
    return copy;
}

static void *copy_bytes(const void *p, size_t n)
{
    void *q = xmalloc(n ? n : 1);
    memcpy(q, p, n);
    return q;
}

bool monitor_png(monitor *self, int frame, void **png, size_t *len, bool *missing, char *err,
                 size_t errsz)
{
    *missing = false;
    pthread_mutex_lock(&self->lock);
    if (frame < 0 || frame >= self->nframes) {
        int n = self->nframes;
        pthread_mutex_unlock(&self->lock);
        *missing = true;
        return err_set(err, errsz, "no frame %d: this render has frames 0..%d", frame, n - 1);
    }
    monitor_frame *fr = &self->frames[frame];
    if (fr->dropped) {
        pthread_mutex_unlock(&self->lock);
        return err_set(err, errsz, "frame %d is complete and its image was dropped from the "
                       "monitor's memory (it keeps %d): read its output file", frame,
                       MONITOR_MAX_IMAGES);
    }
    if (fr->png && fr->png_version == fr->version) {   /* nothing new since */
        *png = copy_bytes(fr->png, fr->png_len);
        *len = fr->png_len;
        pthread_mutex_unlock(&self->lock);
        return true;
    }
    int w = fr->w, h = fr->h;
    uint64_t version = fr->version;
    size_t bytes = (size_t)w * (size_t)h * 3;
    uint8_t *rgb = fr->rgb ? copy_bytes(fr->rgb, bytes) : xcalloc(bytes, 1);
    pthread_mutex_unlock(&self->lock);
    bool ok = image_preview_encode_png_rgb8(rgb, w, h, png, len, err, errsz);   /* unlocked */
    free(rgb);
    if (!ok) return false;
    pthread_mutex_lock(&self->lock);
    fr = &self->frames[frame];
    if (!fr->dropped && fr->version == version && (!fr->png || fr->png_version != version)) {
        free(fr->png);
        fr->png = copy_bytes(*png, *len);
        fr->png_len = *len;
        fr->png_version = version;
    }
    pthread_mutex_unlock(&self->lock);
    return true;
}

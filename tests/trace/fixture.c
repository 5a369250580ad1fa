/*
 * fixture.c: in-memory jobs for renderer tests (see fixture.h).
 */
#include "fixture.h"

#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trace/group.h"

bool fixture_open(fixture *f, const char *rib, const fixture_shader *shaders,
                  int nshaders, const job_options *opt, size_t cache_bytes)
{
    memset(f, 0, sizeof *f);
    f->diag = sl_diag_new();
    f->job = job_new("test.rib", rib, strlen(rib), opt);
    char why[256];
    for (int i = 0; i < nshaders; i++) {
        char file[128];
        snprintf(file, sizeof file, "%s.sl", shaders[i].name);
        if (!job_add_source(f->job, file, shaders[i].source, strlen(shaders[i].source), why, sizeof why) ||
            !job_add_shader(f->job, shaders[i].name, file, why, sizeof why)) {
            fprintf(stderr, "fixture: %s\n", why);
            return false;
        }
    }
    if (!job_finish(f->job, why, sizeof why)) {
        fprintf(stderr, "fixture: %s\n", why);
        return false;
    }
    f->js = job_scene_new(f->job, cache_bytes, true, NULL, f->diag);
    if (!f->js) {
        sl_diag_print(f->diag, stderr);
        return false;
    }
    return true;
}

bool fixture_open_named(fixture *f, const char *rib_format, const char *name,
                        const char *source)
{
    fixture_shader sh[] = {{name, source}};
    char rib[1024];
    int n = snprintf(rib, sizeof rib, rib_format, name);
    if (n < 0 || (size_t)n >= sizeof rib) {
        fprintf(stderr, "fixture: the RIB of %s does not fit %zu bytes\n", name, sizeof rib);
        memset(f, 0, sizeof *f);
        return false;
    }
    return fixture_open(f, rib, sh, 1, NULL, 0);
}

int fixture_count_shared(const trace_world *w)
{
    int n = 0;
    for (int i = 0; i < w->nobjects; i++) {
        const trace_group *g = w->objects[i].group;
        n += w->objects[i].box_proto != NULL;
        if (g && g->first_id >= 0) n += g->n - g->nown;
    }
    return n;
}

void fixture_close(fixture *f)
{
    job_scene_destroy(&f->js);
    job_destroy(&f->job);
    sl_diag_destroy(&f->diag);
}

bool fixture_render(fixture *f, int tile, int nthreads, size_t cache_bytes,
                    float *rgba, float *z)
{
    trace_world *w = &f->js->world;
    size_t saved = w->options.cache_bytes;
    w->options.cache_bytes = cache_bytes;
    trace_thread **th = calloc((size_t)nthreads, sizeof *th);
    for (int i = 0; i < nthreads; i++) th[i] = trace_thread_new(w);
    w->options.cache_bytes = saved;
    int W = w->camera.xres, H = w->camera.yres, k = 0;
    bool ok = true;
    float *trgba = malloc(sizeof(float) * 4 * (size_t)tile * (size_t)tile);
    float *tz = malloc(sizeof(float) * (size_t)tile * (size_t)tile);
    for (int y0 = 0; y0 < H && ok; y0 += tile)
        for (int x0 = 0; x0 < W && ok; x0 += tile) {
            int tw = x0 + tile <= W ? tile : W - x0, thh = y0 + tile <= H ? tile : H - y0;
            trace_thread *t = th[k++ % nthreads];
            if (!trace_render_tile(f->js->renderer, t, x0, y0, tw, thh, trgba, tz)) {
                fprintf(stderr, "fixture: %s\n", t->error);
                ok = false;
                break;
            }
            for (int y = 0; y < thh; y++) {
                memcpy(&rgba[((size_t)(y0 + y) * (size_t)W + (size_t)x0) * 4],
                       &trgba[(size_t)y * (size_t)tw * 4], sizeof(float) * 4 * (size_t)tw);
                memcpy(&z[(size_t)(y0 + y) * (size_t)W + (size_t)x0],
                       &tz[(size_t)y * (size_t)tw], sizeof(float) * (size_t)tw);
            }
        }
    free(trgba);
    free(tz);
    for (int i = 0; i < nthreads; i++) trace_thread_destroy(&th[i]);
    free(th);
    return ok;
}

char *fixture_instances_rib(int n, const char *definition, const char *shader, double km)
{
    size_t cap = (size_t)n * 120 + strlen(definition) + 4096, len = 0;
    char *s = malloc(cap);
    if (!s) abort();
    int side = (int)ceil(sqrt(n));
    len += (size_t)snprintf(s + len, cap - len,
        "Format 16 16 1\nProjection \"perspective\" \"fov\" [40]\nTranslate 0 0 %d\n"
        "WorldBegin\nSurface \"plastic\"\nDisplacement \"%s\" \"float Km\" [%g]\n"
        "ObjectBegin 1\n  %s\nObjectEnd\n", side + 2, shader, km, definition);
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(s + len, cap - len,
                                "AttributeBegin\nTranslate %d %d 0\nRotate %d 0.3 1 0.2\n"
                                "ObjectInstance 1\nAttributeEnd\n",
                                i % side - side / 2, i / side - side / 2, (i * 37) % 360);
    snprintf(s + len, cap - len, "WorldEnd\n");
    return s;
}

char *fixture_torus_rib(int nu, int nv, const char *head, const char *request)
{
    size_t cap = (size_t)nu * nv * 90 + 4096, n = 0;
    char *t = malloc(cap);
    if (!t) abort();
    n += (size_t)snprintf(t + n, cap - n, "Format 32 32 1\nProjection \"perspective\" "
                          "\"fov\" [40]\nTranslate 0 0 4\nRotate 60 1 0 0\nWorldBegin\n%s"
                          "%s [", head, request);
    for (int i = 0; i < nu * nv; i++) n += (size_t)snprintf(t + n, cap - n, "4 ");
    n += (size_t)snprintf(t + n, cap - n, "]\n[");
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
            n += (size_t)snprintf(t + n, cap - n, "%d %d %d %d ", i * nv + j, i * nv + j1,
                                  i1 * nv + j1, i1 * nv + j);
        }
    n += (size_t)snprintf(t + n, cap - n, "]\n\"P\" [");
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double a = 2 * M_PI * i / nu, b = 2 * M_PI * j / nv, r = 1 + 0.4 * cos(b);
            n += (size_t)snprintf(t + n, cap - n, "%.9g %.9g %.9g ", r * cos(a), r * sin(a),
                                  0.4 * sin(b));
        }
    snprintf(t + n, cap - n, "]\nWorldEnd\n");
    return t;
}

size_t fixture_heap_bytes(void)
{
    struct mallinfo2 mi = mallinfo2();
    return mi.uordblks + mi.hblkhd;
}

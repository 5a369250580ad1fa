/*
 * corpus.c: loading the shader corpus and building its test scenes (see
 * corpus.h).
 */
#include "corpus.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sl/noise.h"
#include "tex/tex.h"
#include "test_rng.h"

#ifndef AAFARM_CORPUS_DIR
#error "AAFARM_CORPUS_DIR must name tests/shaders/corpus"
#endif

static char *read_all(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return NULL;
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    if (n < 0 || fread(buf, 1, (size_t)n, fp) != (size_t)n) {
        free(buf);
        fclose(fp);
        return NULL;
    }
    buf[n] = 0;
    fclose(fp);
    return buf;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(((const corpus_file *)a)->name, ((const corpus_file *)b)->name);
}

static bool wanted(const char *name)
{
    const char *only = getenv("AAFARM_CORPUS_ONLY");
    if (!only || !*only) return true;
    size_t n = strlen(name);
    for (const char *p = only; *p;) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && strncmp(p, name, n) == 0) return true;
        if (!e) break;
        p = e + 1;
    }
    return false;
}

/* the files of dir ending in ext, names (without ext when strip) prefixed */
static bool load_dir(const char *dir, const char *ext, bool strip, const char *prefix,
                     bool filter, corpus_file **out, int *count)
{
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "corpus: cannot open %s\n", dir);
        return false;
    }
    struct dirent *e;
    size_t el = strlen(ext);
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n <= el || strcmp(e->d_name + n - el, ext) != 0) continue;
        corpus_file f;
        memset(&f, 0, sizeof f);
        snprintf(f.name, sizeof f.name, "%s%.*s", prefix, (int)(strip ? n - el : n), e->d_name);
        if (filter && !wanted(f.name)) continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        f.text = read_all(path);
        if (!f.text) {
            fprintf(stderr, "corpus: cannot read %s\n", path);
            closedir(d);
            return false;
        }
        *out = realloc(*out, sizeof **out * (size_t)(*count + 1));
        (*out)[(*count)++] = f;
    }
    closedir(d);
    if (*count) qsort(*out, (size_t)*count, sizeof **out, by_name);
    return true;
}

/* The maps of the tex_* shaders (corpus.h). */
static bool write_textures(corpus *c)
{
    snprintf(c->texdir, sizeof c->texdir, "/tmp/aafarm_corpus_tex.XXXXXX");
    if (!mkdtemp(c->texdir)) {
        fprintf(stderr, "corpus: cannot make a folder for the texture maps\n");
        c->texdir[0] = 0;
        return false;
    }
    enum { HW = 96, HH = 64, CW = 24, CH = 16 };
    static float height[HW * HH], rgb[CW * CH * 3];
    for (int j = 0; j < HH; j++)
        for (int i = 0; i < HW; i++) {
            double sum = 0, amp = 0.5;
            for (int o = 0, cells = 3; o < 4; o++, cells *= 2, amp *= 0.5) {
                double p[2] = {(i + 0.5) / HW * cells, (j + 0.5) / HH * cells};
                int per[2] = {cells, cells};
                sum += amp * (2 * sl_pnoise(2, p, per) - 1);
            }
            height[j * HW + i] = (float)sum;
        }
    corpus_rng r = {77};
    for (int k = 0; k < CW * CH * 3; k++) rgb[k] = (float)corpus_rng_uniform(&r);
    const struct { const char *name; const float *px; int w, h, nch; } maps[] = {
        {"corpus_height.exr", height, HW, HH, 1}, {"corpus_rgb.exr", rgb, CW, CH, 3}};
    for (size_t m = 0; m < sizeof maps / sizeof maps[0]; m++) {
        char path[256], err[512];
        snprintf(path, sizeof path, "%s/%s", c->texdir, maps[m].name);
        tex_texture *t = tex_from_pixels(maps[m].px, maps[m].w, maps[m].h, maps[m].nch, path);
        bool ok = t && tex_write_exr(path, t, true, err, sizeof err);
        tex_destroy(&t);
        if (!ok) {
            fprintf(stderr, "corpus: %s\n", err);
            return false;
        }
    }
    return true;
}

bool corpus_load(corpus *c)
{
    memset(c, 0, sizeof *c);
    return load_dir(AAFARM_CORPUS_DIR, ".sl", true, "", true, &c->shaders, &c->nshaders) &&
           load_dir(AAFARM_CORPUS_DIR "/include", ".h", false, "include/", false,
                    &c->headers, &c->nheaders) &&
           write_textures(c);
}

void corpus_free(corpus *c)
{
    if (c->texdir[0]) {
        char path[256];
        const char *names[] = {"corpus_height.exr", "corpus_rgb.exr"};
        for (int k = 0; k < 2; k++) {
            snprintf(path, sizeof path, "%s/%s", c->texdir, names[k]);
            unlink(path);
        }
        rmdir(c->texdir);
    }
    for (int i = 0; i < c->nshaders; i++) free(c->shaders[i].text);
    for (int i = 0; i < c->nheaders; i++) free(c->headers[i].text);
    free(c->shaders);
    free(c->headers);
    memset(c, 0, sizeof *c);
}

const char *corpus_surface_name(corpus_surface s)
{
    static const char *names[] = {"plane", "sphere", "ellipsoid", "cylinder", "patch", "mesh", "subdiv", "nurbs",
                                  "apex", "collapsed"};
    return s < CORPUS_NSURFACES ? names[s] : "?";
}

/* A 2x2 grid of quads over [-1,1]^2, each split into two triangles, with
 * heights z = 0.25 x y + 0.15 x: eight Polygons sharing their edges, all
 * counter-clockwise seen from +z. */
static void mesh_rib(char *out, size_t size, const char *disp)
{
    size_t n = (size_t)snprintf(out, size, "%s", disp);
    double g[3] = {-1, 0, 1};
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            double x0 = g[i], x1 = g[i + 1], y0 = g[j], y1 = g[j + 1];
#define Z(x, y) (0.25 * (x) * (y) + 0.15 * (x))
            n += (size_t)snprintf(out + n, size - n,
                                  "Polygon \"P\" [%g %g %g  %g %g %g  %g %g %g]\n"
                                  "Polygon \"P\" [%g %g %g  %g %g %g  %g %g %g]\n",
                                  x0, y0, Z(x0, y0), x1, y0, Z(x1, y0), x1, y1, Z(x1, y1),
                                  x0, y0, Z(x0, y0), x1, y1, Z(x1, y1), x0, y1, Z(x0, y1));
#undef Z
        }
}

/* The points of the corpus NuPatch: the half circle of radius 1 (two
 * rational quadratic arcs, u) swept along a cubic profile (v): radius
 * 0.6 + 0.1 j, height 0.5 (j - 2), weights wu * wv. */
static const char *nurbs_points(void)
{
    static char out[2048];
    static const double cx[5] = { 1, 1, 0, -1, -1 }, cy[5] = { 0, 1, 1, 1, 0 };
    static const double wv[5] = { 1, 2, 0.5, 1, 2 };
    size_t n = 0;
    out[0] = '\0';
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            double w = (i % 2 ? 0.70710678118654752 : 1) * wv[j];
            double r = 0.6 + 0.1 * j;
            n += (size_t)snprintf(out + n, sizeof out - n, "%.17g %.17g %.17g %.17g  ",
                                  r * cx[i] * w, r * cy[i] * w, 0.5 * (j - 2) * w, w);
        }
    return out;
}

bool corpus_open(fixture *f, const corpus *c, const corpus_file *sh,
                 corpus_surface s, trace_arith arith, int xres, int yres, bool render)
{
    char disp[128], geom[4096];
    snprintf(disp, sizeof disp, "Displacement \"%s\"\n", sh->name);
    switch (s) {
    case CORPUS_PLANE:
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate -50 1 0 0\n%s"
                 "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\n", disp);
        break;
    case CORPUS_SPHERE:
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate 70 1 0 0\n%s"
                 "Sphere 1 -1 1 360\n", disp);
        break;
    case CORPUS_ELLIPSOID:
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate 30 0 1 0\nRotate 60 1 0 0\n"
                 "Scale 1.3 0.6 0.9\n%sSphere 1 -1 1 360\n", disp);
        break;
    case CORPUS_CYLINDER:
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate 60 1 0 0\n%s"
                 "Cylinder 0.7 -1 1 360\n", disp);
        break;
    case CORPUS_PATCH:
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate -40 1 0 0\n%s"
                 "Patch \"bilinear\" \"P\" [-1 -1 0.3  1 -1 -0.2  -1 1 -0.3  1 1 0.4]\n", disp);
        break;
    case CORPUS_MESH: {
        char tmp[256];
        snprintf(tmp, sizeof tmp, "Translate 0 0 5\nRotate -40 1 0 0\n%s", disp);
        mesh_rib(geom, sizeof geom, tmp);
        break;
    }
    case CORPUS_SUBDIV:
        /* a creased box (valence 3 extraordinary points, an infinitely
         * sharp and a semi-sharp crease) and an open fan of five quads
         * (valence 5, boundary with interpolateboundary). No corner tag:
         * its point is a cone whose normals sweep a wide range close to
         * it, which the idioms of 1 / length(ntransform(N)) turn into
         * unbounded boxes (tests/geom/test_geom_subdiv covers corners) */
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate -40 1 0 0\nRotate 25 0 0 1\n%s"
            "AttributeBegin\nTranslate -0.6 0 0\nScale 0.5 0.5 0.5\n"
            "SubdivisionMesh \"catmull-clark\" [4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4 4]\n"
            "  [0 1 2 3  3 2 4 5  1 6 7 2  2 7 8 4  12 11 10 9  14 13 11 12  11 16 15 10  "
            "13 17 16 11  15 16 18 19  19 18 7 6  16 17 20 18  18 20 8 7  22 21 12 9  "
            "0 3 21 22  21 23 14 12  3 5 23 21  14 23 24 13  13 24 20 17  23 5 4 24  "
            "24 4 8 20  10 25 22 9  15 19 25 10  25 1 0 22  19 6 1 25]\n"
            "  [\"crease\" \"crease\"] [9 1 3 1]\n"
            "  [14 23 5 4 8 20 17 13 14  6 7 8] [10 2.5]\n"
            "  \"P\" [1 -1 -1  1 0 -1  1 0 0  1 -1 0  1 0 1  1 -1 1  1 1 -1  1 1 0  1 1 1  "
            "-1 -1 -1  -1 0 -1  -1 0 0  -1 -1 0  -1 0 1  -1 -1 1  -1 1 -1  -1 1 0  -1 1 1  "
            "0 1 0  0 1 -1  0 1 1  0 -1 0  0 -1 -1  0 -1 1  0 0 1  0 0 -1]\n"
            "AttributeEnd\nAttributeBegin\nTranslate 0.7 0 0\nScale 0.5 0.5 0.5\n"
            "SubdivisionMesh \"catmull-clark\" [4 4 4 4 4] [0 1 2 3  0 3 4 5  0 5 6 7  "
            "0 7 8 9  0 9 10 1] [\"interpolateboundary\"] [0 0] [] []\n"
            "  \"P\" [0.1 0 0.3  1 0 0  1.133 0.823 -0.2  0.309 0.951 -0.118  -0.433 1.331 -0.1  "
            "-0.809 0.588 0.19  -1.4 0 0  -0.809 -0.588 -0.19  -0.433 -1.331 0.1  "
            "0.309 -0.951 0.118  1.133 -0.823 0.2]\n"
            "AttributeEnd\n", disp);
        break;
    case CORPUS_NURBS:
        /* a rational NuPatch of orders 3 x 4, 2 x 2 pieces: a quarter of a
         * torus-like surface of revolution whose weights differ (the arcs'
         * sqrt(2)/2 and a cubic profile weighted 1 2 0.5 1 2) */
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate -60 1 0 0\nRotate 20 0 0 1\n%s"
            "NuPatch 5 3 [0 0 0 1 1 2 2 2] 0 2  5 4 [0 0 0 0 1 2 2 2 2] 0 2 \"Pw\" [%s]\n",
            disp, nurbs_points());
        break;
    case CORPUS_APEX:
        /* Ng = 0 at the disk's centre and the cone's apex (v = 1) and the
         * paraboloid's apex (v = 0): their normals there are limits
         * (docs/geometry.md, "Singular points"); the cone under a
         * non-uniform scale (the camera normal's clamped path) */
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate -50 1 0 0\n%s"
            "AttributeBegin\nTranslate -0.7 0 0\nDisk 0.1 0.5 360\nAttributeEnd\n"
            "AttributeBegin\nTranslate 0.1 0.3 0\nScale 1 0.7 1.2\nCone 0.8 0.4 300\n"
            "AttributeEnd\n"
            "AttributeBegin\nTranslate 0.6 -0.4 -0.3\nParaboloid 0.4 0 0.7 360\n"
            "AttributeEnd\n", disp);
        break;
    case CORPUS_COLLAPSED:
        /* Ng = 0 along an edge (v = 0): a bilinear patch with P00 = P10 (a
         * triangle), a bicubic patch whose first row is one point (a
         * dome's cap) and a hyperboloid from a point on its axis */
        snprintf(geom, sizeof geom, "Translate 0 0 5\nRotate -40 1 0 0\n%s"
            "AttributeBegin\nTranslate -0.6 0 0\n"
            "Patch \"bilinear\" \"P\" [0 -0.5 0.2  0 -0.5 0.2  -0.5 0.5 -0.1  0.5 0.5 0.3]\n"
            "AttributeEnd\n"
            "AttributeBegin\nTranslate 0.5 0 0\n"
            "Patch \"bicubic\" \"P\" [0 -0.5 0.4  0 -0.5 0.4  0 -0.5 0.4  0 -0.5 0.4  "
            "-0.5 -0.2 0.1  -0.2 -0.1 0.5  0.2 -0.1 0.5  0.5 -0.2 0.1  "
            "-0.5 0.2 0  -0.2 0.2 0.3  0.2 0.2 0.3  0.5 0.2 0  "
            "-0.5 0.5 -0.2  -0.2 0.5 0  0.2 0.5 0  0.5 0.5 -0.2]\n"
            "AttributeEnd\n"
            "AttributeBegin\nTranslate 0 -0.6 0\n"
            "Hyperboloid 0 0 0  0.4 0.1 0.5  360\nAttributeEnd\n", disp);
        break;
    default:
        return false;
    }
    return corpus_open_world(f, c, sh, corpus_surface_name(s), geom, arith, xres, yres, render);
}

bool corpus_open_world(fixture *f, const corpus *c, const corpus_file *sh, const char *what,
                       const char *world, trace_arith arith, int xres, int yres, bool render)
{
    size_t cap = strlen(world) + 1024;
    char *rib = malloc(cap);
    if (!rib) return false;
    snprintf(rib, cap,
             "Option \"searchpath\" \"texture\" [\"%s\"]\n"
             "Format %d %d 1\nProjection \"perspective\" \"fov\" [35]\n"
             "WorldBegin\nAttributeBegin\n%sAttributeEnd\nWorldEnd\n",
             c->texdir, xres, yres, world);

    job_options opt;
    job_options_default(&opt);
    opt.arith = arith;
    memset(f, 0, sizeof *f);
    f->diag = sl_diag_new();
    f->job = job_new("corpus.rib", rib, strlen(rib), &opt);
    free(rib);
    char why[256], file[96];
    for (int i = 0; i < c->nheaders; i++)
        if (!job_add_source(f->job, c->headers[i].name, c->headers[i].text,
                            strlen(c->headers[i].text), why, sizeof why)) {
            fprintf(stderr, "corpus: %s\n", why);
            return false;
        }
    snprintf(file, sizeof file, "%s.sl", sh->name);
    if (!job_add_source(f->job, file, sh->text, strlen(sh->text), why, sizeof why) ||
        !job_add_shader(f->job, sh->name, file, why, sizeof why) ||
        !job_finish(f->job, why, sizeof why)) {
        fprintf(stderr, "corpus: %s: %s\n", sh->name, why);
        return false;
    }
    f->js = job_scene_new(f->job, 0, render, NULL, f->diag);
    if (!f->js) {
        fprintf(stderr, "corpus: %s on the %s:\n", sh->name, what);
        sl_diag_print(f->diag, stderr);
        return false;
    }
    return true;
}

long corpus_env_long(const char *name, long def)
{
    const char *v = getenv(name);
    if (!v || !*v) return def;
    char *end;
    long n = strtol(v, &end, 10);
    return (*end || n < 1) ? def : n;
}

double corpus_rng_uniform(corpus_rng *r)
{
    return test_rng_unit(&r->s);
}

int corpus_group_load(corpus *c, void **state)
{
    (void)state;
    return corpus_load(c) ? 0 : -1;
}

int corpus_group_free(corpus *c, void **state)
{
    (void)state;
    corpus_free(c);
    return 0;
}

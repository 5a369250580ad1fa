/*
 * peers_embree.c: the tessellation peer of the benchmark (bench/peers/):
 * what a user of Embree 3 would do with a procedural displacement shader
 * instead of ray-tracing it directly (Heidrich & Seidel 1998 §1-2: dice,
 * then trace the micro-polygons). One thread throughout.
 *
 *   peers_embree SCENE.rib N OUT.png [--normals grid|shader] [--ka KA] [--kd KD]
 *
 * 1. tessellate: the displaced surface of every object of the scene on an
 *    (N+1) x (N+1) vertex grid over its (u,v) square (a polygon: per
 *    face, over its corners; a mesh thus gets N x N cells per face), each
 *    vertex from
 *    aafarm's own point evaluation (trace_surface_point_eval: base surface
 *    + displacement shader in dual mode), so the surface is exactly
 *    aafarm's function, with the shader's shading normal N per vertex;
 * 2. build: one Embree grid geometry per object (RTC_GEOMETRY_TYPE_GRID, Embree's own
 *    format for displaced tessellations: no index buffer) and its BVH;
 * 3. trace: one primary ray per pixel through the pixel centre, built by
 *    aafarm's camera (trace_camera_ray), shaded with RenderMan's matte
 *    (Cs (Ka ambient + Kd sum Cl max(0, Nf.L))) under the scene's ambient
 *    and distant lights, Nf the normal interpolated smoothly from the grid's
 *    vertex normals and turned towards the eye (faceforward). The vertex
 *    normals are the grid's own (--normals grid, default: central
 *    differences of the vertices, what a mesh renderer has) or the
 *    shader's N at each vertex (--normals shader: exact on smooth
 *    surfaces, but the nail's walls then get the normals of its top and
 *    of the disk).
 *
 * The scenes of bench/peers/scenes/ use Surface "matte" Ka 1 Kd 0.7 (the
 * defaults here). Prints one line of figures:
 *   "tess_cpu_s T build_cpu_s B trace_cpu_s R vertex_bytes V bvh_bytes M
 *    bvh_peak_bytes P hits H"
 * vertex_bytes: the vertex positions and normals (float3 each); bvh_bytes:
 * what Embree holds after the build (its memory monitor), peak: during it.
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <time.h>

#include "job/job.h"
#include "job/job_scene.h"
#include "peers_png.h"
#include "trace/camera.h"
#include "trace/displace.h"
#include "trace/mesh.h"
#include "trace/render.h"

/* Piece k of ob as an object: ob itself, or a mesh's piece made into
 * *view (its surface and primitive variables; no boxes: points only) */
static const trace_object *piece_of(trace_thread *th, const trace_object *ob, int k,
                                    trace_view *view)
{
    if (!ob->mesh) return ob;
    if (!trace_mesh_view_make(th, ob, k, false, view)) {
        fprintf(stderr, "peers_embree: piece %d of object %d could not be made\n", k, ob->id);
        exit(1);
    }
    return &view->obj;
}

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

typedef struct mem_monitor {
    long long bytes, peak;
} mem_monitor;

static bool on_memory(void *ptr, ssize_t bytes, bool post)
{
    (void)post;
    mem_monitor *m = ptr;
    m->bytes += bytes;
    if (m->bytes > m->peak) m->peak = m->bytes;
    return true;
}

static void on_embree_error(void *ptr, enum RTCError code, const char *str)
{
    (void)ptr;
    fprintf(stderr, "peers_embree: Embree error %d: %s\n", (int)code, str ? str : "");
}

static int usage(void)
{
    fprintf(stderr, "usage: peers_embree SCENE.rib N OUT.png [--normals grid|shader] [--ka KA] [--kd KD]\n"
                    "  N: grid cells per side, 1 .. 32766\n");
    return 2;
}

int main(int argc, char **argv)
{
    if (argc < 4) return usage();
    const char *rib = argv[1], *out = argv[3];
    char *end = NULL;
    long n = strtol(argv[2], &end, 10);
    if (*end || n < 1 || n > 32766) return usage();
    double ka = 1.0, kd = 0.7;
    bool grid_normals = true;
    for (int i = 4; i < argc; i++) {
        if (strcmp(argv[i], "--normals") == 0 && i + 1 < argc) {
            i++;
            if (strcmp(argv[i], "grid") == 0) grid_normals = true;
            else if (strcmp(argv[i], "shader") == 0) grid_normals = false;
            else return usage();
        } else if (strcmp(argv[i], "--ka") == 0 && i + 1 < argc) ka = atof(argv[++i]);
        else if (strcmp(argv[i], "--kd") == 0 && i + 1 < argc) kd = atof(argv[++i]);
        else return usage();
    }

    job_options opt;
    job_options_default(&opt);
    sl_diag *diag = sl_diag_new();
    job *jb = job_load(rib, &opt, NULL, diag);
    job_scene *js = jb ? job_scene_new(jb, 0, true, NULL, diag) : NULL;
    sl_diag_print(diag, stderr);
    sl_diag_destroy(&diag);
    if (!js) {
        job_destroy(&jb);
        return 3;
    }
    const trace_world *w = &js->world;
    if (w->nobjects < 1) {
        fprintf(stderr, "peers_embree: %s: no objects to tessellate\n", rib);
        return 3;
    }
    trace_thread *th = trace_thread_new(w);

    /* 1. tessellate every object: one (N+1) x (N+1) grid per (u,v) square,
     * or per face of a polygon (a quad: bilinear in its (u,v) corners; a
     * triangle: a grid whose last row collapses to its third corner; more
     * corners: a fan of such triangles); one float3 of padding: Embree
     * reads 16 bytes per vertex */
    typedef struct gpatch { int obj, piece; double c[4][2]; } gpatch;
    gpatch *gp = NULL;
    long ngp = 0;
    trace_view *view = malloc(sizeof *view);
    if (!view) abort();
    for (int o = 0; o < w->nobjects; o++) {
        const trace_object *ob = &w->objects[o];
        for (int pc = 0; pc < trace_object_npieces(ob); pc++) {
            const geom_surface *sf = &piece_of(th, ob, pc, view)->surf;
            int parts = sf->kind == GEOM_POLYGON && sf->nuv > 4 ? sf->nuv - 2 : 1;
            gp = realloc(gp, sizeof *gp * (size_t)(ngp + parts));
            if (!gp) abort();
            for (int k = 0; k < parts; k++) {
                gpatch *g = &gp[ngp++];
                g->obj = o;
                g->piece = pc;
                if (sf->kind != GEOM_POLYGON) {
                    double sq[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
                    memcpy(g->c, sq, sizeof sq);
                } else if (sf->nuv == 4) {
                    for (int q = 0; q < 4; q++) g->c[q][0] = sf->uv[q][0], g->c[q][1] = sf->uv[q][1];
                } else {
                    int id[4] = {0, k + 1, k + 2, k + 2};
                    for (int q = 0; q < 4; q++)
                        g->c[q][0] = sf->uv[id[q]][0], g->c[q][1] = sf->uv[id[q]][1];
                }
            }
        }
    }
    long per = (n + 1) * (n + 1), nv = per * ngp;
    float *P = malloc(sizeof(float) * 3 * (size_t)(nv + 1));
    float *N = malloc(sizeof(float) * 3 * (size_t)(nv + 1));
    if (!P || !N) {
        fprintf(stderr, "peers_embree: out of memory for %ld grids of %ldx%ld\n", ngp, n, n);
        return 1;
    }
    long outside = 0;
    const trace_object *obj = NULL;
    double t0 = cpu_now();
    for (long gi = 0; gi < ngp; gi++) {
        const gpatch *gq = &gp[gi];
        if (gi == 0 || gq->obj != gp[gi - 1].obj || gq->piece != gp[gi - 1].piece)
            obj = piece_of(th, &w->objects[gq->obj], gq->piece, view);
        float *GP = P + 3 * per * gi, *GN = N + 3 * per * gi;
        for (long j = 0; j <= n; j++) {
            double v = (double)j / (double)n;
            for (int pass = 0; pass < 2; pass++) {
                for (long i = 0; i <= n; i++) {
                    double a = (double)i / (double)n, u, vv;
                    /* bilinear in the corners c0 c1 c2 c3 (counter-clockwise) */
                    u = (1 - v) * ((1 - a) * gq->c[0][0] + a * gq->c[1][0]) +
                        v * ((1 - a) * gq->c[3][0] + a * gq->c[2][0]);
                    vv = (1 - v) * ((1 - a) * gq->c[0][1] + a * gq->c[1][1]) +
                         v * ((1 - a) * gq->c[3][1] + a * gq->c[2][1]);
                    trace_surface_point sp;
                    trace_surface_point_eval(th, obj, u, vv, &sp);
                    if (pass == 0) outside += !geom_uv_inside(&obj->surf, u, vv);
                    float *p = &GP[3 * (j * (n + 1) + i)], *q = &GN[3 * (j * (n + 1) + i)];
                    p[0] = (float)sp.P.x, p[1] = (float)sp.P.y, p[2] = (float)sp.P.z;
                    q[0] = (float)sp.N.x, q[1] = (float)sp.N.y, q[2] = (float)sp.N.z;
                }
                /* A row that is one point (the pole of a disk or sphere) makes
                 * Embree's grid intersector report hits along a line through
                 * that point far outside the surface (seen on the nail): move
                 * such a row a thousandth of a cell inwards, a ring instead. */
                const float *a = &GP[3 * (j * (n + 1))], *b = &GP[3 * (j * (n + 1) + n / 2)];
                if (pass == 1 || n < 2 || a[0] != b[0] || a[1] != b[1] || a[2] != b[2]) break;
                v += (j == n ? -1e-3 : 1e-3) / (double)n;
            }
        }
        if (grid_normals) {
            /* smooth normals from the grid: central differences of the vertex
             * positions (one-sided at the borders), the shader's N where they
             * vanish; shading turns them to face the eye, so the sign is free */
            float *G = malloc(sizeof(float) * 3 * (size_t)per);
            if (!G) abort();
            for (long j = 0; j <= n; j++)
                for (long i = 0; i <= n; i++) {
                    long i0 = i > 0 ? i - 1 : i, i1 = i < n ? i + 1 : i;
                    long j0 = j > 0 ? j - 1 : j, j1 = j < n ? j + 1 : j;
                    const float *pu0 = &GP[3 * (j * (n + 1) + i0)], *pu1 = &GP[3 * (j * (n + 1) + i1)];
                    const float *pv0 = &GP[3 * (j0 * (n + 1) + i)], *pv1 = &GP[3 * (j1 * (n + 1) + i)];
                    vec3 du = v3(pu1[0] - pu0[0], pu1[1] - pu0[1], pu1[2] - pu0[2]);
                    vec3 dv = v3(pv1[0] - pv0[0], pv1[1] - pv0[1], pv1[2] - pv0[2]);
                    vec3 c = v3_cross(du, dv);
                    double len = v3_length(c);
                    float *g = &G[3 * (j * (n + 1) + i)];
                    const float *q = &GN[3 * (j * (n + 1) + i)];
                    if (len > 0 && isfinite(len)) {
                        g[0] = (float)(c.x / len), g[1] = (float)(c.y / len), g[2] = (float)(c.z / len);
                    } else {
                        g[0] = q[0], g[1] = q[1], g[2] = q[2];
                    }
                }
            memcpy(GN, G, sizeof(float) * 3 * (size_t)per);
            free(G);
        }
    }
    double t_tess = cpu_now() - t0;
    memset(&P[3 * nv], 0, 3 * sizeof(float));
    memset(&N[3 * nv], 0, 3 * sizeof(float));
    if (th->failed) {
        fprintf(stderr, "peers_embree: %s: shader failed while tessellating: %s\n", rib, th->error);
        return 1;
    }
    if (outside)
        fprintf(stderr, "peers_embree: warning: %ld grid vertices lie outside their polygon\n",
                outside);

    /* 2. build: one grid geometry per object (geomID = object index) */
    mem_monitor mon = {0, 0};
    RTCDevice dev = rtcNewDevice("threads=1,set_affinity=0");
    if (!dev) {
        fprintf(stderr, "peers_embree: rtcNewDevice failed (error %d)\n", (int)rtcGetDeviceError(NULL));
        return 1;
    }
    rtcSetDeviceErrorFunction(dev, on_embree_error, NULL);
    rtcSetDeviceMemoryMonitorFunction(dev, on_memory, &mon);
    t0 = cpu_now();
    RTCScene rscene = rtcNewScene(dev);
    for (long gi = 0; gi < ngp;) {
        long gend = gi;
        while (gend < ngp && gp[gend].obj == gp[gi].obj) gend++;
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_GRID);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, P + 3 * per * gi,
                                   0, 3 * sizeof(float), (size_t)(per * (gend - gi)));
        rtcSetGeometryVertexAttributeCount(g, 1);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX_ATTRIBUTE, 0, RTC_FORMAT_FLOAT3,
                                   N + 3 * per * gi, 0, 3 * sizeof(float), (size_t)(per * (gend - gi)));
        struct RTCGrid *grid = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_GRID, 0, RTC_FORMAT_GRID,
                                                       sizeof(struct RTCGrid), (size_t)(gend - gi));
        for (long k = 0; k < gend - gi; k++) {
            grid[k].startVertexID = (unsigned)(k * per);
            grid[k].stride = (unsigned)(n + 1);
            grid[k].width = (unsigned short)(n + 1);
            grid[k].height = (unsigned short)(n + 1);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(rscene, g, (unsigned)gp[gi].obj);
        rtcReleaseGeometry(g);
        gi = gend;
    }
    rtcCommitScene(rscene);
    double t_build = cpu_now() - t0;
    long long bvh_bytes = mon.bytes;

    /* 3. trace and shade */
    int W = w->camera.xres, H = w->camera.yres;
    float *img = calloc((size_t)W * (size_t)H * 4, sizeof *img);
    if (!img) abort();
    long hits = 0;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    t0 = cpu_now();
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            trace_ray ray;
            trace_camera_ray(&w->camera, x + 0.5, y + 0.5, &ray);
            struct RTCRayHit rh;
            memset(&rh, 0, sizeof rh);
            rh.ray.org_x = (float)ray.o.x, rh.ray.org_y = (float)ray.o.y, rh.ray.org_z = (float)ray.o.z;
            rh.ray.dir_x = (float)ray.d.x, rh.ray.dir_y = (float)ray.d.y, rh.ray.dir_z = (float)ray.d.z;
            rh.ray.tnear = (float)ray.tmin;
            rh.ray.tfar = isfinite(ray.tmax) ? (float)ray.tmax : INFINITY;
            rh.ray.mask = 0xffffffffu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(rscene, &ctx, &rh);
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
            const trace_object *hit_obj = &w->objects[rh.hit.geomID];
            float nf[3];
            rtcInterpolate0(rtcGetGeometry(rscene, rh.hit.geomID), rh.hit.primID, rh.hit.u, rh.hit.v,
                            RTC_BUFFER_TYPE_VERTEX_ATTRIBUTE, 0, nf, 3);
            vec3 nn = v3(nf[0], nf[1], nf[2]);
            double len = sqrt(v3_dot(nn, nn));
            if (!(len > 0)) nn = v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z), len = sqrt(v3_dot(nn, nn));
            nn = v3_scale(nn, 1.0 / len);
            if (v3_dot(nn, ray.d) > 0) nn = v3_neg(nn);     /* faceforward(N, I) */
            double amb[3] = {0, 0, 0}, dif[3] = {0, 0, 0};
            for (int l = 0; l < hit_obj->nlights; l++) {
                const trace_light *lt = &w->lights[hit_obj->lights[l]];
                if (lt->kind == TRACE_LIGHT_AMBIENT) {
                    for (int k = 0; k < 3; k++) amb[k] += lt->color[k];
                } else if (lt->kind == TRACE_LIGHT_DISTANT) {
                    double c = -v3_dot(nn, lt->dir);
                    if (c > 0)
                        for (int k = 0; k < 3; k++) dif[k] += lt->color[k] * c;
                }
            }
            float *p = &img[((size_t)y * (size_t)W + (size_t)x) * 4];
            for (int k = 0; k < 3; k++)
                p[k] = (float)(hit_obj->Os[k] * hit_obj->Cs[k] * (ka * amb[k] + kd * dif[k]) * w->gain);
            p[3] = 1.0f;
            hits++;
        }
    double t_trace = cpu_now() - t0;

    char err[512];
    int rc = 0;
    if (!peers_png_write(out, W, H, img, err, sizeof err)) {
        fprintf(stderr, "peers_embree: %s\n", err);
        rc = 1;
    } else {
        printf("tess_cpu_s %.4f build_cpu_s %.4f trace_cpu_s %.4f vertex_bytes %lld bvh_bytes %lld "
               "bvh_peak_bytes %lld hits %ld\n",
               t_tess, t_build, t_trace, (long long)nv * 2 * 3 * (long long)sizeof(float),
               bvh_bytes, mon.peak, hits);
    }
    rtcReleaseScene(rscene);
    rtcReleaseDevice(dev);
    free(img);
    free(P);
    free(N);
    free(gp);
    free(view);
    trace_thread_destroy(&th);
    job_scene_destroy(&js);
    job_destroy(&jb);
    return rc;
}

/*
 * test_trace_walls.c: wrong images with exit 0 (issue 9, finding 5), as
 * regressions. A wall (Heidrich & Seidel §5) only where the surface really
 * jumps; a leaf that reached the depth cap is a hit only where the surface
 * is on the ray; a vanishing normalize() leaves boxes bounded:
 *   - sin(2 PI mod(s*4, 1)) is continuous across the mod seams: no wall
 *     leaves, no dark seam lines (every hit faces the camera);
 *   - a bricks shader (floor/mod/step, displacement <= 0.01) covers its
 *     polygon and nothing else (it used to cover the whole frame);
 *   - atan(y/x) jumps where x changes sign: hits stay on the object;
 *   - normalize(dPdu) vanishes at a sphere's poles: the root box is finite;
 *   - a raised disc (a nail head) has walls, shaded with the wall's own
 *     normal (radial), not a box face's;
 *   - a step whose two cases' boxes are apart is a proven step
 *     (TRACE_BOX_STEP): its stagnant boxes are not sampled, its walls are
 *     drawn; a flagged but continuous hinge is not one; the same when an
 *     if chooses the sides;
 *   - a step of two planes (TRACE_BOX_PLANES) against its analytic hits:
 *     the top's hits beside the wall are exact, not the wall's.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "fixture.h"
#include "trace/camera.h"
#include "trace/displace.h"
#include "trace/render.h"

static const char *SINMOD_SL =
    "displacement sinmod(float Km = 0.02)\n"
    "{\n"
    "    float h = sin(2 * PI * mod(s * 4, 1)) * sin(2 * PI * mod(t * 4, 1));\n"
    "    P += Km * h * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *BRICKS_SL =
    "displacement bricks(float Km = 0.01, bw = 0.25, bh = 0.1, mortar = 0.02)\n"
    "{\n"
    "    float ss = s / bw, tt = t / bh;\n"
    "    if (mod(tt, 2) >= 1)\n"
    "        ss += 0.5;\n"
    "    ss -= floor(ss);\n"
    "    tt -= floor(tt);\n"
    "    float w = step(mortar / bw, ss) - step(1 - mortar / bw, ss);\n"
    "    float h = step(mortar / bh, tt) - step(1 - mortar / bh, tt);\n"
    "    P += Km * w * h * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *ATAN_SL =
    "displacement atanyx(float Km = 0.03)\n"
    "{\n"
    "    point Pc = transform(\"object\", P);\n"
    "    P += Km * atan(ycomp(Pc) / xcomp(Pc)) * normalize(N);\n"
    "}\n";

/* corpus atan_ratio's idiom: rays of bumps around the axis from
 * atan(y / x), whose jump at x = 0 the cosine's period hides (the surface
 * is continuous there, and singular only at the origin) */
static const char *RAYS_SL =
    "displacement rays(float Km = 0.03, rays = 6)\n"
    "{\n"
    "    point Pc = transform(\"object\", P);\n"
    "    float a = atan(ycomp(Pc) / xcomp(Pc));\n"
    "    P += Km * (0.5 + 0.5 * cos(2 * rays * a)) * normalize(N);\n"
    "    N = calculatenormal(P);\n"
    "}\n";

static const char *POLE_SL =
    "displacement pole(float Km = 0.05)\n"
    "{\n"
    "    P += Km * normalize(dPdu) + Km * 0.5 * normalize(N);\n"
    "}\n";

static const char *HEAD_SL =
    "displacement head(float r0 = 0.3, h = 0.2)\n"
    "{\n"
    "    float r = distance(point(s, t, 0), point(0.5, 0.5, 0));\n"
    "    if (r < r0)\n"
    "        P += h * normalize(N);\n"
    "}\n";

/* a step up by Km across s = 0.5 */
static const char *RAISED_SL =
    "displacement raised(float Km = 0.1)\n"
    "{\n"
    "    P += Km * step(0.5, s) * normalize(N);\n"
    "}\n";

/* a step up by Km across s = 0.3, a seam no cell's side lies on */
static const char *RAISED3_SL =
    "displacement raised3(float Km = 0.1)\n"
    "{\n"
    "    P += Km * step(0.3, s) * normalize(N);\n"
    "}\n";

/* flagged (a step) but continuous: 0 on both sides of s = 0.5 */
static const char *HINGE_SL =
    "displacement hinge(float Km = 0.1)\n"
    "{\n"
    "    P += Km * step(0.5, s) * (s - 0.5) * 10 * normalize(N);\n"
    "}\n";

/* the same step and hinge chosen by an if (session 27: the cases of a
 * stagnant box take undecided branches one side a case) */
static const char *RAISED_IF_SL =
    "displacement raised_if(float Km = 0.1)\n"
    "{\n"
    "    float h = 0;\n"
    "    if (s >= 0.5) h = 1;\n"
    "    P += Km * h * normalize(N);\n"
    "}\n";

static const char *HINGE_IF_SL =
    "displacement hinge_if(float Km = 0.1)\n"
    "{\n"
    "    float h = s > 0.5 ? (s - 0.5) * 10 : 0;\n"
    "    P += Km * h * normalize(N);\n"
    "}\n";

/* a square polygon facing the camera at z = 5, side 2 */
#define FACING_RIB(shader)                                                 \
    "Format 48 48 1\nProjection \"perspective\" \"fov\" [30]\n"            \
    "WorldBegin\nDisplacement \"" shader "\"\n"                            \
    "Polygon \"P\" [-1 -1 5  1 -1 5  1 1 5  -1 1 5]\nWorldEnd\n"

typedef struct scan {
    int inside, inside_hits, outside, outside_hits;
    double min_shade;            /* smallest red of a hit inside (default surface) */
    double zlo, zhi;             /* depths of the hits inside */
    trace_stats st;
} scan;

/* One ray through every pixel centre; inside = the ray meets the
 * undisplaced square at least `margin` (in x, y at z = 5) from its edge. */
static void scan_square(const char *name, const char *src, double margin, scan *out)
{
    fixture f;
    assert_true(fixture_open_named(&f, FACING_RIB("%s"), name, src));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_camera *cam = &f.js->world.camera;
    *out = (scan){0, 0, 0, 0, 1e300, 1e300, -1e300, {0}};
    for (int y = 0; y < cam->yres; y++)
        for (int x = 0; x < cam->xres; x++) {
            trace_ray ray;
            trace_camera_ray(cam, x + 0.5, y + 0.5, &ray);
            vec3 at = trace_ray_at(&ray, 5.0 / ray.d.z);
            double edge = fmin(1 - fabs(at.x), 1 - fabs(at.y));
            double rgb[3], a, z;
            trace_render_sample(f.js->renderer, th, x + 0.5, y + 0.5, rgb, &a, &z);
            bool hit = a > 0;
            if (edge > margin) {
                out->inside++;
                out->inside_hits += hit;
                if (hit) {
                    out->min_shade = fmin(out->min_shade, rgb[0]);
                    out->zlo = fmin(out->zlo, z);
                    out->zhi = fmax(out->zhi, z);
                }
            } else if (edge < -margin) {
                out->outside++;
                out->outside_hits += hit;
            }
        }
    out->st = th->stats;
    printf("%-8s inside %d/%d hit, outside %d/%d hit, min shade %.3f, z [%.4f, %.4f], "
           "walls %ld, depth-cap leaves %ld (rejected %ld), boxes/ray %.2f\n", name,
           out->inside_hits, out->inside, out->outside_hits, out->outside, out->min_shade,
           out->zlo, out->zhi, th->stats.wall_leaves, th->stats.depth_cap_leaves,
           th->stats.rejected_leaves, (double)th->stats.boxes / (double)th->stats.primary_rays);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* The whole frame of the fixture's camera as a render samples it (its
 * pixel samples, one tile), the image dropped: for the thread's stats */
static void render_frame(fixture *f, trace_thread *th)
{
    int w = f->js->world.camera.xres, h = f->js->world.camera.yres;
    float *rgba = calloc((size_t)w * h * 4, sizeof *rgba), *z = calloc((size_t)w * h, sizeof *z);
    assert_true(trace_render_tile(f->js->renderer, th, 0, 0, w, h, rgba, z));
    free(rgba);
    free(z);
}

static void test_sin_of_mod_has_no_seams(void **state)
{
    (void)state;
    scan s;
    scan_square("sinmod", SINMOD_SL, 0.03, &s);
    assert_int_equal(s.st.wall_leaves, 0);
    assert_int_equal(s.inside_hits, s.inside);
    assert_int_equal(s.outside_hits, 0);
    /* the surface tilts by at most atan(0.02 * 2 PI * 4 / 2) = 14 degrees:
     * the default surface's facing ratio stays above 0.9 (a wall's box face
     * would give about 0.2) */
    assert_true(s.min_shade > 0.2 + 0.8 * 0.9);
    assert_true(s.zlo > 5 - 0.02 - 0.01 && s.zhi < 5 + 0.02 + 0.01);

    /* seen at a grazing angle with five times the amplitude (the old rule
     * reported 5,472 wall leaves along the seams here) */
    const char *rib = "Format 96 72 1\nProjection \"perspective\" \"fov\" [40]\n"
                      "Translate 0 -0.2 3\nRotate -50 1 0 0\nWorldBegin\n"
                      "Displacement \"sinmod\" \"float Km\" [0.1]\n"
                      "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\nWorldEnd\n";
    fixture f;
    fixture_shader sh[] = {{"sinmod", SINMOD_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    render_frame(&f, th);
    printf("sinmod grazing: walls %ld, depth-cap leaves %ld, boxes/ray %.2f\n",
           th->stats.wall_leaves, th->stats.depth_cap_leaves,
           (double)th->stats.boxes / (double)th->stats.primary_rays);
    assert_int_equal(th->stats.wall_leaves, 0);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static void test_bricks_cover_their_polygon_only(void **state)
{
    (void)state;
    scan s;
    scan_square("bricks", BRICKS_SL, 0.03, &s);
    assert_int_equal(s.inside_hits, s.inside);
    assert_int_equal(s.outside_hits, 0);
    assert_true(s.zlo > 5 - 0.01 - 0.01 && s.zhi < 5 + 0.01 + 0.01);
}

static void test_atan_jump_stays_on_the_object(void **state)
{
    (void)state;
    scan s;
    scan_square("atanyx", ATAN_SL, 0.06, &s);
    assert_int_equal(s.inside_hits, s.inside);
    assert_int_equal(s.outside_hits, 0);
    double amp = 0.03 * M_PI / 2;
    assert_true(s.zlo > 5 - amp - 0.02 && s.zhi < 5 + amp + 0.02);
}

/* Along x = 0 every box holds the pole of y / x, so none shrinks: the
 * pole flags them discontinuous (as a step would), and the stagnant ones
 * are estimated from their samples, which the continuous surface passes
 * (a sample on the line itself, where the derivative is inf / inf, is
 * taken a hair inside the cell). Before, they were smooth boxes that
 * never shrank, and every ray that crossed the line obliquely walked
 * into the work limit (corpus atan_ratio on the pattern bench's wall:
 * 52 s and 1,480 limited rays at 256x192). The wall, turned 30 degrees,
 * at 128x96: every ray through a pixel centre that meets the undisplaced
 * wall 0.1 inside its border hits, and no ray of the frame is limited. */
static void test_pole_of_a_ratio_is_sampled(void **state)
{
    (void)state;
    const char *rib = "Format 128 96 1\nProjection \"perspective\" \"fov\" [40]\n"
                      "Translate 0 0 3\nRotate -30 0 1 0\nWorldBegin\n"
                      "Displacement \"rays\"\n"
                      "Polygon \"P\" [-1.5 -1 0  1.5 -1 0  1.5 1 0  -1.5 1 0]\nWorldEnd\n";
    fixture f;
    fixture_shader sh[] = {{"rays", RAYS_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_camera *cam = &f.js->world.camera;
    const trace_object *obj = &f.js->world.objects[0];
    int inside = 0, hits = 0;
    for (int y = 0; y < cam->yres; y++)
        for (int x = 0; x < cam->xres; x++) {
            trace_ray ray;
            trace_camera_ray(cam, x + 0.5, y + 0.5, &ray);
            /* the ray in object space against the plane z = 0 */
            vec3 o = mat4_xform_point(&obj->from_camera, ray.o);
            vec3 d = mat4_xform_vector(&obj->from_camera, ray.d);
            double t = -o.z / d.z;
            vec3 at = v3_add(o, v3_scale(d, t));
            double rgb[3], a, z;
            trace_render_sample(f.js->renderer, th, x + 0.5, y + 0.5, rgb, &a, &z);
            if (t > 0 && fabs(at.x) < 1.5 - 0.1 && fabs(at.y) < 1 - 0.1) {
                inside++;
                hits += a > 0;
            }
        }
    /* and the frame as a render samples it (2 x 2 jittered samples a
     * pixel): with the pixel centres, 17 rays reached the work limit
     * before */
    render_frame(&f, th);
    trace_thread_sync_stats(th);
    printf("rays: %d/%d hit, limited rays %ld, samplings %ld (%ld estimated), boxes %ld\n",
           hits, inside, th->stats.limited_rays, th->stats.samplings, th->stats.sampled_boxes,
           th->stats.boxes);
    assert_true(inside > 5000);
    assert_int_equal(hits, inside);
    assert_int_equal(th->stats.limited_rays, 0);
    assert_true(th->stats.sampled_boxes > 0);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

static void test_normalize_at_the_poles_is_bounded(void **state)
{
    (void)state;
    const char *rib = "Format 32 32 1\nProjection \"perspective\" \"fov\" [40]\n"
                      "WorldBegin\nTranslate 0 0 5\nDisplacement \"pole\"\n"
                      "Sphere 1 -1 1 360\nWorldEnd\n";
    fixture f;
    fixture_shader sh[] = {{"pole", POLE_SL}};
    for (int a = 0; a < 2; a++) {
        job_options opt;
        job_options_default(&opt);
        opt.arith = a ? TRACE_ARITH_INTERVAL : TRACE_ARITH_AFFINE;
        assert_true(fixture_open(&f, rib, sh, 1, &opt, 0));
        const trace_box *root = &f.js->world.objects[0].root;
        printf("pole root box (%s): [%g %g %g] - [%g %g %g]\n", trace_arith_name(opt.arith),
               root->lo.x, root->lo.y, root->lo.z, root->hi.x, root->hi.y, root->hi.z);
        assert_false(root->flags & AA_UNBOUNDED);
        assert_true(trace_box_extent(root) < 2 * (1 + 0.05 + 0.025) + 1e-9);
        /* a ray that misses the sphere visits only a few nodes */
        trace_thread *th = trace_thread_new(&f.js->world);
        double rgb[3], al, z;
        trace_render_sample(f.js->renderer, th, 1.5, 1.5, rgb, &al, &z);
        assert_true(al == 0);
        assert_true(th->stats.nodes < 50);
        trace_thread_destroy(&th);
        fixture_close(&f);
    }
}

/* The wall leaves of one ray through every pixel centre of a 64x64 scene
 * (one object): their normals (camera space) handed to fn; how many */
typedef void (*wall_normal_fn)(const trace_object *obj, vec3 n, void *ctx);
static int scan_wall_normals(const char *rib, const char *name, const char *src,
                             wall_normal_fn fn, void *ctx)
{
    fixture f;
    fixture_shader sh[] = {{name, src}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_object *obj = &f.js->world.objects[0];
    int walls = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            trace_ray ray;
            trace_camera_ray(&f.js->world.camera, x + 0.5, y + 0.5, &ray);
            trace_hit hit = {.t = ray.tmax, .obj = NULL};
            if (!trace_bvh_intersect(f.js->renderer->bvh, th, &ray,
                                     &f.js->renderer->primary_tol, false, &hit))
                continue;
            if (hit.kind != TRACE_LEAF_WALL) continue;
            walls++;
            fn(obj, hit.wall_normal, ctx);
        }
    trace_thread_destroy(&th);
    fixture_close(&f);
    return walls;
}

/* perpendicular to the displacement (the polygon's normal) */
static void count_radial(const trace_object *obj, vec3 n, void *ctx)
{
    vec3 up = v3_normalize(mat4_xform_normal(&obj->from_camera, v3(0, 0, 1)));
    *(int *)ctx += fabs(v3_dot(n, up)) < 0.2;
}

/* A disc of radius 0.3 (in s, t) raised by 0.2 on a square seen from the
 * side and above: rays that hit the head's wall are shaded with a normal
 * perpendicular to the displacement (the wall's), so its facing ratio is
 * that of a vertical cylinder, not of the box faces. */
static void test_wall_normals_are_the_walls(void **state)
{
    (void)state;
    const char *rib = "Format 64 64 1\nProjection \"perspective\" \"fov\" [30]\n"
                      "WorldBegin\nTranslate 0 0 5\nRotate -60 1 0 0\n"
                      "Displacement \"head\"\n"
                      "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\nWorldEnd\n";
    int radial = 0;
    int walls = scan_wall_normals(rib, "head", HEAD_SL, count_radial, &radial);
    printf("head: %d wall hits, %d with a normal perpendicular to the displacement\n",
           walls, radial);
    assert_true(walls > 20);
    assert_true(radial >= walls * 9 / 10);
}

/* a square of s, t in [0.3, 0.7] raised by h */
static const char *PLINTH_SL =
    "displacement plinth(float h = 0.2)\n"
    "{\n"
    "    P += h * step(0.3, s) * step(s, 0.7) * step(0.3, t) * step(t, 0.7) * normalize(N);\n"
    "}\n";

/* how far a wall normal is from object x or y: within 10 degrees, the
 * sum of the angles, the largest */
typedef struct square_off {
    int square;
    double sum, worst;
} square_off;

static void off_square(const trace_object *obj, vec3 n, void *ctx)
{
    square_off *q = ctx;
    vec3 o = v3_normalize(mat4_xform_vector(&obj->from_camera, n));
    double along = fmin(fmax(fabs(o.x), fabs(o.y)), 1.0), deg = acos(along) * 180 / M_PI;
    q->square += deg < 10;
    q->sum += deg;
    q->worst = fmax(q->worst, deg);
}

/* The raised square on a square cut into two triangles (a mesh whose
 * faces' (u,v) are skewed against s and t): its walls run along object x
 * and y, and the wall leaves' normals must say so. The step between the
 * sides' sample centroids leans with a skewed sample grid (up to 30
 * degrees before its part along the edge was taken out:
 * refine_wall_normal): 56 of 64 within 10 degrees, 3.9 off on average;
 * 64 of 65 and under a degree now (the triangles also start along st). */
static void test_wall_normals_on_skewed_faces(void **state)
{
    (void)state;
    const char *rib = "Format 64 64 1\nProjection \"perspective\" \"fov\" [30]\n"
                      "WorldBegin\nTranslate 0 0 5\nRotate -60 1 0 0\n"
                      "Displacement \"plinth\"\n"
                      "PointsPolygons [3 3] [0 1 2  0 2 3] \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\n"
                      "  \"st\" [0 0  1 0  1 1  0 1]\nWorldEnd\n";
    square_off q = {0, 0, 0};
    int walls = scan_wall_normals(rib, "plinth", PLINTH_SL, off_square, &q);
    double mean = walls ? q.sum / walls : 0;
    printf("plinth on triangles: %d wall hits, %d with a normal within 10 degrees of the "
           "wall's, %.1f degrees off on average (the worst %.1f)\n", walls, q.square, mean,
           q.worst);
    assert_true(walls > 20);
    assert_true(q.square >= walls * 19 / 20);
    assert_true(mean < 2.0);
}

/* Of a 16 x 16 grid of (u,v) cells, those whose one run is flagged
 * discontinuous, and of them those whose cases mark a proven step */
static void count_step_cells(const char *name, const char *src, int *flagged, int *steps)
{
    fixture f;
    assert_true(fixture_open_named(&f, FACING_RIB("%s"), name, src));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_object *obj = &f.js->world.objects[0];
    *flagged = *steps = 0;
    for (int i = 0; i < 16; i++)
        for (int j = 0; j < 16; j++) {
            double u0 = i / 16.0, u1 = (i + 1) / 16.0, v0 = j / 16.0, v1 = (j + 1) / 16.0;
            trace_box b;
            trace_surface_box(th, obj, u0, u1, v0, v1, &b);
            assert_false(b.flags & TRACE_BOX_STEP);      /* only the cases mark it */
            if (!(b.flags & AA_DISCONTINUOUS)) continue;
            (*flagged)++;
            trace_surface_box_cases(th, obj, u0, u1, v0, v1, &b, NULL, NULL);
            *steps += (b.flags & TRACE_BOX_STEP) != 0;
        }
    printf("%-7s %d of 256 cells flagged discontinuous, %d proven steps\n", name, *flagged,
           *steps);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* A step up by 0.1 is proven (its cases' boxes, at 0 and 0.1, are apart)
 * in the cells across it, which then take no samples anywhere below
 * them: a grazing render samples no stagnant box, and still draws the
 * step's wall and both sides. The hinge, 0 on both sides of its step,
 * is never a proven step: its cases' boxes share the hinge's points. */
static void test_proven_steps_take_no_samples(void **state)
{
    (void)state;
    /* the step and the hinge, and the same chosen by branches (one side
     * a case): the same verdicts */
    const struct {
        const char *name, *src;
        bool step;
    } shapes[] = {
        {"raised", RAISED_SL, true},
        {"hinge", HINGE_SL, false},
        {"raised_if", RAISED_IF_SL, true},
        {"hinge_if", HINGE_IF_SL, false},
    };
    for (size_t k = 0; k < sizeof shapes / sizeof shapes[0]; k++) {
        int flagged, steps;
        count_step_cells(shapes[k].name, shapes[k].src, &flagged, &steps);
        assert_true(flagged > 0);
        assert_int_equal(steps, shapes[k].step ? flagged : 0);
    }

    const char *rib = "Format 96 72 1\nProjection \"perspective\" \"fov\" [40]\n"
                      "Translate 0 -0.2 3\nRotate -50 1 0 0\nRotate 20 0 0 1\nWorldBegin\n"
                      "Displacement \"raised\"\n"
                      "Polygon \"P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]\nWorldEnd\n";
    fixture f;
    fixture_shader sh[] = {{"raised", RAISED_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    /* one ray per pixel centre; the hits' heights above the polygon's
     * plane (along N, +-z in object space): the plane's and the raised
     * plane's */
    const trace_object *obj = &f.js->world.objects[0];
    int low = 0, high = 0, hits = 0;
    for (int y = 0; y < 72; y++)
        for (int x = 0; x < 96; x++) {
            double rgb[3], a, z;
            trace_render_sample(f.js->renderer, th, x + 0.5, y + 0.5, rgb, &a, &z);
            if (!(a > 0)) continue;
            hits++;
            trace_ray ray;
            trace_camera_ray(&f.js->world.camera, x + 0.5, y + 0.5, &ray);
            vec3 o = mat4_xform_point(&obj->from_camera, trace_ray_at(&ray, z / ray.d.z));
            low += fabs(o.z) < 0.005;
            high += fabs(fabs(o.z) - 0.1) < 0.005;
        }
    printf("raised grazing: %d hits, %d on the plane, %d raised; walls %ld, samplings %ld, "
           "boxes/ray %.2f\n", hits, low, high, th->stats.wall_leaves, th->stats.samplings,
           (double)th->stats.boxes / (double)th->stats.primary_rays);
    assert_int_equal(th->stats.samplings, 0);
    assert_int_equal(th->stats.sampled_boxes, 0);
    assert_true(th->stats.wall_leaves > 0);
    assert_true(low > hits / 4 && high > hits / 4);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

/* The diamond |x| + |y| <= sqrt 2 at z = 0, "st" 0 0, 1 0, 1 1, 0 1 at
 * its corners (0, -r), (r, 0), (0, r), (-r, 0): s = (x + y) / (2 r) + 1/2.
 * Its cells' object-space boxes are loose (the cells run diagonally), so
 * rays meet boxes of cells whose surface they pass beside. */
#define DIAMOND_R 1.4142135623730951
static bool in_diamond(double x, double y) { return fabs(x) + fabs(y) <= DIAMOND_R; }

/* The exact first hit (object space t; INFINITY: none) of the ray o + t d
 * with the raised step on the diamond, its edge where s = s0: the plane
 * z = h where s >= s0, z = 0 where s < s0, and the wall between them;
 * *kind 0 the low plane, 1 the raised one, 2 the wall */
static double step_hit(vec3 o, vec3 d, double h, double s0, int *kind)
{
    double best = INFINITY;
    *kind = -1;
    /* g(x, y) = s - s0, affine */
    double gx = 1 / (2 * DIAMOND_R), gy = gx, g0 = 0.5 - s0;
    if (d.z != 0) {
        double tz[2] = {(0 - o.z) / d.z, (h - o.z) / d.z};
        for (int k = 0; k < 2; k++) {
            double x = o.x + tz[k] * d.x, y = o.y + tz[k] * d.y, g = g0 + gx * x + gy * y;
            bool side = k == 1 ? g >= 0 : g < 0;
            if (tz[k] > 0 && side && in_diamond(x, y) && tz[k] < best) {
                best = tz[k];
                *kind = k;
            }
        }
    }
    double gd = gx * d.x + gy * d.y;
    if (gd != 0) {
        double tw = -(g0 + gx * o.x + gy * o.y) / gd;
        double x = o.x + tw * d.x, y = o.y + tw * d.y, z = o.z + tw * d.z;
        if (tw > 0 && in_diamond(x, y) && z >= fmin(0, h) && z <= fmax(0, h) && tw < best) {
            best = tw;
            *kind = 2;
        }
    }
    return best;
}

/* The raised step (at s = 0.3) on the diamond seen at a slant, one ray per
 * pixel centre, against its exact hits (step_hit): every hit that claims
 * to be exact (TRACE_LEAF_PROVEN: proofs, undisplaced and moved cells,
 * and the cells of two planes, planes_cell) is at the exact hit's t (to
 * 1e-6 of it: a hit proof's Newton point is a few 1e-9 off), and so is
 * every hit whose exact hit is on a plane away from the border and the
 * wall; every ray whose exact hit is on the wall hits (a wall leaf, at its
 * box's entry). The cells of two planes settle rays by the first plane
 * they cross, where the surface there is that plane (without that check
 * the raised plane is drawn over the low one, as exact hits), or as
 * misses where the rays' stretch between the planes passes beside them. */
static void test_planes_hit_exactly_beside_the_wall(void **state)
{
    (void)state;
    const char *rib = "Format 96 72 1\nProjection \"perspective\" \"fov\" [40]\n"
                      "Translate 0 -0.2 3\nRotate -50 1 0 0\nRotate 20 0 0 1\nWorldBegin\n"
                      "Displacement \"raised3\"\n"
                      "Polygon \"P\" [0 -1.4142135623730951 0  1.4142135623730951 0 0  "
                      "0 1.4142135623730951 0  -1.4142135623730951 0 0] "
                      "\"st\" [0 0  1 0  1 1  0 1]\nWorldEnd\n";
    fixture f;
    fixture_shader sh[] = {{"raised3", RAISED3_SL}};
    assert_true(fixture_open(&f, rib, sh, 1, NULL, 0));
    trace_thread *th = trace_thread_new(&f.js->world);
    const trace_object *obj = &f.js->world.objects[0];
    /* the side N points to (the raised plane's z): the step's height, at
     * the point (0.5, 0.5) of the diamond (s = 0.75) */
    double h = NAN;
    for (int k = 0; k < 64 && isnan(h); k++) {
        double u = (k % 8 + 0.5) / 8, v = (k / 8 + 0.5) / 8;
        trace_surface_point sp;
        trace_surface_point_eval(th, obj, u, v, &sp);
        vec3 q = mat4_xform_point(&obj->from_camera, sp.P);
        geom_sample g;
        geom_eval(&obj->surf, u, v, &g);
        if (in_diamond(g.P.x, g.P.y) && (g.P.x + g.P.y) / (2 * DIAMOND_R) + 0.5 > 0.5) h = q.z;
    }
    assert_true(fabs(fabs(h) - 0.1) < 1e-12);
    int proven = 0, proven_ok = 0, beside = 0, planes = 0, planes_ok = 0, walls = 0,
        walls_hit = 0;
    for (int y = 0; y < 72; y++)
        for (int x = 0; x < 96; x++) {
            trace_ray ray;
            trace_camera_ray(&f.js->world.camera, x + 0.5, y + 0.5, &ray);
            /* object space: the same t */
            vec3 o = mat4_xform_point(&obj->from_camera, ray.o),
                 d = mat4_xform_vector(&obj->from_camera, ray.d);
            int kind;
            double te = step_hit(o, d, h, 0.3, &kind);
            trace_hit hit = {.t = ray.tmax, .obj = NULL};
            bool found = trace_bvh_intersect(f.js->renderer->bvh, th, &ray,
                                             &f.js->renderer->primary_tol, false, &hit);
            bool exact = found && fabs(hit.t - te) <= 1e-6 * te;
            vec3 p = v3_add(o, v3_scale(d, te));
            /* distances from the border and from the wall, object units */
            double border = DIAMOND_R - fabs(p.x) - fabs(p.y),
                   wall = fabs((p.x + p.y) / (2 * DIAMOND_R) + 0.5 - 0.3) * 2 * DIAMOND_R;
            if (found && hit.kind == TRACE_LEAF_PROVEN) {
                proven++;
                proven_ok += exact;
                beside += kind >= 0 && kind < 2 && wall < 0.05;
            }
            if (kind == 2) {
                walls++;
                walls_hit += found;
            } else if (kind >= 0 && border > 0.05 && wall > 0.05) {
                planes++;
                planes_ok += exact;
            }
        }
    printf("planes: %d/%d exact hits at the exact t (%d within 0.05 of the wall), %d/%d "
           "plane hits exact, %d/%d wall rays hit; plane cells %ld (hits %ld, misses %ld)\n",
           proven_ok, proven, beside, planes_ok, planes, walls_hit, walls, th->stats.plane_cells,
           th->stats.plane_hits, th->stats.plane_misses);
    assert_true(proven > 1000);
    assert_int_equal(proven_ok, proven);
    assert_true(beside > 20);
    assert_true(planes > 1000);
    assert_int_equal(planes_ok, planes);
    assert_true(walls > 20);
    assert_int_equal(walls_hit, walls);
    assert_true(th->stats.plane_hits > 0 && th->stats.plane_misses > 0);
    trace_thread_destroy(&th);
    fixture_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sin_of_mod_has_no_seams),
        cmocka_unit_test(test_bricks_cover_their_polygon_only),
        cmocka_unit_test(test_atan_jump_stays_on_the_object),
        cmocka_unit_test(test_pole_of_a_ratio_is_sampled),
        cmocka_unit_test(test_normalize_at_the_poles_is_bounded),
        cmocka_unit_test(test_wall_normals_are_the_walls),
        cmocka_unit_test(test_wall_normals_on_skewed_faces),
        cmocka_unit_test(test_proven_steps_take_no_samples),
        cmocka_unit_test(test_planes_hit_exactly_beside_the_wall),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

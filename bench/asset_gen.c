/*
 * bench/asset_gen.c: writes a production-style scene (issue 23): a
 * displaced, textured terrain of N faces and rocks instanced K times, each
 * rock a Catmull-Clark cage, their geometry in gzip-compressed archives
 * that the top-level RIB reads, in the idioms exporters write (ReadArchive
 * of .rib.gz files, ObjectBegin/ObjectInstance, facevarying "st",
 * "displacementbound", the shaders and texture on search paths).
 *
 *   asset_gen [--faces N] [--rocks K] [--rock-kinds R] [--cage M] [--format W H]
 *             [--shaders DIR] [--textures DIR] OUTDIR
 *   asset_gen --instances K [--faces N] [--format W H] OUTDIR
 *
 * writes OUTDIR/asset.rib, OUTDIR/terrain.rib.gz (a PointsPolygons grid of
 * about N quads: heights from a few sine octaves, "st" per point) and
 * OUTDIR/rock.rib.gz (a cube cage of 6 M^2 faces, creased corners). The
 * terrain is displaced by heightmap.sl with textures/terrain_height.exr
 * (scenes/make_textures.sh writes it), the rocks by dented.sl. Defaults:
 * 1,000,000 faces, 200 rocks, M = 6, 640 x 480, the source tree's scenes/
 * shaders and textures.
 *
 * --rock-kinds R (R >= 1) writes the rocks as a scatter is usually made:
 * R recorded rocks of different sizes (the scale inside each definition),
 * each rock a placement of one of them moved and turned about the up
 * axis (no scale), all under one Displacement "rockdents" call (dented's
 * dents in "object" space, Km 0.02), the placements in OUTDIR/
 * scatter.rib.gz: each placement is then its rock
 * moved rigidly, which the renderer draws as a reference to it
 * (docs/renderer.md "Instances as references"). Without it each rock has
 * its own Displacement "dented" call (Km 0.25, in the space of the call)
 * and its own scale: 200 meshes of their own.
 *
 * --instances K writes instances.rib and instances_body.rib.gz instead:
 * one undisplaced PointsPolygons grid of about N bent quads (default
 * 1000), recorded once and placed K times on a square grid seen from
 * above, each with its own colour, turn and tilt (the aim of issue 23:
 * 1,000,000 instances of a 1000-face object at 256 x 256).
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

static void die(const char *what, const char *path)
{
    fprintf(stderr, "asset_gen: %s %s\n", what, path);
    exit(1);
}

static double height(double x, double y)
{
    return 0.25 * sin(1.3 * x + 0.4) * cos(1.1 * y) + 0.08 * sin(4.1 * x + 2.1 * y) +
           0.03 * cos(9.7 * x - 7.3 * y);
}

static void write_terrain(const char *path, int n)
{
    gzFile f = gzopen(path, "wb6");
    if (!f) die("cannot write", path);
    const double size = 8.0;
    gzprintf(f, "##RenderMan RIB-Structure 1.1 Entity\n# terrain: %d x %d quads\n"
                "PointsPolygons [", n, n);
    for (int i = 0; i < n * n; i++) gzputs(f, i % 32 == 31 ? "4\n" : "4 ");
    gzputs(f, "]\n[");
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int a = j * (n + 1) + i;
            gzprintf(f, "%d %d %d %d%s", a, a + n + 1, a + n + 2, a + 1, i % 8 == 7 ? "\n" : " ");
        }
    gzputs(f, "]\n\"P\" [");
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            double x = size * (i / (double)n - 0.5), y = size * (j / (double)n - 0.5);
            gzprintf(f, "%.6g %.6g %.6g%s", x, y, height(x, y), i % 4 == 3 ? "\n" : " ");
        }
    gzputs(f, "]\n\"float[2] st\" [");
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++)
            gzprintf(f, "%.6g %.6g%s", i / (double)n, j / (double)n, i % 8 == 7 ? "\n" : " ");
    gzputs(f, "]\n");
    if (gzclose(f) != Z_OK) die("cannot finish", path);
}

/* a cube cage of 6 m^2 quads (points shared along the edges) */
static void write_rock(const char *path, int m)
{
    gzFile f = gzopen(path, "wb6");
    if (!f) die("cannot write", path);
    /* the points of the cube's surface grid, by their integer coordinates */
    int side = m + 1, npts = 0;
    int *id = malloc(sizeof *id * (size_t)side * side * side);
    if (!id) abort();
    double *P = malloc(sizeof *P * 3 * (size_t)side * side * side);
    if (!P) abort();
    for (int z = 0; z < side; z++)
        for (int y = 0; y < side; y++)
            for (int x = 0; x < side; x++) {
                int k = (z * side + y) * side + x;
                bool surface = x == 0 || y == 0 || z == 0 || x == m || y == m || z == m;
                id[k] = surface ? npts : -1;
                if (!surface) continue;
                P[3 * npts] = 2.0 * x / m - 1;
                P[3 * npts + 1] = 2.0 * y / m - 1;
                P[3 * npts + 2] = 2.0 * z / m - 1;
                npts++;
            }
    gzprintf(f, "##RenderMan RIB-Structure 1.1 Entity\n# rock: a cube cage of %d faces\n"
                "SubdivisionMesh \"catmull-clark\" [", 6 * m * m);
    for (int i = 0; i < 6 * m * m; i++) gzputs(f, "4 ");
    gzputs(f, "]\n[");
    /* each face of the cube: axis a fixed at 0 or m, the other two (b, c)
     * running; the winding outward */
    for (int a = 0; a < 3; a++)
        for (int s = 0; s < 2; s++)
            for (int i = 0; i < m; i++)
                for (int j = 0; j < m; j++) {
                    int q[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
                    int out[4];
                    for (int c = 0; c < 4; c++) {
                        int v[3];
                        v[a] = s ? m : 0;
                        v[(a + 1) % 3] = q[c][0];
                        v[(a + 2) % 3] = q[c][1];
                        out[c] = id[(v[2] * side + v[1]) * side + v[0]];
                    }
                    if (s)
                        gzprintf(f, "%d %d %d %d ", out[0], out[1], out[2], out[3]);
                    else
                        gzprintf(f, "%d %d %d %d ", out[0], out[3], out[2], out[1]);
                }
    gzputs(f, "]\n[\"interpolateboundary\"] [0 0] [] []\n\"P\" [");
    for (int i = 0; i < npts; i++) gzprintf(f, "%.6g %.6g %.6g\n", P[3 * i], P[3 * i + 1], P[3 * i + 2]);
    gzputs(f, "]\n");
    free(id);
    free(P);
    if (gzclose(f) != Z_OK) die("cannot finish", path);
}

static void write_instances(const char *out, long instances, long faces, int w, int h)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/instances_body.rib.gz", out);
    gzFile f = gzopen(path, "wb6");
    if (!f) die("cannot write", path);
    int gx = (int)ceil(sqrt((double)faces * 1.6)), gy = (int)ceil((double)faces / gx);
    gzprintf(f, "# a %d x %d grid of bent quads, recorded once, placed %ld times\n"
                "ObjectBegin \"tile\"\nPointsPolygons [", gx, gy, instances);
    for (long i = 0; i < (long)gx * gy; i++) gzputs(f, i % 32 == 31 ? "4\n" : "4 ");
    gzputs(f, "]\n[");
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            int a = j * (gx + 1) + i;
            gzprintf(f, "%d %d %d %d%s", a, a + 1, a + gx + 2, a + gx + 1, i % 8 == 7 ? "\n" : " ");
        }
    gzputs(f, "]\n\"P\" [");
    for (int j = 0; j <= gy; j++)
        for (int i = 0; i <= gx; i++)
            gzprintf(f, "%.5g %.5g %.5g\n", 0.8 * i / gx - 0.4, 0.8 * j / gy - 0.4,
                     0.05 * sin(7.0 * i / gx) * cos(5.0 * j / gy));
    gzputs(f, "]\nObjectEnd\n");
    int side = (int)ceil(sqrt((double)instances));
    for (long k = 0; k < instances; k++)
        gzprintf(f, "AttributeBegin Color [%.2f %.2f %.2f] Translate %g %g 0 Rotate %ld 0 0 1 "
                    "Rotate %ld 1 0 0 ObjectInstance \"tile\" AttributeEnd\n",
                 0.4 + 0.6 * (k % 7) / 6.0, 0.4 + 0.6 * (k % 5) / 4.0, 0.4 + 0.6 * (k % 3) / 2.0,
                 (k % side) - 0.5 * (side - 1), (k / side) - 0.5 * (side - 1), (k * 37) % 360,
                 (k * 11) % 40);
    if (gzclose(f) != Z_OK) die("cannot finish", path);
    snprintf(path, sizeof path, "%s/instances.rib", out);
    FILE *r = fopen(path, "w");
    if (!r) die("cannot write", path);
    fprintf(r, "##RenderMan RIB\n# instances.rib (bench/asset_gen --instances): %ld instances of "
               "a %d-face object\nversion 3.04\nDisplay \"instances.exr\" \"file\" \"rgba\"\n"
               "Format %d %d 1\nPixelSamples 1 1\nProjection \"perspective\" \"fov\" [40]\n"
               "Translate 0 0 %g\nWorldBegin\n"
               "  LightSource \"distantlight\" 1 \"from\" [0 0 -1] \"to\" [0 0 0]\n"
               "  Surface \"plastic\"\n  ReadArchive \"instances_body.rib.gz\"\nWorldEnd\n",
            instances, gx * gy, w, h, 1.4 * side + 1.0);
    if (fclose(r) != 0) die("cannot finish", path);
}

/* A rock's place on the terrain (x, y in [-3.5, 3.5)) from the seed,
 * which is then stepped once more for the caller's size and turn */
static void rock_spot(unsigned *seed, double *x, double *y)
{
    *seed = *seed * 1103515245u + 12345u;
    *x = 7.0 * ((*seed >> 8) / 16777216.0 - 0.5);
    *seed = *seed * 1103515245u + 12345u;
    *y = 7.0 * ((*seed >> 8) / 16777216.0 - 0.5);
    *seed = *seed * 1103515245u + 12345u;
}

/* the rocks, each with its own Displacement call and scale (the default) */
static void write_rocks(FILE *f, int rocks)
{
    unsigned seed = 7;
    for (int i = 0; i < rocks; i++) {
        double x, y;
        rock_spot(&seed, &x, &y);
        double s = 0.06 + 0.12 * ((seed >> 8) / 16777216.0), a = 360.0 * ((seed >> 4) % 4096) / 4096;
        fprintf(f, "  AttributeBegin\n    Color [0.45 0.43 0.4]\n    Surface \"plastic\" \"Ks\" "
                   "[0.2]\n    Displacement \"dented\" \"Km\" [0.25]\n"
                   "    Rotate -90 1 0 0\n    Translate %.4f %.4f %.4f\n    Rotate %.1f 0 0 1\n"
                   "    Scale %.4f %.4f %.4f\n    ObjectInstance \"rock\"\n  AttributeEnd\n",
                x, y, height(x, y) + 0.6 * s, a, s, s, 0.7 * s);
    }
}

/* --rock-kinds: `kinds` recorded rocks of sizes 0.06 .. 0.18, each
 * placement one of them moved and turned about the up axis, all under one
 * Displacement call in "object" space; the placements in the gzip archive
 * `path` (a large scatter's text stays out of the scene file) */
static void write_scatter(FILE *f, const char *path, const char *name, int rocks, int kinds)
{
    for (int k = 0; k < kinds; k++) {
        double s = 0.06 + 0.12 * (kinds > 1 ? (double)k / (kinds - 1) : 0.5);
        fprintf(f, "  ObjectBegin \"rock%d\"\n    Scale %.4f %.4f %.4f\n"
                   "    ReadArchive \"rock.rib.gz\"\n  ObjectEnd\n", k, s, s, 0.7 * s);
    }
    fprintf(f, "  AttributeBegin\n    Color [0.45 0.43 0.4]\n    Surface \"plastic\" \"Ks\" [0.2]\n"
               "    Displacement \"rockdents\" \"Km\" [0.02]\n    ReadArchive \"%s\"\n"
               "  AttributeEnd\n", name);
    gzFile g = gzopen(path, "wb6");
    if (!g) die("cannot write", path);
    gzprintf(g, "##RenderMan RIB-Structure 1.1 Entity\n# scatter: %d rocks of %d kinds\n", rocks,
             kinds);
    unsigned seed = 7;
    for (int i = 0; i < rocks; i++) {
        double x, y;
        rock_spot(&seed, &x, &y);
        int k = (int)((seed >> 8) % (unsigned)kinds);
        double s = 0.06 + 0.12 * (kinds > 1 ? (double)k / (kinds - 1) : 0.5);
        double a = 360.0 * ((seed >> 4) % 4096) / 4096;
        gzprintf(g, "AttributeBegin Rotate -90 1 0 0 Translate %.4f %.4f %.4f Rotate %.1f 0 0 1 "
                    "ObjectInstance \"rock%d\" AttributeEnd\n",
                 x, y, height(x, y) + 0.6 * s, a, k);
    }
    if (gzclose(g) != Z_OK) die("cannot finish", path);
}

int main(int argc, char **argv)
{
    long faces = 1000000;
    int rocks = 200, cage = 6, w = 640, h = 480, kinds = 0;
    const char *shaders = AAFARM_SCENES_DIR "/shaders", *textures = AAFARM_SCENES_DIR "/textures";
    const char *out = NULL;
    long instances = 0;
    bool faces_given = false;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--faces") == 0 && i + 1 < argc) {
            faces = atol(argv[++i]);
            faces_given = true;
        } else if (strcmp(argv[i], "--instances") == 0 && i + 1 < argc) instances = atol(argv[++i]);
        else if (strcmp(argv[i], "--rocks") == 0 && i + 1 < argc) rocks = atoi(argv[++i]);
        else if (strcmp(argv[i], "--rock-kinds") == 0 && i + 1 < argc) kinds = atoi(argv[++i]);
        else if (strcmp(argv[i], "--cage") == 0 && i + 1 < argc) cage = atoi(argv[++i]);
        else if (strcmp(argv[i], "--format") == 0 && i + 2 < argc) {
            w = atoi(argv[++i]);
            h = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--shaders") == 0 && i + 1 < argc) shaders = argv[++i];
        else if (strcmp(argv[i], "--textures") == 0 && i + 1 < argc) textures = argv[++i];
        else if (strcmp(argv[i], "--help") == 0) {
            printf("usage: asset_gen [--faces N] [--rocks K] [--rock-kinds R] [--cage M] "
                   "[--format W H] [--shaders DIR] [--textures DIR] OUTDIR\n"
                   "       asset_gen --instances K [--faces N] [--format W H] OUTDIR\n");
            return 0;
        } else if (argv[i][0] != '-' && !out) out = argv[i];
        else {
            fprintf(stderr, "asset_gen: unknown option '%s' (see --help)\n", argv[i]);
            return 2;
        }
    }
    if (!out || faces < 1 || rocks < 0 || kinds < 0 || cage < 1 || w < 1 || h < 1) {
        fprintf(stderr, "asset_gen: give OUTDIR (and positive sizes; see --help)\n");
        return 2;
    }
    mkdir(out, 0777);
    if (instances > 0) {
        write_instances(out, instances, faces_given ? faces : 1000, w, h);
        return 0;
    }
    int n = (int)ceil(sqrt((double)faces));
    char path[4096];
    snprintf(path, sizeof path, "%s/terrain.rib.gz", out);
    write_terrain(path, n);
    snprintf(path, sizeof path, "%s/rock.rib.gz", out);
    write_rock(path, cage);
    snprintf(path, sizeof path, "%s/asset.rib", out);
    FILE *f = fopen(path, "w");
    if (!f) die("cannot write", path);
    fprintf(f, "##RenderMan RIB\n# asset.rib (bench/asset_gen): a displaced, textured terrain of "
               "%d quads and %d instanced subdivision rocks\nversion 3.04\n"
               "Option \"searchpath\" \"shader\" [\"%s:&\"]\n"
               "Option \"searchpath\" \"texture\" [\"%s:&\"]\n"
               "Display \"asset.exr\" \"file\" \"rgba\"\nFormat %d %d 1\nPixelSamples 2 2\n"
               "ShadingRate 1\nProjection \"perspective\" \"fov\" [40]\nClipping 0.1 100\n"
               "Translate 0 -0.4 7\nRotate -35 1 0 0\n"
               "WorldBegin\n"
               "  LightSource \"ambientlight\" 1 \"intensity\" [0.2]\n"
               "  LightSource \"distantlight\" 2 \"intensity\" [1.0] \"from\" [-2 3 -1] \"to\" [0 0 0]\n"
               "  AttributeBegin\n    Attribute \"identifier\" \"name\" [\"terrain\"]\n"
               "    Attribute \"displacementbound\" \"sphere\" [0.2]\n    Color [0.55 0.5 0.4]\n"
               "    Surface \"plastic\" \"Ks\" [0.1] \"roughness\" [0.3]\n"
               "    Displacement \"heightmap\" \"Km\" [0.15] \"string mapname\" "
               "[\"terrain_height.exr\"]\n"
               "    Rotate -90 1 0 0\n    ReadArchive \"terrain.rib.gz\"\n  AttributeEnd\n",
            n * n, rocks, shaders, textures, w, h);
    if (kinds > 0) {
        snprintf(path, sizeof path, "%s/scatter.rib.gz", out);
        write_scatter(f, path, "scatter.rib.gz", rocks, kinds);
    } else {
        fprintf(f, "  ObjectBegin \"rock\"\n    ReadArchive \"rock.rib.gz\"\n  ObjectEnd\n");
        write_rocks(f, rocks);
    }
    fprintf(f, "WorldEnd\n");
    if (fclose(f) != 0) die("cannot finish", path);
    printf("asset_gen: %s/asset.rib: %d terrain quads, %d rocks of %d cage faces\n", out, n * n,
           rocks, 6 * cage * cage);
    return 0;
}

/*
 * geom_fixtures.c: fixtures and the long double oracle of the geom tests
 * (see geom_fixtures.h).
 */
#include "geom_fixtures.h"
#include "geom/subdiv.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* ---------------------------------------------------------------------- */
/* random numbers                                                          */
/* ---------------------------------------------------------------------- */

static uint64_t g_state = 0x6e0fa5eedULL;

/* AAFARM_PROPERTY_SEED (tests/CMakeLists.txt) varies every stream */
void fx_seed(uint64_t seed)
{
    const char *env = getenv("AAFARM_PROPERTY_SEED");
    g_state = seed ^ (env ? strtoull(env, NULL, 0) * 0x9e3779b97f4a7c15ULL : 0);
}

static uint64_t next(void)
{
    uint64_t z = (g_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

double fx_unit(void)
{
    return (double)(next() >> 11) * 0x1p-53;
}

double fx_range(double lo, double hi)
{
    return lo + (hi - lo) * fx_unit();
}

vec3 fx_unit_vector(void)
{
    for (;;) {
        vec3 p = v3(fx_range(-1, 1), fx_range(-1, 1), fx_range(-1, 1));
        double l = v3_length(p);
        if (l > 0.1 && l <= 1)
            return v3_scale(p, 1 / l);
    }
}

/* ---------------------------------------------------------------------- */
/* fixtures                                                                */
/* ---------------------------------------------------------------------- */

#define PI 3.14159265358979323846

geom_surface fx_default(geom_kind kind)
{
    geom_surface s = { 0 };
    s.kind = kind;
    s.thetamax = 2 * PI;
    switch (kind) {
    case GEOM_SPHERE:
    case GEOM_CYLINDER:
        s.radius = 1; s.zmin = -1; s.zmax = 1;
        break;
    case GEOM_DISK:
        s.height = 0; s.radius = 1;
        break;
    case GEOM_CONE:
        s.height = 1; s.radius = 1;
        break;
    case GEOM_PARABOLOID:
        s.rmax = 1; s.zmin = 0; s.zmax = 1;
        break;
    case GEOM_HYPERBOLOID:
        s.point1 = v3(1, 0, -1); s.point2 = v3(0, 1, 1);
        break;
    case GEOM_TORUS:
        s.majorrad = 1; s.minorrad = 0.25; s.phimin = 0; s.phimax = 2 * PI;
        break;
    case GEOM_POLYGON:
        s.nverts = 4;
        s.verts[0] = v3(0, 0, 0); s.verts[1] = v3(1, 0, 0);
        s.verts[2] = v3(1, 1, 0); s.verts[3] = v3(0, 1, 0);
        break;
    case GEOM_PATCH:
        s.nverts = 4;
        s.verts[0] = v3(0, 0, 0); s.verts[1] = v3(1, 0, 0);
        s.verts[2] = v3(0, 1, 0); s.verts[3] = v3(1, 1, 0);
        break;
    case GEOM_BICUBIC:                            /* the flat unit square */
        s.nverts = 16;
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++)
                s.verts[4 * j + i] = v3(i / 3.0, j / 3.0, 0);
        break;
    default:
        break;
    }
    return s;
}

enum { MAX_FX = 40 };
static fx_surface g_fx[MAX_FX];
static int g_nfx;

static geom_surface *add(const char *name, geom_kind kind, double size)
{
    fx_surface *f = &g_fx[g_nfx++];
    f->name = name;
    f->s = fx_default(kind);
    f->size = size;
    return &f->s;
}

static void regular_polygon(geom_surface *s, int n, vec3 c, vec3 e1, vec3 e2, double r)
{
    s->nverts = n;
    for (int i = 0; i < n; i++) {
        double a = 2 * PI * i / n;
        s->verts[i] = v3_add(c, v3_add(v3_scale(e1, r * cos(a)), v3_scale(e2, r * sin(a))));
    }
}

static void build(void)
{
    geom_surface *s;
    add("sphere", GEOM_SPHERE, 1);
    s = add("sphere partial", GEOM_SPHERE, 2);
    s->radius = 2; s->zmin = -0.5; s->zmax = 1.5; s->thetamax = 1.5 * PI;
    s = add("sphere negative sweep", GEOM_SPHERE, 1);
    s->zmin = -2; s->zmax = 0.3; s->thetamax = -0.8 * PI;
    /* RI spec §5.2: the ends in either order (zmin > zmax, phimin > phimax:
     * v runs the other way, the surface inside out) */
    s = add("sphere reversed z", GEOM_SPHERE, 1.5);
    s->radius = 1.5; s->zmin = 1.2; s->zmax = -0.4; s->thetamax = 1.1 * PI;
    s = add("cylinder reversed z", GEOM_CYLINDER, 2);
    s->radius = 0.7; s->zmin = 1.5; s->zmax = -0.5; s->thetamax = -1.4 * PI;
    s = add("paraboloid reversed z", GEOM_PARABOLOID, 1.5);
    s->rmax = 0.6; s->zmin = 1.2; s->zmax = 0.4; s->thetamax = 1.7 * PI;
    s = add("torus reversed phi", GEOM_TORUS, 2);
    s->majorrad = 1.2; s->minorrad = 0.4; s->phimin = PI; s->phimax = -PI / 3;
    s->thetamax = 0.9 * PI;
    add("disk", GEOM_DISK, 1);
    s = add("disk partial", GEOM_DISK, 2);
    s->height = -1; s->radius = 2; s->thetamax = 0.75 * PI;
    add("cylinder", GEOM_CYLINDER, 1);
    s = add("cylinder partial", GEOM_CYLINDER, 2);
    s->radius = 0.5; s->zmin = 0; s->zmax = 2; s->thetamax = 0.5 * PI;
    add("cone", GEOM_CONE, 1);
    s = add("cone partial", GEOM_CONE, 1.5);
    s->height = 1.5; s->radius = 0.7; s->thetamax = 1.2 * PI;
    add("paraboloid", GEOM_PARABOLOID, 1);
    s = add("paraboloid partial", GEOM_PARABOLOID, 1);
    s->rmax = 0.5; s->zmin = 0.3; s->zmax = 1; s->thetamax = 1.3 * PI;
    add("hyperboloid", GEOM_HYPERBOLOID, 1.5);
    s = add("hyperboloid partial", GEOM_HYPERBOLOID, 1.2);
    s->point1 = v3(0.5, 0.2, 0); s->point2 = v3(1, -0.3, 0.8); s->thetamax = 1.5 * PI;
    s = add("hyperboloid flat", GEOM_HYPERBOLOID, 1.2);
    s->point1 = v3(0.5, 0, 0.2); s->point2 = v3(1, 0.5, 0.2);
    add("torus", GEOM_TORUS, 1.25);
    s = add("torus partial", GEOM_TORUS, 2);
    s->majorrad = 1.5; s->minorrad = 0.5; s->phimin = -PI / 2; s->phimax = PI;
    s->thetamax = 1.2 * PI;
    s = add("triangle", GEOM_POLYGON, 2);
    s->nverts = 3;
    s->verts[0] = v3(0.2, -0.3, 0.1); s->verts[1] = v3(1.5, 0.4, -0.6);
    s->verts[2] = v3(-0.4, 1.1, 0.9);
    s = add("hexagon", GEOM_POLYGON, 2);
    regular_polygon(s, 6, v3(0.3, -0.2, 0.5), v3_normalize(v3(1, 1, 0)),
                    v3_normalize(v3(-1, 1, 1)), 1);
    s = add("quad with repeats", GEOM_POLYGON, 2);
    s->nverts = 6;
    s->verts[0] = v3(0, 0, 1); s->verts[1] = v3(2, 0, 1); s->verts[2] = v3(2, 0, 1);
    s->verts[3] = v3(2, 1, 1); s->verts[4] = v3(0.5, 1, 1); s->verts[5] = v3(0, 0, 1);
    s = add("patch saddle", GEOM_PATCH, 1.5);
    s->verts[0] = v3(0, 0, 0); s->verts[1] = v3(1, 0, 0.5);
    s->verts[2] = v3(0, 1, 0.2); s->verts[3] = v3(1, 1, -0.4);
    add("patch flat", GEOM_PATCH, 1.5);
    s = add("patch skew", GEOM_PATCH, 3);
    s->verts[0] = v3(-1, 0.2, 0.3); s->verts[1] = v3(1.2, -0.3, 0);
    s->verts[2] = v3(-0.6, 1.4, 1.1); s->verts[3] = v3(1.7, 2, -0.8);
    /* bicubic Bezier patches: a wavy sheet, a dome, a twisted strip */
    static const double wave[16] = { 0, 0.4, -0.3, 0.1,  0.5, -0.6, 0.8, 0.2,
                                     -0.4, 0.9, -0.7, 0.3,  0.2, -0.1, 0.6, -0.5 };
    s = add("bicubic wavy", GEOM_BICUBIC, 2);
    for (int k = 0; k < 16; k++)
        s->verts[k] = v3((k % 4) * 0.6 - 0.9, (k / 4) * 0.6 - 0.9, wave[k]);
    s = add("bicubic dome", GEOM_BICUBIC, 2);
    for (int k = 0; k < 16; k++) {
        double x = (k % 4) / 1.5 - 1, y = (k / 4) / 1.5 - 1;
        s->verts[k] = v3(x, y, 1.2 - 0.6 * (x * x + y * y));
    }
    s = add("bicubic twisted", GEOM_BICUBIC, 3);
    for (int k = 0; k < 16; k++) {
        double a = (k / 4) * 0.5, r = (k % 4) * 0.7 - 1.05;
        s->verts[k] = v3(r * cos(a), r * sin(a), (k / 4) * 0.8 + 0.1 * (k % 3));
    }
}

int fx_surfaces(fx_surface **out)
{
    if (g_nfx == 0) {
        build();
        for (int i = 0; i < g_nfx; i++) {
            char why[200];
            if (!geom_surface_prepare(&g_fx[i].s, why, sizeof why)) {
                fprintf(stderr, "fixture %s: %s\n", g_fx[i].name, why);
                abort();
            }
        }
    }
    *out = g_fx;
    return g_nfx;
}

/* ---------------------------------------------------------------------- */
/* the oracle: RI spec §5.2 formulas and their derivatives, long double    */
/* ---------------------------------------------------------------------- */

typedef long double ld;

static void set3(ld *a, ld x, ld y, ld z)
{
    a[0] = x;
    a[1] = y;
    a[2] = z;
}

static void oracle_sphere(const geom_surface *s, ld th, ld c, ld sn, ld v, fx_exact *o)
{
    ld r = s->radius, dphi = (ld)s->phi1 - (ld)s->phi0, phi = s->phi0 + v * dphi;
    ld cp = cosl(phi), sp = sinl(phi);
    (void)th;
    set3(o->P, r * c * cp, r * sn * cp, r * sp);
    set3(o->Pu, -s->thetamax * r * sn * cp, s->thetamax * r * c * cp, 0);
    set3(o->Pv, -dphi * r * c * sp, -dphi * r * sn * sp, dphi * r * cp);
}

static void oracle_torus(const geom_surface *s, ld c, ld sn, ld v, fx_exact *o)
{
    ld R = s->majorrad, r = s->minorrad, dphi = (ld)s->phimax - (ld)s->phimin;
    ld phi = s->phimin + v * dphi, cp = cosl(phi), sp = sinl(phi), rho = R + r * cp;
    set3(o->P, rho * c, rho * sn, r * sp);
    set3(o->Pu, -s->thetamax * rho * sn, s->thetamax * rho * c, 0);
    set3(o->Pv, -dphi * r * sp * c, -dphi * r * sp * sn, dphi * r * cp);
}

static void oracle_hyperboloid(const geom_surface *s, ld c, ld sn, ld v, fx_exact *o)
{
    ld qx = (1 - v) * s->point1.x + v * s->point2.x;
    ld qy = (1 - v) * s->point1.y + v * s->point2.y;
    ld qz = (1 - v) * s->point1.z + v * s->point2.z;
    ld dx = (ld)s->point2.x - s->point1.x, dy = (ld)s->point2.y - s->point1.y;
    ld dz = (ld)s->point2.z - s->point1.z, tm = s->thetamax;
    set3(o->P, qx * c - qy * sn, qx * sn + qy * c, qz);
    set3(o->Pu, tm * (-qx * sn - qy * c), tm * (qx * c - qy * sn), 0);
    set3(o->Pv, dx * c - dy * sn, dx * sn + dy * c, dz);
}

/* P = rho(v) (cos, sin) + z(v), for disk, cylinder, cone, paraboloid */
static void oracle_radial(const geom_surface *s, ld c, ld sn, ld v, fx_exact *o)
{
    ld rho, rho1, z, z1, tm = s->thetamax;
    switch (s->kind) {
    case GEOM_DISK:
        rho = s->radius * (1 - v); rho1 = -(ld)s->radius; z = s->height; z1 = 0;
        break;
    case GEOM_CYLINDER:
        rho = s->radius; rho1 = 0; z1 = (ld)s->zmax - s->zmin; z = s->zmin + v * z1;
        break;
    case GEOM_CONE:
        rho = s->radius * (1 - v); rho1 = -(ld)s->radius; z = v * s->height; z1 = s->height;
        break;
    default:                                      /* paraboloid */
        z1 = (ld)s->zmax - s->zmin;
        z = s->zmin + v * z1;
        rho = s->rmax * sqrtl(z / s->zmax);
        rho1 = s->rmax * z1 / (2 * sqrtl(z * s->zmax));
        break;
    }
    set3(o->P, rho * c, rho * sn, z);
    set3(o->Pu, -tm * rho * sn, tm * rho * c, 0);
    set3(o->Pv, rho1 * c, rho1 * sn, z1);
}

static void oracle_polygon(const geom_surface *s, ld u, ld v, fx_exact *o)
{
    for (int i = 0; i < 3; i++) {
        ld au = v3_comp(s->axis_u, i), av = v3_comp(s->axis_v, i);
        o->P[i] = v3_comp(s->origin, i) + u * au + v * av;
        o->Pu[i] = au;
        o->Pv[i] = av;
    }
}

static void oracle_patch(const geom_surface *s, ld u, ld v, fx_exact *o)
{
    for (int i = 0; i < 3; i++) {
        ld p00 = v3_comp(s->verts[0], i), p10 = v3_comp(s->verts[1], i);
        ld p01 = v3_comp(s->verts[2], i), p11 = v3_comp(s->verts[3], i);
        o->P[i] = (1 - u) * (1 - v) * p00 + u * (1 - v) * p10 + (1 - u) * v * p01 +
                  u * v * p11;
        o->Pu[i] = (1 - v) * (p10 - p00) + v * (p11 - p01);
        o->Pv[i] = (1 - u) * (p01 - p00) + u * (p11 - p10);
    }
}

/* de Casteljau on 4 points (long double), and the curve's derivative */
static ld casteljau(const ld *p, int n, ld t)
{
    ld q[4];
    for (int i = 0; i < n; i++)
        q[i] = p[i];
    for (int k = n - 1; k > 0; k--)
        for (int i = 0; i < k; i++)
            q[i] = (1 - t) * q[i] + t * q[i + 1];
    return q[0];
}

/* P by de Casteljau in v of the de Casteljau values in u; the derivatives
 * from the hodographs 3 (p[i+1] - p[i]) (a form independent of the
 * library's Bernstein sums) */
static void oracle_bicubic(const geom_surface *s, ld u, ld v, fx_exact *o)
{
    for (int c = 0; c < 3; c++) {
        ld row[4], drow[4], col[4];
        for (int j = 0; j < 4; j++) {
            ld p[4], dp[3];
            for (int i = 0; i < 4; i++)
                p[i] = v3_comp(s->verts[4 * j + i], c);
            for (int i = 0; i < 3; i++)
                dp[i] = 3 * (p[i + 1] - p[i]);
            row[j] = casteljau(p, 4, u);
            drow[j] = casteljau(dp, 3, u);
        }
        o->P[c] = casteljau(row, 4, v);
        o->Pu[c] = casteljau(drow, 4, v);
        for (int j = 0; j < 3; j++)
            col[j] = 3 * (row[j + 1] - row[j]);
        o->Pv[c] = casteljau(col, 3, v);
    }
}

void fx_oracle(const geom_surface *s, double u, double v, fx_exact *o)
{
    ld th = (ld)u * s->thetamax, c = cosl(th), sn = sinl(th);
    switch (s->kind) {
    case GEOM_SPHERE:      oracle_sphere(s, th, c, sn, v, o); break;
    case GEOM_TORUS:       oracle_torus(s, c, sn, v, o); break;
    case GEOM_HYPERBOLOID: oracle_hyperboloid(s, c, sn, v, o); break;
    case GEOM_POLYGON:     oracle_polygon(s, u, v, o); break;
    case GEOM_PATCH:       oracle_patch(s, u, v, o); break;
    case GEOM_BICUBIC:     oracle_bicubic(s, u, v, o); break;
    default:               oracle_radial(s, c, sn, v, o); break;
    }
    o->Ng[0] = o->Pu[1] * o->Pv[2] - o->Pu[2] * o->Pv[1];
    o->Ng[1] = o->Pu[2] * o->Pv[0] - o->Pu[0] * o->Pv[2];
    o->Ng[2] = o->Pu[0] * o->Pv[1] - o->Pu[1] * o->Pv[0];
}

bool fx_on_surface(const geom_surface *s, double u, double v)
{
    return u >= 0 && u <= 1 && v >= 0 && v <= 1 && geom_uv_inside(s, u, v);
}

/* ---- subdivision meshes ---- */

const double FX_CUBE_P[24] = { -1, -1, -1,  1, -1, -1,  1, 1, -1,  -1, 1, -1,
                               -1, -1, 1,   1, -1, 1,   1, 1, 1,   -1, 1, 1 };
static const int CUBE_NV[] = { 4, 4, 4, 4, 4, 4 };
static const int CUBE_V[] = { 0, 3, 2, 1,  4, 5, 6, 7,  0, 1, 5, 4,
                              1, 2, 6, 5,  2, 3, 7, 6,  3, 0, 4, 7 };

geom_subdiv *fx_subdiv_cube(int ncreases, const int *clen, const int *cverts,
                            const double *csharp, int ncorners, const int *corners,
                            const double *csh)
{
    geom_subdiv_desc d = { 6, CUBE_NV, CUBE_V, 8, FX_CUBE_P, ncreases, clen, cverts, csharp,
                           ncorners, corners, csh, 0, NULL, false };
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    if (!sd) fprintf(stderr, "cube: %s\n", why);
    return sd;
}

geom_subdiv *fx_subdiv_fan(int n, const double **P)
{
    static double fan_P[3 * (2 * FX_FAN_MAX + 1)];
    static int fan_V[4 * FX_FAN_MAX], fan_NV[FX_FAN_MAX];
    if (n < 3 || n > FX_FAN_MAX) return NULL;
    fan_P[0] = 0.1, fan_P[1] = -0.05, fan_P[2] = 0.3;
    for (int i = 0; i < n; i++) {
        double a = 2 * M_PI * i / n, b = 2 * M_PI * (i + 0.5) / n;
        double *E = fan_P + 3 * (1 + 2 * i), *F = fan_P + 3 * (2 + 2 * i);
        E[0] = cos(a), E[1] = sin(a), E[2] = 0.2 * sin(3 * a);
        F[0] = 1.5 * cos(b), F[1] = 1.5 * sin(b), F[2] = -0.3 + 0.1 * i;
        int e0 = 1 + 2 * i, f0 = 2 + 2 * i, e1 = 1 + 2 * ((i + 1) % n);
        fan_V[4 * i] = 0, fan_V[4 * i + 1] = e0, fan_V[4 * i + 2] = f0, fan_V[4 * i + 3] = e1;
        fan_NV[i] = 4;
    }
    geom_subdiv_desc d = { n, fan_NV, fan_V, 2 * n + 1, fan_P, 0, NULL, NULL, NULL,
                           0, NULL, NULL, 0, NULL, true };
    char why[200];
    geom_subdiv *sd = geom_subdiv_new(&d, why, sizeof why);
    if (!sd) fprintf(stderr, "fan %d: %s\n", n, why);
    if (P) *P = fan_P;
    return sd;
}

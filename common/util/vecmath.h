/*
 * vecmath.h: the small double-precision vector and matrix algebra every
 * part of the renderer shares (points, vectors, normals, 4x4 transforms).
 *
 * Conventions (docs/renderer.md): a vec3 is a column vector; a mat4 m maps
 * a point p to m * (p, 1) and a vector v to m * (v, 0), m.m[row][col]; the
 * composition "apply a, then b" is mat4_mul(b, a). RenderMan's RIB writes
 * matrices as row vectors (p' = p M), so a RIB matrix is the transpose of
 * ours; the scene parser converts (mat4_from_rib). Normals transform by the
 * inverse transpose (mat4_xform_normal takes the inverse).
 *
 * Header-only and inline: these are called in the innermost loops.
 */
#ifndef UTIL_VECMATH_H
#define UTIL_VECMATH_H

#include <math.h>
#include <stdbool.h>

typedef struct vec3 { double x, y, z; } vec3;
typedef struct mat4 { double m[4][4]; } mat4;

static inline vec3 v3(double x, double y, double z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline vec3 v3_scale(vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline double v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_length(vec3 a) { return sqrt(v3_dot(a, a)); }
/* a / |a|; the zero vector stays zero */
static inline vec3 v3_normalize(vec3 a)
{
    double l = v3_length(a);
    return l > 0 ? v3_scale(a, 1.0 / l) : a;
}
static inline bool v3_is_finite(vec3 a)
{
    return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}
static inline vec3 v3_lerp(vec3 a, vec3 b, double t)
{
    return v3(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t);
}
static inline double v3_comp(vec3 a, int i) { return i == 0 ? a.x : i == 1 ? a.y : a.z; }

static inline mat4 mat4_identity(void)
{
    mat4 r = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    return r;
}
/* a * b: apply b first, then a */
static inline mat4 mat4_mul(mat4 a, mat4 b)
{
    mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] +
                        a.m[i][2] * b.m[2][j] + a.m[i][3] * b.m[3][j];
    return r;
}
static inline mat4 mat4_transpose(mat4 a)
{
    mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) r.m[i][j] = a.m[j][i];
    return r;
}
/* RIB's 16 numbers (row-vector convention) to our column convention */
static inline mat4 mat4_from_rib(const double v[16])
{
    mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) r.m[j][i] = v[i * 4 + j];
    return r;
}
static inline mat4 mat4_translate(double x, double y, double z)
{
    mat4 r = mat4_identity();
    r.m[0][3] = x; r.m[1][3] = y; r.m[2][3] = z;
    return r;
}
static inline mat4 mat4_scale(double x, double y, double z)
{
    mat4 r = mat4_identity();
    r.m[0][0] = x; r.m[1][1] = y; r.m[2][2] = z;
    return r;
}
/* rotation by `degrees` about axis (x,y,z), RenderMan's Rotate */
static inline mat4 mat4_rotate(double degrees, double x, double y, double z)
{
    vec3 a = v3_normalize(v3(x, y, z));
    double r = degrees * (M_PI / 180.0), c = cos(r), s = sin(r), t = 1 - c;
    mat4 m = mat4_identity();
    m.m[0][0] = t * a.x * a.x + c;       m.m[0][1] = t * a.x * a.y - s * a.z; m.m[0][2] = t * a.x * a.z + s * a.y;
    m.m[1][0] = t * a.x * a.y + s * a.z; m.m[1][1] = t * a.y * a.y + c;       m.m[1][2] = t * a.y * a.z - s * a.x;
    m.m[2][0] = t * a.x * a.z - s * a.y; m.m[2][1] = t * a.y * a.z + s * a.x; m.m[2][2] = t * a.z * a.z + c;
    return m;
}
static inline vec3 mat4_xform_point(const mat4 *m, vec3 p)
{
    double x = m->m[0][0] * p.x + m->m[0][1] * p.y + m->m[0][2] * p.z + m->m[0][3];
    double y = m->m[1][0] * p.x + m->m[1][1] * p.y + m->m[1][2] * p.z + m->m[1][3];
    double z = m->m[2][0] * p.x + m->m[2][1] * p.y + m->m[2][2] * p.z + m->m[2][3];
    double w = m->m[3][0] * p.x + m->m[3][1] * p.y + m->m[3][2] * p.z + m->m[3][3];
    if (w != 1.0 && w != 0.0) { x /= w; y /= w; z /= w; }
    return v3(x, y, z);
}
static inline vec3 mat4_xform_vector(const mat4 *m, vec3 v)
{
    return v3(m->m[0][0] * v.x + m->m[0][1] * v.y + m->m[0][2] * v.z,
              m->m[1][0] * v.x + m->m[1][1] * v.y + m->m[1][2] * v.z,
              m->m[2][0] * v.x + m->m[2][1] * v.y + m->m[2][2] * v.z);
}
/* a normal under the transform whose INVERSE is `inv`: inv^T * n */
static inline vec3 mat4_xform_normal(const mat4 *inv, vec3 n)
{
    return v3(inv->m[0][0] * n.x + inv->m[1][0] * n.y + inv->m[2][0] * n.z,
              inv->m[0][1] * n.x + inv->m[1][1] * n.y + inv->m[2][1] * n.z,
              inv->m[0][2] * n.x + inv->m[1][2] * n.y + inv->m[2][2] * n.z);
}

/* General 4x4 inverse (cofactors). Returns false (and leaves *out the
 * identity) when the matrix is singular. */
static inline bool mat4_invert(const mat4 *a, mat4 *out)
{
    const double *m = &a->m[0][0];
    double inv[16];
    inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
    inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
    inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
    inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
    inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
    inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
    inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
    inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
    inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
    inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
    inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
    inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
    inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
    inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
    inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
    inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
    double det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
    if (det == 0 || !isfinite(det)) {
        *out = mat4_identity();
        return false;
    }
    double r = 1.0 / det;
    for (int i = 0; i < 16; i++) (&out->m[0][0])[i] = inv[i] * r;
    return true;
}
static inline double mat4_det3(const mat4 *a)
{
    const double (*m)[4] = a->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
/* Whether the 3x3 part of m is a rotation: orthonormal columns (each
 * product within 1e-9 of the identity's) and a positive determinant. */
static inline bool mat4_is_rotation(const mat4 *m)
{
    vec3 c[3];
    for (int i = 0; i < 3; i++) c[i] = v3(m->m[0][i], m->m[1][i], m->m[2][i]);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (!(fabs(v3_dot(c[i], c[j]) - (i == j ? 1.0 : 0.0)) <= 1e-9)) return false;
    return v3_dot(c[0], v3_cross(c[1], c[2])) > 0;
}

#endif

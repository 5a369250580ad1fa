/*
 * subdiv_ev.c: the proven cone of normals over the irregular sub-face at an
 * interior smooth extraordinary point of valence n (subdiv_ev.h), every
 * constant enclosed with interval arithmetic (docs/geometry.md, "Proven
 * normals at smooth extraordinary points", gives the argument in full).
 *
 * Per valence, once: the subdivision matrix S of the sub-face's 2n+8 points
 * (exact rationals, enclosed); the 3 regular sub-patches one level down as
 * Bezier nets E_p of those points; the map M on differences D = X - X_0
 * (no eigenvalue 1 left); enclosures of the exact right and left
 * eigenvectors R*, L* of the subdominant eigenvalue lambda (double,
 * semisimple: the Fourier block of frequency 1; that lambda has a
 * 2-dimensional eigenspace is the one fact taken from the literature,
 * Doo & Sabin 1978, Stam 1998), proven by a verified
 * linear solve with lambda from its closed form, normalised L*^T R* = I;
 * Q = I - R L^T and B = Q M (then T_m = lambda^m T_0 and Y_{m+1} = B Y_m
 * exactly, no coupling left); P with ||B^P|| <= lambda^P / 2; decay weights
 * omega_c >= |(h^T B^m)_c| / lambda^m for the 72 hodograph functionals h
 * and every m (explicit to m = 10 P, at most 200, the tail from B^P);
 * C >= |R^T h|_1; J <= |det| of the characteristic map's Jacobian
 * (Bernstein coefficients, G x G pieces). Per call: T = L^T D, Y = Q D, e = sum omega_c |Y_c|,
 * rho = (2 C max|t_i| e + e^2) / (J |t1 x t2|).
 */
#include "geom/subdiv_ev.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "util/xalloc.h"

enum { NMAX = SD_EV_NMAX, FULL = 6 * NMAX + 1, KR = SD_EV_RING_MAX, KD = KR - 1, NH = 72 };

typedef ia_interval iv;

struct sd_ev_consts {
    int n, N;                 /* valence, ring size 2n+8 (differences: N - 1) */
    iv S[KR][KR];             /* one step on the ring */
    iv R[KD][2], L[KD][2];    /* eigenvector enclosures (difference space) */
    iv Q[KD][KD];             /* I - R L^T */
    double omega[KD];         /* decay weights */
    double C, J, sign;        /* sign: of the characteristic map's Jacobian */
    sd_ev_info info;
};

static sd_ev_consts *TABLE[NMAX + 1];
static int READY[NMAX + 1];   /* 1 proven, -1 failed (atomic) */
static pthread_mutex_t LOCK = PTHREAD_MUTEX_INITIALIZER;

/* ---- small interval helpers ---- */

static iv Z0(void) { return ia_point(0); }
static double mag(iv x) { return fmax(fabs(x.lo), fabs(x.hi)); }
static double mig(iv x) { return (x.lo <= 0 && x.hi >= 0) ? 0 : fmin(fabs(x.lo), fabs(x.hi)); }
static iv fma_iv(iv acc, iv a, iv b) { return ia_add(acc, ia_mul(a, b)); }
static iv pm(double r) { return ia_make(-r, r); }

/* ---- the 2-ring and one step, after bench/ev_route.c ---- */

/* the full 2-ring index of G_i(a, b) (any integers near the point), -1 outside */
static int idx(int n, int i, int a, int b)
{
    for (;;) {
        i = ((i % n) + n) % n;
        if (a == 0 && b == 0) return 0;
        if (a <= 0 && b >= 0) {
            int t = a;
            a = b, b = -t, i++;
            continue;
        }
        if (b < 0) {
            int t = b;
            b = a, a = -t, i--;
            continue;
        }
        break;
    }
    if (a > 2 || b > 2) return -1;
    return 1 + 6 * i + 3 * (a - 1) + b;
}

typedef struct {
    iv c[FULL];
    bool bad;
} form;

static void add(int n, form *f, int i, int a, int b, iv w)
{
    int k = idx(n, i, a, b);
    if (k < 0) {
        f->bad = true;
        return;
    }
    f->c[k] = ia_add(f->c[k], w);
}

static void face(int n, form *f, int i, int a, int b, iv w)
{
    iv q = ia_mul_s(w, 0.25);
    add(n, f, i, a, b, q), add(n, f, i, a + 1, b, q);
    add(n, f, i, a + 1, b + 1, q), add(n, f, i, a, b + 1, q);
}

/* the point (A, B) of sector i one level down, as weights on the 2-ring */
static void child(int n, int i, int A, int B, form *f)
{
    for (int c = 0; c < FULL; c++) f->c[c] = Z0();
    f->bad = false;
    for (;;) {
        if (A == 0 && B == 0) break;
        if (A <= 0 && B >= 0) {
            int t = A;
            A = B, B = -t, i++;
            continue;
        }
        if (B < 0) {
            int t = B;
            B = A, A = -t, i--;
            continue;
        }
        break;
    }
    i = ((i % n) + n) % n;
    iv one = ia_point(1);
    if (A == 0 && B == 0) { /* the EV: (n-2)/n S + (sum E + sum F) / n^2 */
        f->c[0] = ia_add(f->c[0], ia_div(ia_point(n - 2), ia_point(n)));
        iv w = ia_div(one, ia_point((double)n * n));
        for (int j = 0; j < n; j++) {
            add(n, f, j, 1, 0, w);
            face(n, f, j, 0, 0, w);
        }
    } else if (A % 2 == 0 && B % 2 == 0) { /* a regular vertex */
        int a = A / 2, b = B / 2;
        iv w36 = ia_point(36.0 / 64), w6 = ia_point(6.0 / 64), w1 = ia_point(1.0 / 64);
        add(n, f, i, a, b, w36);
        add(n, f, i, a + 1, b, w6), add(n, f, i, a - 1, b, w6);
        add(n, f, i, a, b + 1, w6), add(n, f, i, a, b - 1, w6);
        add(n, f, i, a + 1, b + 1, w1), add(n, f, i, a - 1, b + 1, w1);
        add(n, f, i, a + 1, b - 1, w1), add(n, f, i, a - 1, b - 1, w1);
    } else if (A % 2 && B % 2) {
        face(n, f, i, (A - 1) / 2, (B - 1) / 2, one);
    } else if (A % 2) { /* edge along a */
        int a = (A - 1) / 2, b = B / 2;
        iv q = ia_point(0.25);
        add(n, f, i, a, b, q), add(n, f, i, a + 1, b, q);
        face(n, f, i, a, b, q), face(n, f, i, a, b - 1, q);
    } else { /* edge along b */
        int a = A / 2, b = (B - 1) / 2;
        iv q = ia_point(0.25);
        add(n, f, i, a, b, q), add(n, f, i, a, b + 1, q);
        face(n, f, i, a, b, q), face(n, f, i, a - 1, b, q);
    }
}

/* canonical ring index k -> full 2-ring index */
static int full_of(int n, int k)
{
    if (k == 0) return 0;
    if (k <= n) return idx(n, k - 1, 1, 0);
    if (k <= 2 * n) return idx(n, k - 1 - n, 1, 1);
    static const int X[7][2] = {{2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {-1, 2}, {2, -1}};
    return idx(n, 0, X[k - 2 * n - 1][0], X[k - 2 * n - 1][1]);
}

/* weights of form f on the canonical ring; false if f uses a point outside it */
static bool restrict_form(int n, int N, const form *f, iv *out)
{
    if (f->bad) return false;
    bool in[FULL] = {false};
    for (int k = 0; k < N; k++) {
        in[full_of(n, k)] = true;
        out[k] = f->c[full_of(n, k)];
    }
    for (int c = 0; c < FULL; c++)
        if (!in[c] && (f->c[c].lo != 0 || f->c[c].hi != 0)) return false;
    return true;
}

/* ---- float helpers (approximations only: the proofs check them) ---- */

static void orth2(int m, double *a, double *b)
{
    double na = 0, ab = 0, nb = 0;
    for (int c = 0; c < m; c++) na += a[c] * a[c];
    for (int c = 0; c < m; c++) a[c] /= sqrt(na);
    for (int c = 0; c < m; c++) ab += a[c] * b[c];
    for (int c = 0; c < m; c++) b[c] -= ab * a[c];
    for (int c = 0; c < m; c++) nb += b[c] * b[c];
    for (int c = 0; c < m; c++) b[c] /= sqrt(nb);
}

/* the dominant 2-space of A (m x m, row-major doubles; transposed if tr) */
static void subspace(int m, const double *A, bool tr, double *r /* m x 2 */)
{
    double a[KD], b[KD], t[KD];
    unsigned long long st = 7;
    for (int c = 0; c < m; c++) {
        st = st * 6364136223846793005ULL + 1442695040888963407ULL;
        a[c] = (double)(st >> 11) / 9007199254740992.0 - 0.5;
        st = st * 6364136223846793005ULL + 1442695040888963407ULL;
        b[c] = (double)(st >> 11) / 9007199254740992.0 - 0.5;
    }
    for (int it = 0; it < 4000; it++) {
        double *v[2] = {a, b};
        for (int w = 0; w < 2; w++) {
            for (int i = 0; i < m; i++) {
                double s = 0;
                for (int j = 0; j < m; j++) s += (tr ? A[j * m + i] : A[i * m + j]) * v[w][j];
                t[i] = s;
            }
            memcpy(v[w], t, sizeof(double) * (size_t)m);
        }
        orth2(m, a, b);
    }
    for (int c = 0; c < m; c++) r[2 * c] = a[c], r[2 * c + 1] = b[c];
}

/* inverse of a k x k double matrix (Gauss-Jordan, partial pivots) */
static bool invert(int k, const double *A, double *inv)
{
    double *W = xmalloc(sizeof(double) * (size_t)(k * 2 * k));
    for (int i = 0; i < k; i++)
        for (int j = 0; j < 2 * k; j++) W[i * 2 * k + j] = j < k ? A[i * k + j] : (j - k == i);
    bool ok = true;
    for (int c = 0; c < k && ok; c++) {
        int p = c;
        for (int i = c + 1; i < k; i++)
            if (fabs(W[i * 2 * k + c]) > fabs(W[p * 2 * k + c])) p = i;
        if (!(fabs(W[p * 2 * k + c]) > 1e-300)) {
            ok = false;
            break;
        }
        for (int j = 0; j < 2 * k; j++) {
            double t = W[c * 2 * k + j];
            W[c * 2 * k + j] = W[p * 2 * k + j], W[p * 2 * k + j] = t;
        }
        double d = W[c * 2 * k + c];
        for (int j = 0; j < 2 * k; j++) W[c * 2 * k + j] /= d;
        for (int i = 0; i < k; i++) {
            if (i == c) continue;
            double f = W[i * 2 * k + c];
            if (f == 0) continue;
            for (int j = 0; j < 2 * k; j++) W[i * 2 * k + j] -= f * W[c * 2 * k + j];
        }
    }
    for (int i = 0; i < k && ok; i++)
        for (int j = 0; j < k; j++) inv[i * k + j] = W[i * 2 * k + k + j];
    free(W);
    return ok;
}

/*
 * Enclose a basis of the eigenspace of lambda of the interval matrix A
 * (m x m, transposed if tr): the exact eigenvectors r* with r*[i1], r*[i2]
 * = (1, 0) and (0, 1). Given that the eigenspace of the exact A and lambda is
 * 2-dimensional, the other m - 2 coordinates of r* solve the square system
 * G x = g (the rows other than i1, i2 of (A - lambda I) r = 0); G is proven
 * nonsingular (||I - C G|| <= beta < 1), which also makes (r[i1], r[i2]) a
 * bijection on the eigenspace, so r* exists and x lies in x~ +- |C (g -
 * G x~)| / (1 - beta). The two rows left out must contain 0 (a check that
 * lambda is an eigenvalue). approx: float basis of the space (m x 2). The
 * first `inner` coordinates (the EV's 1-ring) do not depend on the others
 * (M is block triangular), so i1, i2 are taken among them: any other
 * choice leaves the singular inner block in G.
 */
static bool verify_eig(int m, int inner, const iv *A, bool tr, iv lam, const double *approx,
                       iv *out, double *rad_out)
{
#define AT(i, j) (tr ? A[(j) * m + (i)] : A[(i) * m + (j)])
    int i1 = 0, i2 = 1;
    double best = -1;
    for (int i = 0; i < inner; i++)
        for (int j = i + 1; j < inner; j++) {
            double d = fabs(approx[2 * i] * approx[2 * j + 1] - approx[2 * i + 1] * approx[2 * j]);
            if (d > best) best = d, i1 = i, i2 = j;
        }
    int k = m - 2, rest[KD];
    for (int i = 0, q = 0; i < m; i++)
        if (i != i1 && i != i2) rest[q++] = i;
    iv *G = xmalloc(sizeof(iv) * (size_t)(k * k));
    double *Gm = xmalloc(sizeof(double) * (size_t)(k * k));
    double *C = xmalloc(sizeof(double) * (size_t)(k * k));
    for (int a = 0; a < k; a++)
        for (int b = 0; b < k; b++) {
            iv g = AT(rest[a], rest[b]);
            if (a == b) g = ia_sub(g, lam);
            G[a * k + b] = g;
            Gm[a * k + b] = ia_mid(g);
        }
    bool ok = invert(k, Gm, C);
    double beta = 0;
    for (int a = 0; a < k && ok; a++) { /* ||I - C G||_inf */
        double row = 0;
        for (int b = 0; b < k; b++) {
            iv s = ia_point(a == b ? 1 : 0);
            for (int c = 0; c < k; c++) s = ia_sub(s, ia_mul_s(G[c * k + b], C[a * k + c]));
            row = fp_add_up(row, mag(s));
        }
        beta = fmax(beta, row);
    }
    if (!(beta < 0.5)) ok = false;
    double radmax = 0;
    for (int col = 0; col < 2 && ok; col++) {
        int ic = col ? i2 : i1;
        iv g[KD];
        double gm[KD], x[KD];
        for (int a = 0; a < k; a++) g[a] = ia_neg(AT(rest[a], ic)), gm[a] = ia_mid(g[a]);
        for (int a = 0; a < k; a++) { /* x~ = C g, one refinement */
            double s = 0;
            for (int c = 0; c < k; c++) s += C[a * k + c] * gm[c];
            x[a] = s;
        }
        for (int round = 0; round < 2; round++) {
            double r[KD], dx[KD];
            for (int a = 0; a < k; a++) {
                double s = gm[a];
                for (int c = 0; c < k; c++) s -= Gm[a * k + c] * x[c];
                r[a] = s;
            }
            for (int a = 0; a < k; a++) {
                double s = 0;
                for (int c = 0; c < k; c++) s += C[a * k + c] * r[c];
                dx[a] = s;
            }
            for (int a = 0; a < k; a++) x[a] += dx[a];
        }
        iv res[KD];
        for (int a = 0; a < k; a++) {
            iv s = g[a];
            for (int c = 0; c < k; c++) s = ia_sub(s, ia_mul_s(G[a * k + c], x[c]));
            res[a] = s;
        }
        double rmax = 0;
        for (int a = 0; a < k; a++) {
            iv s = Z0();
            for (int c = 0; c < k; c++) s = ia_add(s, ia_mul_s(res[c], C[a * k + c]));
            rmax = fmax(rmax, mag(s));
        }
        double rad = fp_div_up(rmax, fp_add_dn(1, -beta));
        radmax = fmax(radmax, rad);
        for (int i = 0; i < m; i++) out[2 * i + col] = Z0();
        out[2 * ic + col] = ia_point(1);
        for (int a = 0; a < k; a++) out[2 * rest[a] + col] = ia_add(ia_point(x[a]), pm(rad));
        /* the rows left out: (A - lambda I) r contains 0 */
        for (int q = 0; q < 2; q++) {
            int i = q ? i2 : i1;
            iv s = ia_mul(ia_neg(lam), out[2 * i + col]);
            for (int c = 0; c < m; c++) s = fma_iv(s, AT(i, c), out[2 * c + col]);
            if (!(s.lo <= 0 && s.hi >= 0)) ok = false;
        }
    }
    free(G), free(Gm), free(C);
    *rad_out = radmax;
    return ok;
#undef AT
}

/* out = A B (m x m intervals, row-major) */
static void matmul(int m, const iv *A, const iv *B, iv *out)
{
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            iv s = Z0();
            for (int c = 0; c < m; c++) s = fma_iv(s, A[i * m + c], B[c * m + j]);
            out[i * m + j] = s;
        }
}

static double norm_inf(int m, const iv *A)
{
    double nm = 0;
    for (int i = 0; i < m; i++) {
        double s = 0;
        for (int j = 0; j < m; j++) s = fp_add_up(s, mag(A[i * m + j]));
        nm = fmax(nm, s);
    }
    return nm;
}

/* lower bound of the least |Bernstein coefficient| of the characteristic
 * map's Jacobian over patch net P (16 2D points) split into G x G pieces,
 * times G^2; sign of the coefficients in *sgn (0: undecided) */
static double jac_low(const iv P[16][2], int G, int *sgn)
{
    static const double B2[3] = {1, 2, 1}, B3[4] = {1, 3, 3, 1}, B5[6] = {1, 5, 10, 10, 5, 1};
    double lowpos = INFINITY, highneg = -INFINITY;
    bool pos = true, neg = true;
    for (int pj = 0; pj < G; pj++)
        for (int pi = 0; pi < G; pi++) {
            double t0s[2] = {(double)pi / G, (double)pj / G}, t1s[2] = {(double)(pi + 1) / G,
                                                                         (double)(pj + 1) / G};
            iv H[4][4][2]; /* restricted net: first along u (i), then v (j) */
            for (int pass = 0; pass < 2; pass++) {
                double t0 = t0s[pass], t1 = t1s[pass];
                double ts[4][3] = {{t0, t0, t0}, {t0, t0, t1}, {t0, t1, t1}, {t1, t1, t1}};
                for (int line = 0; line < 4; line++)
                    for (int d = 0; d < 2; d++) {
                        iv src[4], dst[4];
                        for (int q = 0; q < 4; q++)
                            src[q] = pass == 0 ? P[4 * line + q][d] : H[q][line][d];
                        for (int q = 0; q < 4; q++) {
                            iv a[4] = {src[0], src[1], src[2], src[3]};
                            for (int r = 0; r < 3; r++)
                                for (int s = 0; s < 3 - r; s++)
                                    a[s] = ia_add(ia_mul_s(a[s], 1 - ts[q][r]),
                                                  ia_mul_s(a[s + 1], ts[q][r]));
                            dst[q] = a[0];
                        }
                        for (int q = 0; q < 4; q++) {
                            if (pass == 0) H[line][q][d] = dst[q];
                            else H[q][line][d] = dst[q];
                        }
                    }
            }
            iv Cf[6][6];
            for (int a = 0; a < 6; a++)
                for (int b = 0; b < 6; b++) Cf[a][b] = Z0();
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 3; i++)
                    for (int l = 0; l < 3; l++)
                        for (int k = 0; k < 4; k++) {
                            iv ux = ia_mul_s(ia_sub(H[j][i + 1][0], H[j][i][0]), 3);
                            iv uy = ia_mul_s(ia_sub(H[j][i + 1][1], H[j][i][1]), 3);
                            iv vx = ia_mul_s(ia_sub(H[l + 1][k][0], H[l][k][0]), 3);
                            iv vy = ia_mul_s(ia_sub(H[l + 1][k][1], H[l][k][1]), 3);
                            iv w = ia_div(ia_point(B2[i] * B3[k] * B3[j] * B2[l]),
                                          ia_point(B5[i + k] * B5[j + l]));
                            iv J = ia_sub(ia_mul(ux, vy), ia_mul(uy, vx));
                            Cf[j + l][i + k] = ia_add(Cf[j + l][i + k], ia_mul(w, J));
                        }
            for (int a = 0; a < 6; a++)
                for (int b = 0; b < 6; b++) {
                    if (!(Cf[a][b].lo > 0)) pos = false;
                    if (!(Cf[a][b].hi < 0)) neg = false;
                    lowpos = fmin(lowpos, Cf[a][b].lo);
                    highneg = fmax(highneg, Cf[a][b].hi);
                }
        }
    double g2 = (double)G * G;
    if (pos) return *sgn = 1, fp_mul_dn(lowpos, g2);
    if (neg) return *sgn = -1, fp_mul_dn(-highneg, g2);
    *sgn = 0;
    return 0;
}

static bool compute(int n, sd_ev_consts *K)
{
    memset(K, 0, sizeof *K);
    int N = 2 * n + 8, m = N - 1;
    K->n = n, K->N = N;
    form *f = xmalloc(sizeof *f);
    bool ok = true;
    for (int k = 0; k < N && ok; k++) {
        int c = full_of(n, k), i = c == 0 ? 0 : (c - 1) / 6, a = c == 0 ? 0 : 1 + ((c - 1) % 6) / 3,
            b = c == 0 ? 0 : (c - 1) % 3;
        child(n, i, a, b, f);
        ok = restrict_form(n, N, f, K->S[k]);
    }
    if (!ok) K->info.failed = "the ring is not closed under a step";
    /* the 3 patches one level down: B-spline grid -> Bezier */
    static const int LO[3][2] = {{1, 0}, {1, 1}, {0, 1}};
    static const double MN[4][4] = {{1, 4, 1, 0}, {0, 4, 2, 0}, {0, 2, 4, 0}, {0, 1, 4, 1}};
    iv(*E)[16][KR] = xcalloc(3, sizeof *E);
    iv(*g)[4][KR] = xcalloc(4, sizeof *g);
    for (int p = 0; p < 3 && ok; p++) {
        for (int q = 0; q < 4 && ok; q++)
            for (int r = 0; r < 4 && ok; r++) {
                child(n, 0, LO[p][0] - 1 + r, LO[p][1] - 1 + q, f);
                ok = restrict_form(n, N, f, g[q][r]);
            }
        if (!ok) K->info.failed = "a patch uses a point outside the ring";
        for (int j = 0; j < 4 && ok; j++)
            for (int i = 0; i < 4; i++)
                for (int c = 0; c < N; c++) {
                    iv s = Z0();
                    for (int q = 0; q < 4; q++)
                        for (int r = 0; r < 4; r++)
                            if (MN[j][q] != 0 && MN[i][r] != 0)
                                s = ia_add(s, ia_mul_s(g[q][r][c], MN[j][q] * MN[i][r]));
                    E[p][4 * j + i][c] = ia_div(s, ia_point(36));
                }
    }
    free(g);
    free(f);
    /* differences: M[r][c] = S[r+1][c+1] - S[0][c+1] */
    iv *M = xmalloc(sizeof(iv) * (size_t)(m * m)), *B = xmalloc(sizeof(iv) * (size_t)(m * m)),
       *Bp = xmalloc(sizeof(iv) * (size_t)(m * m)), *T = xmalloc(sizeof(iv) * (size_t)(m * m));
    double *Mm = xmalloc(sizeof(double) * (size_t)(m * m));
    for (int r = 0; r < m; r++)
        for (int c = 0; c < m; c++) {
            M[r * m + c] = ia_sub(K->S[r + 1][c + 1], K->S[0][c + 1]);
            Mm[r * m + c] = ia_mid(M[r * m + c]);
        }
    /* lambda = (5 + cos(2 pi/n) + cos(pi/n) sqrt(2 (9 + cos(2 pi/n)))) / 16 */
    iv pi = ia_make(AA_PI_LO, AA_PI_HI);
    iv c2 = ia_cos(ia_div(ia_mul_s(pi, 2), ia_point(n))), c1 = ia_cos(ia_div(pi, ia_point(n)));
    iv lam = ia_mul_s(
        ia_add(ia_add(ia_point(5), c2), ia_mul(c1, ia_sqrt(ia_mul_s(ia_add(ia_point(9), c2), 2)))),
        1.0 / 16);
    K->info.lambda_lo = lam.lo;
    /* eigenvectors */
    double ar[2 * KD] = {0}, al[2 * KD] = {0}, rr = 0, rl = 0;
    iv Lraw[KD][2];
    if (ok) {
        subspace(m, Mm, false, ar);
        subspace(m, Mm, true, al);
        ok = verify_eig(m, 2 * n, M, false, lam, ar, &K->R[0][0], &rr) &&
             verify_eig(m, 2 * n, M, true, lam, al, &Lraw[0][0], &rl);
        if (!ok) K->info.failed = "eigenvector enclosure";
    }
    if (ok) { /* L = Lraw G^-T, G = Lraw^T R */
        iv G2[2][2];
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2; b++) {
                iv s = Z0();
                for (int c = 0; c < m; c++) s = fma_iv(s, Lraw[c][a], K->R[c][b]);
                G2[a][b] = s;
            }
        iv det = ia_sub(ia_mul(G2[0][0], G2[1][1]), ia_mul(G2[0][1], G2[1][0]));
        if (det.lo <= 0 && det.hi >= 0) ok = false, K->info.failed = "L^T R singular";
        iv Gi[2][2] = {{ia_div(G2[1][1], det), ia_div(ia_neg(G2[0][1]), det)},
                       {ia_div(ia_neg(G2[1][0]), det), ia_div(G2[0][0], det)}};
        for (int c = 0; c < m && ok; c++)
            for (int a = 0; a < 2; a++)
                K->L[c][a] = ia_add(ia_mul(Lraw[c][0], Gi[a][0]), ia_mul(Lraw[c][1], Gi[a][1]));
        double rad = 0;
        for (int c = 0; c < m; c++)
            for (int a = 0; a < 2; a++)
                rad = fmax(rad, fmax(ia_width(K->R[c][a]), ia_width(K->L[c][a])) / 2);
        K->info.eig_rad = rad;
    }
    /* Q = I - R L^T, B = Q M, P */
    for (int r = 0; r < m; r++)
        for (int c = 0; c < m; c++) {
            iv s = ia_point(r == c);
            s = ia_sub(s, ia_add(ia_mul(K->R[r][0], K->L[c][0]), ia_mul(K->R[r][1], K->L[c][1])));
            K->Q[r][c] = s;
            T[r * m + c] = s;
        }
    if (ok) matmul(m, T, M, B);
    int P = 0;
    double lamP = 1;
    memcpy(Bp, B, sizeof(iv) * (size_t)(m * m));
    for (int k = 1; k <= 80 && ok; k++) {
        lamP = fp_mul_dn(lamP, lam.lo);
        if (norm_inf(m, Bp) <= lamP / 2) {
            P = k;
            break;
        }
        matmul(m, Bp, B, T);
        memcpy(Bp, T, sizeof(iv) * (size_t)(m * m));
    }
    if (ok && P == 0) ok = false, K->info.failed = "no P <= 80 with ||B^P|| <= lambda^P / 2";
    K->info.P = P;
    /* omega, C from the 72 hodograph functionals (in differences) */
    K->C = 0;
    for (int c = 0; c < m; c++) K->omega[c] = 0;
    /* explicit to 10 P (at most 200): the tail's bound, half the largest of
     * the last P, is then about 2^-10 of the weights' peaks */
    enum { KMAX_EXP = 200 };
    int KEXP = 10 * P < 40 ? 40 : 10 * P > KMAX_EXP ? KMAX_EXP : 10 * P;
    iv(*hist)[KD] = xcalloc(KMAX_EXP, sizeof *hist);
    for (int h = 0; h < NH && ok; h++) {
        int p = h / 24, hh = h % 24, j = (hh % 12) / 3, i = hh % 3;
        int q1 = hh < 12 ? 4 * j + i + 1 : 4 * (i + 1) + j, q0 = hh < 12 ? 4 * j + i : 4 * i + j;
        for (int c = 0; c < m; c++)
            hist[0][c] = ia_mul_s(ia_sub(E[p][q1][c + 1], E[p][q0][c + 1]), 3);
        iv cr[2] = {Z0(), Z0()};
        for (int c = 0; c < m; c++)
            for (int a = 0; a < 2; a++) cr[a] = fma_iv(cr[a], hist[0][c], K->R[c][a]);
        K->C = fmax(K->C, fp_add_up(mag(cr[0]), mag(cr[1])));
        double lk = 1, tail = 0;
        for (int k = 0; k < KEXP; k++) {
            if (k > 0) {
                const iv *src = k < P ? hist[k - 1] : hist[k - P];
                const iv *A = k < P ? B : Bp;
                for (int c = 0; c < m; c++) {
                    iv s = Z0();
                    for (int q = 0; q < m; q++) s = fma_iv(s, src[q], A[q * m + c]);
                    hist[k][c] = s;
                }
                lk = fp_mul_dn(lk, lam.lo);
            }
            double l1 = 0;
            for (int c = 0; c < m; c++) {
                K->omega[c] = fmax(K->omega[c], fp_div_up(mag(hist[k][c]), lk));
                l1 = fp_add_up(l1, mag(hist[k][c]));
            }
            if (k >= KEXP - P) tail = fmax(tail, fp_div_up(l1, lk));
        }
        /* m >= KEXP: ||h^T B^m||_1 / lambda^m <= max of the last P / 2 */
        for (int c = 0; c < m; c++) K->omega[c] = fmax(K->omega[c], tail / 2);
    }
    free(hist);
    double osum = 0;
    for (int c = 0; c < m; c++) osum = fp_add_up(osum, K->omega[c]);
    K->info.omega_sum = osum;
    K->info.C = K->C;
    /* J: characteristic map's nets */
    K->J = 0;
    for (int G = 1; G <= 8 && ok; G *= 2) {
        double low = INFINITY;
        int sgn = 0, s0 = 2;
        for (int p = 0; p < 3; p++) {
            iv net[16][2];
            for (int q = 0; q < 16; q++)
                for (int a = 0; a < 2; a++) {
                    iv s = Z0();
                    for (int c = 0; c < m; c++) s = fma_iv(s, E[p][q][c + 1], K->R[c][a]);
                    net[q][a] = s;
                }
            double jl = jac_low((const iv(*)[2])net, G, &sgn);
            if (sgn == 0 || (s0 != 2 && sgn != s0)) {
                low = 0;
                break;
            }
            s0 = sgn;
            low = fmin(low, jl);
        }
        if (low > K->J) K->J = low, K->sign = s0, K->info.J_pieces = G;
    }
    if (ok && !(K->J > 0)) ok = false, K->info.failed = "J > 0 not proven";
    K->info.J = K->J;
    free(E), free(M), free(B), free(Bp), free(T), free(Mm);
    K->info.proven = ok;
    return ok;
}

const sd_ev_consts *sd_ev_consts_get(int n)
{
    if (n < 3 || n > NMAX || n == 4) return NULL;
    int r = __atomic_load_n(&READY[n], __ATOMIC_ACQUIRE);
    if (r == 0) {
        pthread_mutex_lock(&LOCK);
        if (READY[n] == 0) {
            sd_ev_consts *K = xmalloc(sizeof *K);
            bool ok = compute(n, K);
            TABLE[n] = K;
            __atomic_store_n(&READY[n], ok ? 1 : -1, __ATOMIC_RELEASE);
        }
        pthread_mutex_unlock(&LOCK);
        r = __atomic_load_n(&READY[n], __ATOMIC_ACQUIRE);
    }
    return r == 1 ? TABLE[n] : NULL;
}

const char *sd_ev_failed(int n)
{
    if (n < 3 || n > NMAX || n == 4) return "valence out of range";
    if (sd_ev_consts_get(n)) return NULL;
    return TABLE[n]->info.failed;
}

void sd_ev_consts_info(const sd_ev_consts *K, sd_ev_info *out) { *out = K->info; }

void sd_ev_step(const sd_ev_consts *K, const ia_interval (*X)[3], ia_interval (*out)[3])
{
    for (int r = 0; r < K->N; r++)
        for (int d = 0; d < 3; d++) {
            iv s = Z0();
            for (int c = 0; c < K->N; c++)
                if (K->S[r][c].hi != 0 || K->S[r][c].lo != 0) s = fma_iv(s, K->S[r][c], X[c][d]);
            out[r][d] = s;
        }
}

/* upper bound of the Euclidean length of an interval vector */
static double len_up(const iv v[3])
{
    double s = 0;
    for (int d = 0; d < 3; d++) s = fp_add_up(s, fp_mul_up(mag(v[d]), mag(v[d])));
    return fp_next_up(sqrt(s));
}

static double len_dn(const iv v[3])
{
    double s = 0;
    for (int d = 0; d < 3; d++) s = fp_add_dn(s, fp_mul_dn(mig(v[d]), mig(v[d])));
    return fp_next_down(sqrt(s));
}

bool sd_ev_cone(const sd_ev_consts *K, const ia_interval (*X)[3], ia_interval axis[3],
                double *rho)
{
    int m = K->N - 1;
    iv D[KD][3], T[2][3];
    for (int c = 0; c < m; c++)
        for (int d = 0; d < 3; d++) D[c][d] = ia_sub(X[c + 1][d], X[0][d]);
    for (int a = 0; a < 2; a++)
        for (int d = 0; d < 3; d++) {
            iv s = Z0();
            for (int c = 0; c < m; c++) s = fma_iv(s, K->L[c][a], D[c][d]);
            T[a][d] = s;
        }
    double e = 0;
    for (int r = 0; r < m; r++) {
        iv Y[3];
        for (int d = 0; d < 3; d++) {
            iv s = Z0();
            for (int c = 0; c < m; c++) s = fma_iv(s, K->Q[r][c], D[c][d]);
            Y[d] = s;
        }
        e = fp_add_up(e, fp_mul_up(K->omega[r], len_up(Y)));
    }
    double tmax = fmax(len_up(T[0]), len_up(T[1]));
    iv w[3] = {ia_sub(ia_mul(T[0][1], T[1][2]), ia_mul(T[0][2], T[1][1])),
               ia_sub(ia_mul(T[0][2], T[1][0]), ia_mul(T[0][0], T[1][2])),
               ia_sub(ia_mul(T[0][0], T[1][1]), ia_mul(T[0][1], T[1][0]))};
    double wlo = len_dn(w), whi = len_up(w);
    if (!(wlo > 0) || !(whi < INFINITY)) return false;
    double num = fp_add_up(fp_mul_up(fp_mul_up(2 * K->C, tmax), e), fp_mul_up(e, e));
    *rho = fp_div_up(num, fp_mul_dn(K->J, wlo));
    if (!(*rho < INFINITY)) return false;
    iv len = ia_make(wlo, whi);
    for (int d = 0; d < 3; d++) {
        axis[d] = ia_div(w[d], len);
        if (K->sign < 0) axis[d] = ia_neg(axis[d]);
        axis[d] = ia_make(fmax(axis[d].lo, -1), fmin(axis[d].hi, 1));
    }
    return true;
}

bool sd_ev_unit_normal_box(const sd_ev_consts *K, const ia_interval (*X)[3], double scale,
                           double pad, ia_interval N[3])
{
    iv axis[3];
    double rho;
    if (!sd_ev_cone(K, X, axis, &rho) || !(rho < 1)) return false;
    /* |N - a| = 2 sin(theta / 2) <= sqrt(2) sin(theta) <= sqrt(2) rho */
    double r = fp_add_up(fp_mul_up(fp_mul_up(0x1.6a09e667f3bcdp+0, rho), scale), pad);
    for (int d = 0; d < 3; d++)
        N[d] = ia_make(fmax(fp_add_dn(axis[d].lo, -r), -1), fmin(fp_add_up(axis[d].hi, r), 1));
    return true;
}

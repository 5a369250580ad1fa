/*
 * subdiv_ev.c: EXPERIMENT (numerical constants, not a proof; not for
 * merge): the cone of unit normals over an irregular sub-face whose one
 * irregular corner is an interior smooth extraordinary point, by the route
 * of docs/geometry.md (bench/ev_route's constants, computed here in doubles
 * per valence on first use).
 */
#include "geom/subdiv_local.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

enum { EV_NMAX = 16, FULL = 6 * EV_NMAX + 1, KMAX = 2 * EV_NMAX + 8 };

typedef struct ev_consts {
    int ready;
    double L1[KMAX], L2[KMAX], l0[KMAX], r1[KMAX], r2[KMAX], omega[KMAX], C, J;
    double sign;
} ev_consts;

static ev_consts TABLE[EV_NMAX + 1];
static pthread_mutex_t LOCK = PTHREAD_MUTEX_INITIALIZER;

static int n_;

static int idx(int i, int a, int b)
{
    int n = n_;
    for (;;) {
        i = ((i % n) + n) % n;
        if (a == 0 && b == 0) return 0;
        if (a <= 0 && b >= 0) { int t = a; a = b, b = -t, i++; continue; }
        if (b < 0) { int t = b; b = a, a = -t, i--; continue; }
        break;
    }
    return 1 + 6 * i + 3 * (a - 1) + b;
}

typedef struct { double c[FULL]; } form;

static void add(form *f, int i, int a, int b, double w) { f->c[idx(i, a, b)] += w; }

static void face(form *f, int i, int a, int b, double w)
{
    add(f, i, a, b, w / 4), add(f, i, a + 1, b, w / 4);
    add(f, i, a + 1, b + 1, w / 4), add(f, i, a, b + 1, w / 4);
}

static form child(int i, int A, int B)
{
    int n = n_;
    form f;
    memset(&f, 0, sizeof f);
    for (;;) {
        if (A == 0 && B == 0) break;
        if (A <= 0 && B >= 0) { int t = A; A = B, B = -t, i++; continue; }
        if (B < 0) { int t = B; B = A, A = -t, i--; continue; }
        break;
    }
    i = ((i % n) + n) % n;
    if (A == 0 && B == 0) {
        f.c[0] += (double)(n - 2) / n;
        for (int j = 0; j < n; j++) {
            add(&f, j, 1, 0, 1.0 / ((double)n * n));
            face(&f, j, 0, 0, 1.0 / ((double)n * n));
        }
    } else if (A % 2 == 0 && B % 2 == 0) {
        int a = A / 2, b = B / 2;
        add(&f, i, a, b, 36.0 / 64);
        add(&f, i, a + 1, b, 6.0 / 64), add(&f, i, a - 1, b, 6.0 / 64);
        add(&f, i, a, b + 1, 6.0 / 64), add(&f, i, a, b - 1, 6.0 / 64);
        add(&f, i, a + 1, b + 1, 1.0 / 64), add(&f, i, a - 1, b + 1, 1.0 / 64);
        add(&f, i, a + 1, b - 1, 1.0 / 64), add(&f, i, a - 1, b - 1, 1.0 / 64);
    } else if (A % 2 && B % 2) {
        face(&f, i, (A - 1) / 2, (B - 1) / 2, 1);
    } else if (A % 2) {
        int a = (A - 1) / 2, b = B / 2;
        add(&f, i, a, b, 0.25), add(&f, i, a + 1, b, 0.25);
        face(&f, i, a, b, 0.25), face(&f, i, a, b - 1, 0.25);
    } else {
        int a = A / 2, b = (B - 1) / 2;
        add(&f, i, a, b, 0.25), add(&f, i, a, b + 1, 0.25);
        face(&f, i, a, b, 0.25), face(&f, i, a - 1, b, 0.25);
    }
    return f;
}

/* canonical order: c, e_0..e_n-1, f_0..f_n-1, G20 G21 G22 G12 G02 G-12 G2-1 */
static int full_of(int k)
{
    int n = n_;
    if (k == 0) return 0;
    if (k <= n) return idx(k - 1, 1, 0);
    if (k <= 2 * n) return idx(k - 1 - n, 1, 1);
    static const int X[7][2] = { { 2, 0 }, { 2, 1 }, { 2, 2 }, { 1, 2 }, { 0, 2 }, { -1, 2 }, { 2, -1 } };
    return idx(0, X[k - 2 * n - 1][0], X[k - 2 * n - 1][1]);
}

static void compute(int n, ev_consts *K)
{
    n_ = n;
    int N = 2 * n + 8;
    static double S[KMAX][KMAX], E[3][16][KMAX], B[KMAX][KMAX], Q[KMAX][KMAX], T[KMAX][KMAX];
    int inv[FULL];
    for (int c = 0; c < FULL; c++) inv[c] = -1;
    for (int k = 0; k < N; k++) inv[full_of(k)] = k;
    for (int k = 0; k < N; k++) {
        int f = full_of(k), i = f == 0 ? 0 : (f - 1) / 6, a = f == 0 ? 0 : 1 + ((f - 1) % 6) / 3,
            b = f == 0 ? 0 : (f - 1) % 3;
        form g = child(i, a, b);
        for (int c = 0; c < N; c++) S[k][c] = g.c[full_of(c)];
    }
    static const int LO[3][2] = { { 1, 0 }, { 1, 1 }, { 0, 1 } };
    static const double M[4][4] = { { 1 / 6., 4 / 6., 1 / 6., 0 }, { 0, 4 / 6., 2 / 6., 0 },
                                    { 0, 2 / 6., 4 / 6., 0 }, { 0, 1 / 6., 4 / 6., 1 / 6. } };
    for (int p = 0; p < 3; p++) {
        static form g[4][4];
        for (int q = 0; q < 4; q++)
            for (int r = 0; r < 4; r++) g[q][r] = child(0, LO[p][0] - 1 + r, LO[p][1] - 1 + q);
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++)
                for (int c = 0; c < N; c++) {
                    double s = 0;
                    for (int q = 0; q < 4; q++)
                        for (int r = 0; r < 4; r++) s += M[j][q] * M[i][r] * g[q][r].c[full_of(c)];
                    E[p][4 * j + i][c] = s;
                }
    }
    (void)inv;
    double *l0 = K->l0, *r1 = K->r1, *r2 = K->r2, m1[KMAX], m2[KMAX], t[KMAX];
    for (int c = 0; c < N; c++) l0[c] = 1.0 / N;
#define MUL(y, x, tr) do { for (int r_ = 0; r_ < N; r_++) { double s_ = 0; \
        for (int c_ = 0; c_ < N; c_++) { s_ += ((tr) ? S[c_][r_] : S[r_][c_]) * (x)[c_]; } \
        t[r_] = s_; } memcpy((y), t, (size_t)N * sizeof(double)); } while (0)
    for (int it = 0; it < 2000; it++) {
        MUL(l0, l0, 1);
        double s = 0;
        for (int c = 0; c < N; c++) s += l0[c];
        for (int c = 0; c < N; c++) l0[c] /= s;
    }
    unsigned long long st = 7;
    for (int c = 0; c < N; c++) {
        st = st * 6364136223846793005ULL + 1; r1[c] = (double)(st >> 11) / 9007199254740992.0;
        st = st * 6364136223846793005ULL + 1; r2[c] = (double)(st >> 11) / 9007199254740992.0;
        st = st * 6364136223846793005ULL + 1; m1[c] = (double)(st >> 11) / 9007199254740992.0;
        st = st * 6364136223846793005ULL + 1; m2[c] = (double)(st >> 11) / 9007199254740992.0;
    }
    for (int it = 0; it < 3000; it++) {
        MUL(r1, r1, 0); MUL(r2, r2, 0); MUL(m1, m1, 1); MUL(m2, m2, 1);
        double p1 = 0, p2 = 0, q1 = 0, q2 = 0;
        for (int c = 0; c < N; c++) p1 += l0[c] * r1[c], p2 += l0[c] * r2[c], q1 += m1[c], q2 += m2[c];
        for (int c = 0; c < N; c++) r1[c] -= p1, r2[c] -= p2, m1[c] -= q1 * l0[c], m2[c] -= q2 * l0[c];
        double *pa[2][2] = { { r1, r2 }, { m1, m2 } };
        for (int w = 0; w < 2; w++) {
            double *a = pa[w][0], *b = pa[w][1], na = 0, ab = 0, nb = 0;
            for (int c = 0; c < N; c++) na += a[c] * a[c];
            for (int c = 0; c < N; c++) a[c] /= sqrt(na);
            for (int c = 0; c < N; c++) ab += a[c] * b[c];
            for (int c = 0; c < N; c++) b[c] -= ab * a[c];
            for (int c = 0; c < N; c++) nb += b[c] * b[c];
            for (int c = 0; c < N; c++) b[c] /= sqrt(nb);
        }
    }
    double G[2][2] = { { 0, 0 }, { 0, 0 } };
    for (int c = 0; c < N; c++) {
        G[0][0] += m1[c] * r1[c], G[0][1] += m1[c] * r2[c];
        G[1][0] += m2[c] * r1[c], G[1][1] += m2[c] * r2[c];
    }
    double det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
    for (int c = 0; c < N; c++) {
        K->L1[c] = (G[1][1] * m1[c] - G[0][1] * m2[c]) / det;
        K->L2[c] = (-G[1][0] * m1[c] + G[0][0] * m2[c]) / det;
    }
    double lam = (5 + cos(2 * M_PI / n) + cos(M_PI / n) * sqrt(2 * (9 + cos(2 * M_PI / n)))) / 16;
    for (int r = 0; r < N; r++)
        for (int c = 0; c < N; c++) Q[r][c] = (r == c) - l0[c] - r1[r] * K->L1[c] - r2[r] * K->L2[c];
    for (int r = 0; r < N; r++)
        for (int c = 0; c < N; c++) {
            double s = 0;
            for (int k = 0; k < N; k++) s += S[r][k] * Q[k][c];
            T[r][c] = s;
        }
    for (int r = 0; r < N; r++)
        for (int c = 0; c < N; c++) {
            double s = 0;
            for (int k = 0; k < N; k++) s += Q[r][k] * T[k][c];
            B[r][c] = s;
        }
    memset(K->omega, 0, sizeof K->omega);
    K->C = 0;
    double Jmin = INFINITY, Jmax = -INFINITY;
    for (int p = 0; p < 3; p++) {
        for (int h = 0; h < 24; h++) {
            int j = (h % 12) / 3, i = h % 3;
            int q1 = h < 12 ? 4 * j + i + 1 : 4 * (i + 1) + j, q0 = h < 12 ? 4 * j + i : 4 * i + j;
            double v[KMAX], cr1 = 0, cr2 = 0;
            for (int c = 0; c < N; c++) v[c] = 3 * (E[p][q1][c] - E[p][q0][c]);
            for (int c = 0; c < N; c++) cr1 += v[c] * r1[c], cr2 += v[c] * r2[c];
            K->C = fmax(K->C, fabs(cr1) + fabs(cr2));
            for (int k = 0; k <= 160; k++) {
                double sc = pow(lam, -k);
                for (int c = 0; c < N; c++) K->omega[c] = fmax(K->omega[c], fabs(v[c]) * sc);
                double w[KMAX];
                for (int c = 0; c < N; c++) {
                    double s = 0;
                    for (int q = 0; q < N; q++) s += v[q] * B[q][c];
                    w[c] = s;
                }
                memcpy(v, w, sizeof w);
            }
        }
        /* J: Bernstein coefficients of the hodographs' product (one piece) */
        double P[16][2];
        for (int q = 0; q < 16; q++) {
            P[q][0] = P[q][1] = 0;
            for (int c = 0; c < N; c++) P[q][0] += E[p][q][c] * r1[c], P[q][1] += E[p][q][c] * r2[c];
        }
        static const double B2[3] = { 1, 2, 1 }, B3[4] = { 1, 3, 3, 1 }, B5[6] = { 1, 5, 10, 10, 5, 1 };
        double Cf[6][6];
        memset(Cf, 0, sizeof Cf);
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 3; i++)
                for (int l = 0; l < 3; l++)
                    for (int k = 0; k < 4; k++) {
                        double ux = 3 * (P[4 * j + i + 1][0] - P[4 * j + i][0]);
                        double uy = 3 * (P[4 * j + i + 1][1] - P[4 * j + i][1]);
                        double vx = 3 * (P[4 * (l + 1) + k][0] - P[4 * l + k][0]);
                        double vy = 3 * (P[4 * (l + 1) + k][1] - P[4 * l + k][1]);
                        double w = B2[i] * B3[k] / B5[i + k] * B3[j] * B2[l] / B5[j + l];
                        Cf[j + l][i + k] += w * (ux * vy - uy * vx);
                    }
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 6; b++) Jmin = fmin(Jmin, Cf[a][b]), Jmax = fmax(Jmax, Cf[a][b]);
    }
    K->sign = Jmin > 0 ? 1 : -1;
    K->J = Jmin > 0 ? Jmin : (Jmax < 0 ? -Jmax : 0);
}

static const ev_consts *consts(int n)
{
    if (n < 3 || n > EV_NMAX) return NULL;
    ev_consts *K = &TABLE[n];
    if (__atomic_load_n(&K->ready, __ATOMIC_ACQUIRE)) return K;
    pthread_mutex_lock(&LOCK);
    if (!K->ready) {
        static ev_consts tmp;
        compute(n, &tmp);
        tmp.ready = 0;
        *K = tmp;
        __atomic_store_n(&K->ready, 1, __ATOMIC_RELEASE);
    }
    pthread_mutex_unlock(&LOCK);
    return K;
}

/* the face with a followed by b; the two corners after b */
static bool after(const sd_mesh *m, int a, int b, int *x, int *y)
{
    for (int f = 0; f < m->nf; f++) {
        int k = m->fo[f + 1] - m->fo[f];
        if (k != 4) continue;
        for (int c = 0; c < 4; c++)
            if (m->fv[m->fo[f] + c] == a && m->fv[m->fo[f] + (c + 1) % 4] == b) {
                *x = m->fv[m->fo[f] + (c + 2) % 4];
                *y = m->fv[m->fo[f] + (c + 3) % 4];
                return true;
            }
    }
    return false;
}

static int valence(const sd_mesh *m, int v)
{
    int k = 0;
    for (int c = 0; c < m->fo[m->nf]; c++) k += m->fv[c] == v;
    return k;
}

bool sd_ev_normal_box(const sd_mesh *m, ia_interval Nn[3]);

bool sd_ev_normal_box(const sd_mesh *m, ia_interval Nn[3])
{
    if (m->fo[1] - m->fo[0] != 4) return false;
    for (int c = 0; c < m->fo[m->nf]; c++)
        if (m->es[c] != 0) return false;
    for (int v = 0; v < m->nv; v++)
        if (m->vs[v] != 0) return false;
    int k = -1;
    for (int c = 0; c < 4; c++) {
        int val = valence(m, m->fv[m->fo[0] + c]);
        if (val != 4) {
            if (k >= 0) return false;
            k = c;
        }
    }
    if (k < 0) return false;
    int cpt = m->fv[m->fo[0] + k];
    int n = valence(m, cpt);
    const ev_consts *K = consts(n);
    if (!K || !(K->J > 0)) return false;
    int idxs[KMAX], *e = idxs + 1, *f = idxs + 1 + n, *g = idxs + 1 + 2 * n;
    idxs[0] = cpt;
    e[0] = m->fv[m->fo[0] + (k + 1) % 4];
    f[0] = m->fv[m->fo[0] + (k + 2) % 4];
    e[1 % n] = m->fv[m->fo[0] + (k + 3) % 4];
    for (int i = 1; i < n; i++) {
        int en;
        if (!after(m, cpt, e[i], &f[i], &en)) return false;
        if (i + 1 < n) e[i + 1] = en;
        else if (en != e[0]) return false;
    }
    int x, y;
    if (!after(m, f[0], e[0], &g[0], &g[1])) return false;
    if (!after(m, e[0], f[n - 1], &g[6], &x) || x != g[0]) return false;
    if (!after(m, f[0], g[1], &g[2], &g[3])) return false;
    if (!after(m, e[1], f[0], &x, &g[4]) || x != g[3]) return false;
    if (!after(m, f[1], e[1], &y, &g[5]) || y != g[4]) return false;
    if (valence(m, e[0]) != 4 || valence(m, e[1]) != 4 || valence(m, f[0]) != 4) return false;
    int N = 2 * n + 8;
    double p[3] = { 0, 0, 0 }, t1[3] = { 0, 0, 0 }, t2[3] = { 0, 0, 0 };
    for (int c = 0; c < N; c++)
        for (int d = 0; d < 3; d++) {
            double X = v3_comp(m->P[idxs[c]], d);
            p[d] += K->l0[c] * X, t1[d] += K->L1[c] * X, t2[d] += K->L2[c] * X;
        }
    double e_ = 0, scale = 0;
    for (int c = 0; c < N; c++) {
        double Y[3];
        for (int d = 0; d < 3; d++) {
            double X = v3_comp(m->P[idxs[c]], d);
            Y[d] = X - p[d] - K->r1[c] * t1[d] - K->r2[c] * t2[d];
            scale = fmax(scale, fabs(X));
        }
        e_ += K->omega[c] * sqrt(Y[0] * Y[0] + Y[1] * Y[1] + Y[2] * Y[2]);
    }
    double osum = 0;
    for (int c = 0; c < N; c++) osum += K->omega[c];
    e_ += osum * 1e-15 * scale;                  /* the ring's rounding (rough) */
    vec3 T1 = v3(t1[0], t1[1], t1[2]), T2 = v3(t2[0], t2[1], t2[2]), w = v3_cross(T1, T2);
    double wl = v3_length(w);
    double rho = (2 * K->C * fmax(v3_length(T1), v3_length(T2)) * e_ + e_ * e_) / (K->J * wl);
    if (!(rho < 1)) return false;
    vec3 n0 = v3_scale(w, K->sign / wl);
    double pad = sqrt(2) * rho + 1e-5;           /* + the float evaluator's noise */
    for (int i = 0; i < 3; i++) {
        double c = v3_comp(n0, i);
        Nn[i] = ia_make(fmax(c - pad, -1), fmin(c + pad, 1));
    }
    return true;
}

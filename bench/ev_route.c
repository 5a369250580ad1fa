/*
 * ev_route.c: a numerical prototype (doubles, no interval arithmetic: NOT
 * a proof) of the sound route of docs/geometry.md "Normals at smooth
 * extraordinary points" for a bound of the unit normal over the irregular
 * sub-face at an interior smooth extraordinary point of valence n: the
 * constants it needs per valence, and the cone it gives on a bumpy ring
 * level by level next to the largest angle met on the sub-face's regular
 * sub-patches (sampled), so that the route's tightness can be judged
 * before it is made rigorous.
 *
 * The 2-ring of the point in a canonical order: the point, then per
 * sector i (between edge i and edge i+1) the 6 grid points G_i(a, b),
 * a = 1..2, b = 0..2 (G_i(0, b) = G_{i+1}(b, 0)). One Catmull-Clark step
 * maps it linearly onto the 2-ring of the same point one level down (S,
 * (6n+1)^2, exact rationals); the 3 regular sub-patches of sector 0's
 * sub-face one level down are Bezier nets linear in the 2-ring (E_p).
 * With EV_SUBFACE=1 in the environment only the 2n+8 points the sub-face
 * depends on are kept (their closure under S is checked), as the renderer
 * would hold them.
 *
 * Per valence it prints lambda and A = L^T S R - lambda I (rounding only:
 * the approximate eigenvectors are good), omega's sum (the weights of the
 * decaying part Y, from the 24 hodograph functionals of the 3 patches, so
 * for any (s,t), and k <= 160), the |J| lower bound from Bernstein
 * coefficients (1 to 8x8 pieces) next to its sampled minimum, then for
 * levels j = 0..22 of a bumpy ring the cone's half-angle (90 where
 * rho >= 1: no bound) and the largest angle of the sampled normals of the
 * 3 patches at levels j..j+30 (9 x 9 points each) to the cone's axis.
 * A "VIOLATION" flag marks a sampled normal outside the cone.
 *
 * Usage: [EV_SUBFACE=1] ev_route [valence ...]   (default 3 5 6 8)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NMAX = 6 * 16 + 1 };

static int n, N;

/* the canonical index of G_i(a, b), any integers near the point */
static int idx(int i, int a, int b)
{
    for (;;) {
        i = ((i % n) + n) % n;
        if (a == 0 && b == 0) return 0;
        if (a <= 0 && b >= 0) {
            int t = a;
            a = b, b = -t, i++;
            continue;
        } /* G_{i+1}(b, -a) */
        if (b < 0) {
            int t = b;
            b = a, a = -t, i--;
            continue;
        } /* G_{i-1}(-b, a) */
        break;
    }
    if (a > 2 || b > 2) {
        fprintf(stderr, "ev_route: (%d,%d) outside the 2-ring\n", a, b);
        exit(1);
    }
    return 1 + 6 * i + 3 * (a - 1) + b;
}

typedef struct {
    double c[NMAX];
} form; /* a point as weights on the 2-ring */

static void add(form *f, int i, int a, int b, double w) { f->c[idx(i, a, b)] += w; }

/* face point of the parent cell with lower corner (a, b) */
static void face(form *f, int i, int a, int b, double w)
{
    add(f, i, a, b, w / 4), add(f, i, a + 1, b, w / 4);
    add(f, i, a + 1, b + 1, w / 4), add(f, i, a, b + 1, w / 4);
}

/* child point (A, B) of sector i (any integers, not the point itself when
 * A, B fall in another sector: normalised first) */
static form child(int i, int A, int B)
{
    form f;
    memset(&f, 0, sizeof f);
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
    if (A == 0 && B == 0) { /* the extraordinary point */
        f.c[0] += (double)(n - 2) / n;
        for (int j = 0; j < n; j++) {
            add(&f, j, 1, 0, 1.0 / ((double)n * n));
            face(&f, j, 0, 0, 1.0 / ((double)n * n));
        }
    } else if (A % 2 == 0 && B % 2 == 0) { /* a regular vertex */
        int a = A / 2, b = B / 2;
        add(&f, i, a, b, 36.0 / 64);
        add(&f, i, a + 1, b, 6.0 / 64), add(&f, i, a - 1, b, 6.0 / 64);
        add(&f, i, a, b + 1, 6.0 / 64), add(&f, i, a, b - 1, 6.0 / 64);
        add(&f, i, a + 1, b + 1, 1.0 / 64), add(&f, i, a - 1, b + 1, 1.0 / 64);
        add(&f, i, a + 1, b - 1, 1.0 / 64), add(&f, i, a - 1, b - 1, 1.0 / 64);
    } else if (A % 2 && B % 2) {
        face(&f, i, (A - 1) / 2, (B - 1) / 2, 1);
    } else if (A % 2) { /* edge along a */
        int a = (A - 1) / 2, b = B / 2;
        add(&f, i, a, b, 0.25), add(&f, i, a + 1, b, 0.25);
        face(&f, i, a, b, 0.25), face(&f, i, a, b - 1, 0.25);
    } else { /* edge along b */
        int a = A / 2, b = (B - 1) / 2;
        add(&f, i, a, b, 0.25), add(&f, i, a, b + 1, 0.25);
        face(&f, i, a, b, 0.25), face(&f, i, a - 1, b, 0.25);
    }
    return f;
}

static double S[NMAX][NMAX], E[3][16][NMAX];

static void build(void)
{
    memset(S, 0, sizeof S);
    form f = child(0, 0, 0);
    memcpy(S[0], f.c, sizeof f.c);
    for (int i = 0; i < n; i++)
        for (int a = 1; a <= 2; a++)
            for (int b = 0; b <= 2; b++) {
                f = child(i, a, b);
                memcpy(S[idx(i, a, b)], f.c, sizeof f.c);
            }
    /* sub-patches [1,2]x[0,1], [1,2]x[1,2], [0,1]x[1,2] of sector 0's
     * cell [0,1]^2 one level down: B-spline grid, then Bezier */
    static const int LO[3][2] = {{1, 0}, {1, 1}, {0, 1}};
    static const double M[4][4] = {{1 / 6., 4 / 6., 1 / 6., 0},
                                   {0, 4 / 6., 2 / 6., 0},
                                   {0, 2 / 6., 4 / 6., 0},
                                   {0, 1 / 6., 4 / 6., 1 / 6.}};
    for (int p = 0; p < 3; p++) {
        form g[4][4];
        for (int q = 0; q < 4; q++)
            for (int r = 0; r < 4; r++) g[q][r] = child(0, LO[p][0] - 1 + r, LO[p][1] - 1 + q);
        for (int j = 0; j < 4; j++)       /* v (b) */
            for (int i = 0; i < 4; i++) { /* u (a) */
                for (int c = 0; c < N; c++) {
                    double s = 0;
                    for (int q = 0; q < 4; q++)
                        for (int r = 0; r < 4; r++) s += M[j][q] * M[i][r] * g[q][r].c[c];
                    E[p][4 * j + i][c] = s;
                }
            }
    }
}

/* Keep only the points sector 0's sub-face depends on (the corners of
 * the cells touching its 4 corners: the point's 2n+1 and 7 more, Stam's
 * 2n+8), checking that one step maps them onto themselves; the test ring's
 * points pos[] follow. */
static int keep_subface(double (*pos)[3])
{
    int in[NMAX] = {0}, map[NMAX], m = 0;
    static const int CELLS[][2] = {{0, 0}, {1, 0}, {0, -1}, {1, -1},
                                   {0, 1}, {1, 1}, {-1, 0}, {-1, 1}};
    for (int j = 0; j < n; j++)
        for (int q = 0; q < 4; q++) in[idx(j, q == 1 || q == 2, q >= 2)] = 1;
    for (int k = 0; k < 8; k++)
        for (int q = 0; q < 4; q++)
            in[idx(0, CELLS[k][0] + (q == 1 || q == 2), CELLS[k][1] + (q >= 2))] = 1;
    for (int c = 0; c < N; c++) map[c] = in[c] ? m++ : -1;
    for (int r = 0; r < N; r++)
        for (int c = 0; c < N; c++)
            if (in[r] && !in[c] && S[r][c] != 0) return -1; /* not closed */
    for (int p = 0; p < 3; p++)
        for (int q = 0; q < 16; q++)
            for (int c = 0; c < N; c++)
                if (!in[c] && E[p][q][c] != 0) return -2;
    for (int r = 0; r < N; r++) {
        if (!in[r]) continue;
        for (int c = 0; c < N; c++)
            if (in[c]) S[map[r]][map[c]] = S[r][c];
        for (int d = 0; d < 3; d++) pos[map[r]][d] = pos[r][d];
    }
    for (int p = 0; p < 3; p++)
        for (int q = 0; q < 16; q++)
            for (int c = 0; c < N; c++)
                if (in[c]) E[p][q][map[c]] = E[p][q][c];
    N = m;
    return m;
}

static void mulv(double y[NMAX], const double x[NMAX], int transpose)
{
    double t[NMAX];
    for (int r = 0; r < N; r++) {
        double s = 0;
        for (int c = 0; c < N; c++) s += (transpose ? S[c][r] : S[r][c]) * x[c];
        t[r] = s;
    }
    memcpy(y, t, sizeof t[0] * (size_t)N);   /* rows N.. are not the matrix's */
}

static void orth2(double a[NMAX], double b[NMAX])
{
    double na = 0, ab = 0, nb = 0;
    for (int c = 0; c < N; c++) na += a[c] * a[c];
    for (int c = 0; c < N; c++) a[c] /= sqrt(na);
    for (int c = 0; c < N; c++) ab += a[c] * b[c];
    for (int c = 0; c < N; c++) b[c] -= ab * a[c];
    for (int c = 0; c < N; c++) nb += b[c] * b[c];
    for (int c = 0; c < N; c++) b[c] /= sqrt(nb);
}

/* Bezier derivative of a 16-net (2 or 3 components) at (s, t) */
static void bez_d(const double (*net)[3], int dim, double s, double t, double du[3], double dv[3])
{
    double Bs[4] = {(1 - s) * (1 - s) * (1 - s), 3 * s * (1 - s) * (1 - s), 3 * s * s * (1 - s),
                    s * s * s};
    double Bt[4] = {(1 - t) * (1 - t) * (1 - t), 3 * t * (1 - t) * (1 - t), 3 * t * t * (1 - t),
                    t * t * t};
    double Ds[3] = {(1 - s) * (1 - s), 2 * s * (1 - s), s * s};
    double Dt[3] = {(1 - t) * (1 - t), 2 * t * (1 - t), t * t};
    for (int k = 0; k < dim; k++) {
        double u = 0, v = 0;
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 3; i++)
                u += 3 * Ds[i] * Bt[j] * (net[4 * j + i + 1][k] - net[4 * j + i][k]);
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 4; i++)
                v += 3 * Bs[i] * Dt[j] * (net[4 * (j + 1) + i][k] - net[4 * j + i][k]);
        du[k] = u, dv[k] = v;
    }
}

static void cross(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1], c[1] = a[2] * b[0] - a[0] * b[2],
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double norm3(const double a[3]) { return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

static double l0[NMAX], Chod;

static double binom(int m, int i)
{
    double r = 1;
    for (int k = 1; k <= i; k++) r = r * (m - i + k) / k;
    return r;
}

/* cubic Bezier p[0..3] (2D) restricted to [t0, t1] (blossoms) */
static void restrict4(const double p[4][2], double t0, double t1, double q[4][2])
{
    double ts[4][3] = {{t0, t0, t0}, {t0, t0, t1}, {t0, t1, t1}, {t1, t1, t1}};
    for (int k = 0; k < 4; k++)
        for (int d = 0; d < 2; d++) {
            double a[4] = {p[0][d], p[1][d], p[2][d], p[3][d]};
            for (int r = 0; r < 3; r++)
                for (int i = 0; i < 3 - r; i++) a[i] = a[i] * (1 - ts[k][r]) + a[i + 1] * ts[k][r];
            q[k][d] = a[0];
        }
}

/* A lower bound of J = det(dchi/ds, dchi/dt) over a 2D bicubic net
 * (net[4 j + i]) split into G x G pieces: the least Bernstein coefficient
 * of the degree (5,5) product of its hodographs, per piece (the
 * coefficients' convex hull holds the polynomial); times G^2 for the
 * pieces' own parameters. Orientation sign s: bound of s J. */
static double jac_low(const double net[16][2], int G, double sgn)
{
    double low = INFINITY;
    for (int pj = 0; pj < G; pj++)
        for (int pi = 0; pi < G; pi++) {
            double H[4][4][2], P[4][4][2];
            for (int j = 0; j < 4; j++) {
                double row[4][2], out[4][2];
                for (int i = 0; i < 4; i++)
                    row[i][0] = net[4 * j + i][0], row[i][1] = net[4 * j + i][1];
                restrict4((const double(*)[2])row, (double)pi / G, (double)(pi + 1) / G, out);
                memcpy(H[j], out, sizeof out);
            }
            for (int i = 0; i < 4; i++) {
                double col[4][2], out[4][2];
                for (int j = 0; j < 4; j++) col[j][0] = H[j][i][0], col[j][1] = H[j][i][1];
                restrict4((const double(*)[2])col, (double)pj / G, (double)(pj + 1) / G, out);
                for (int j = 0; j < 4; j++) P[j][i][0] = out[j][0], P[j][i][1] = out[j][1];
            }
            /* hodographs: U[j][i] (j 0..3, i 0..2) degree (2 in s, 3 in t),
             * V[j][i] (j 0..2, i 0..3) degree (3 in s, 2 in t) */
            double C[6][6];
            memset(C, 0, sizeof C);
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 3; i++)
                    for (int l = 0; l < 3; l++)
                        for (int k = 0; k < 4; k++) {
                            double ux = 3 * (P[j][i + 1][0] - P[j][i][0]),
                                   uy = 3 * (P[j][i + 1][1] - P[j][i][1]);
                            double vx = 3 * (P[l + 1][k][0] - P[l][k][0]),
                                   vy = 3 * (P[l + 1][k][1] - P[l][k][1]);
                            double w = binom(2, i) * binom(3, k) / binom(5, i + k) * binom(3, j) *
                                       binom(2, l) / binom(5, j + l);
                            C[j + l][i + k] += w * (ux * vy - uy * vx);
                        }
            for (int a = 0; a < 6; a++)
                for (int b = 0; b < 6; b++) low = fmin(low, sgn * C[a][b] * G * G);
        }
    return low;
}

/* subtract the limit point (constants do not change the normals; the
 * ring's differences, lambda^k small, keep their precision) */
static void center(double (*Z)[3])
{
    double p[3] = {0, 0, 0};
    for (int c = 0; c < N; c++)
        for (int d = 0; d < 3; d++) p[d] += l0[c] * Z[c][d];
    for (int c = 0; c < N; c++)
        for (int d = 0; d < 3; d++) Z[c][d] -= p[d];
}

static void study(int val)
{
    n = val, N = 6 * n + 1;
    build();
    static double X[NMAX][3], Xk[NMAX][3], Y[NMAX][3];
    for (int c = 0; c < N; c++) {
        int i = c == 0 ? 0 : (c - 1) / 6, a = c == 0 ? 0 : 1 + ((c - 1) % 6) / 3,
            b = c == 0 ? 0 : (c - 1) % 3;
        double ang = 2 * M_PI * (i + (a + b > 0 ? (double)b / (a + b) : 0)) / n,
               rad = sqrt(a * a + b * b);
        X[c][0] = rad * cos(ang), X[c][1] = rad * sin(ang);
        X[c][2] = 0.3 * sin(3.0 * c) + 0.1 * rad * rad;
    }
    if (getenv("EV_SUBFACE")) {
        int m = keep_subface(X);
        printf("valence %d: the sub-face's points: %d (2n+8 = %d)%s\n", n, m, 2 * n + 8,
               m < 0 ? ": NOT CLOSED" : "");
        if (m < 0) return;
    }
    /* l0: the limit mask (power iteration on S^T) */
    static double r1[NMAX], r2[NMAX], m1[NMAX], m2[NMAX];
    for (int c = 0; c < N; c++) l0[c] = 1.0 / N;
    for (int it = 0; it < 2000; it++) {
        mulv(l0, l0, 1);
        double s = 0;
        for (int c = 0; c < N; c++) s += l0[c];
        for (int c = 0; c < N; c++) l0[c] /= s;
    }
    srand(7);
    for (int c = 0; c < N; c++)
        r1[c] = rand() / (double)RAND_MAX, r2[c] = rand() / (double)RAND_MAX;
    for (int c = 0; c < N; c++)
        m1[c] = rand() / (double)RAND_MAX, m2[c] = rand() / (double)RAND_MAX;
    for (int it = 0; it < 3000; it++) {
        mulv(r1, r1, 0), mulv(r2, r2, 0), mulv(m1, m1, 1), mulv(m2, m2, 1);
        double p1 = 0, p2 = 0, q1 = 0, q2 = 0;
        for (int c = 0; c < N; c++)
            p1 += l0[c] * r1[c], p2 += l0[c] * r2[c], q1 += m1[c], q2 += m2[c];
        for (int c = 0; c < N; c++)
            r1[c] -= p1, r2[c] -= p2, m1[c] -= q1 * l0[c], m2[c] -= q2 * l0[c];
        orth2(r1, r2), orth2(m1, m2);
    }
    /* L^T R = I */
    double G[2][2] = {{0, 0}, {0, 0}};
    for (int c = 0; c < N; c++) {
        G[0][0] += m1[c] * r1[c], G[0][1] += m1[c] * r2[c];
        G[1][0] += m2[c] * r1[c], G[1][1] += m2[c] * r2[c];
    }
    double det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
    /* L <- M G^-T (G = M^T R): l1 = (G11 m1 - G01 m2) / det, l2 = (-G10 m1 + G00 m2) / det */
    static double L1[NMAX], L2[NMAX];
    for (int c = 0; c < N; c++) {
        L1[c] = (G[1][1] * m1[c] - G[0][1] * m2[c]) / det;
        L2[c] = (-G[1][0] * m1[c] + G[0][0] * m2[c]) / det;
    }
    double A[2][2] = {{0, 0}, {0, 0}}, Sr1[NMAX], Sr2[NMAX];
    mulv(Sr1, r1, 0), mulv(Sr2, r2, 0);
    for (int c = 0; c < N; c++) {
        A[0][0] += L1[c] * Sr1[c], A[0][1] += L1[c] * Sr2[c];
        A[1][0] += L2[c] * Sr1[c], A[1][1] += L2[c] * Sr2[c];
    }
    double lam = (5 + cos(2 * M_PI / n) + cos(M_PI / n) * sqrt(2 * (9 + cos(2 * M_PI / n)))) / 16;
    double lamA = sqrt(A[0][0] * A[1][1] - A[0][1] * A[1][0]);
    /* Q = I - 1 l0^T - R L^T; B = Q S Q; gamma = sup ||B^k|| / lam^k */
    static double Q[NMAX][NMAX], B[NMAX][NMAX], P[NMAX][NMAX], T[NMAX][NMAX];
    for (int r = 0; r < N; r++)
        for (int c = 0; c < N; c++) Q[r][c] = (r == c) - l0[c] - r1[r] * L1[c] - r2[r] * L2[c];
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
    memcpy(P, Q, sizeof P);
    double gamma = 0, rowmax = 0;
    int kmax = 0, khalf = -1;
    for (int k = 0; k <= 400; k++) {
        double nm = 0;
        for (int r = 0; r < N; r++) {
            double s = 0;
            for (int c = 0; c < N; c++) s += fabs(P[r][c]);
            nm = fmax(nm, s);
        }
        if (nm / pow(lam, k) > gamma) gamma = nm / pow(lam, k), kmax = k;
        if (khalf < 0 && k > 0 && nm / pow(lam, k) <= 0.5) khalf = k;
        rowmax = nm / pow(lam, k);
        for (int r = 0; r < N; r++)
            for (int c = 0; c < N; c++) {
                double s = 0;
                for (int q = 0; q < N; q++) s += B[r][q] * P[q][c];
                T[r][c] = s;
            }
        memcpy(P, T, sizeof P);
    }
    /* the couplings E = Q S R and F = L^T S Q (0 for exact eigenvectors) */
    double Emax = 0, Fmax = 0;
    for (int r = 0; r < N; r++) {
        double e1 = 0, e2 = 0, f1 = 0, f2 = 0;
        for (int q = 0; q < N; q++) {
            double a1 = 0, a2 = 0;
            for (int k = 0; k < N; k++) a1 += S[q][k] * r1[k], a2 += S[q][k] * r2[k];
            e1 += Q[r][q] * a1, e2 += Q[r][q] * a2;
        }
        /* F's column r: sum_q (L^T S)_q Q[q][r] */
        for (int q = 0; q < N; q++) {
            double b1 = 0, b2 = 0;
            for (int k = 0; k < N; k++) b1 += L1[k] * S[k][q], b2 += L2[k] * S[k][q];
            f1 += b1 * Q[q][r], f2 += b2 * Q[q][r];
        }
        Emax = fmax(Emax, fmax(fabs(e1), fabs(e2)));
        Fmax = fmax(Fmax, fmax(fabs(f1), fabs(f2)));
    }
    /* the characteristic map's 3 patches: J_min, C_max (sampled) */
    double Jmin = INFINITY, Jmax = -INFINITY, Cmax = 0;
    for (int p = 0; p < 3; p++) {
        double net[16][3];
        for (int q = 0; q < 16; q++) {
            net[q][0] = net[q][1] = net[q][2] = 0;
            for (int c = 0; c < N; c++)
                net[q][0] += E[p][q][c] * r1[c], net[q][1] += E[p][q][c] * r2[c];
        }
        for (int a = 0; a <= 32; a++)
            for (int b = 0; b <= 32; b++) {
                double du[3], dv[3];
                bez_d((const double(*)[3])net, 2, a / 32., b / 32., du, dv);
                double J = du[0] * dv[1] - du[1] * dv[0];
                Jmin = fmin(Jmin, J), Jmax = fmax(Jmax, J);
                Cmax = fmax(Cmax, fmax(fabs(du[0]) + fabs(du[1]), fabs(dv[0]) + fabs(dv[1])));
            }
    }
    /* omega_c >= |(a^T B^k)_c| / lambda^k for every derivative functional
     * a of the 3 patches at any (s, t) and every k <= 160: a is a convex
     * combination of the hodograph functionals 3 (b_i+1,j - b_ij) (and
     * likewise in v), so their largest |.| bounds it (not sampled) */
    static double omega[NMAX];
    memset(omega, 0, sizeof omega);
    Chod = 0;
    for (int p = 0; p < 3; p++)
        for (int h = 0; h < 24; h++) {
            int j = (h % 12) / 3, i = h % 3; /* u: rows j, i -> i+1 */
            int q1 = h < 12 ? 4 * j + i + 1 : 4 * (i + 1) + j, q0 = h < 12 ? 4 * j + i : 4 * i + j;
            double v[NMAX], t[NMAX], cr1 = 0, cr2 = 0;
            for (int c = 0; c < N; c++) v[c] = 3 * (E[p][q1][c] - E[p][q0][c]);
            for (int c = 0; c < N; c++) cr1 += v[c] * r1[c], cr2 += v[c] * r2[c];
            Chod = fmax(Chod, fabs(cr1) + fabs(cr2));
            for (int k = 0; k <= 160; k++) {
                double sc = pow(lam, -k);
                for (int c = 0; c < N; c++) omega[c] = fmax(omega[c], fabs(v[c]) * sc);
                for (int c = 0; c < N; c++) {
                    double sum = 0;
                    for (int q = 0; q < N; q++) sum += v[q] * B[q][c];
                    t[c] = sum;
                }
                memcpy(v, t, sizeof t);
            }
        }
    double osum = 0;
    for (int c = 0; c < N; c++) osum += omega[c];
    double Jlow[4];
    for (int g = 0; g < 4; g++) {
        Jlow[g] = INFINITY;
        for (int p = 0; p < 3; p++) {
            double net[16][2];
            for (int q = 0; q < 16; q++) {
                net[q][0] = net[q][1] = 0;
                for (int c = 0; c < N; c++)
                    net[q][0] += E[p][q][c] * r1[c], net[q][1] += E[p][q][c] * r2[c];
            }
            Jlow[g] = fmin(Jlow[g], jac_low((const double(*)[2])net, 1 << g, Jmax < 0 ? -1 : 1));
        }
    }
    double Jbest = fmax(fmax(Jlow[0], Jlow[1]), fmax(Jlow[2], Jlow[3]));
    printf("valence %d: lambda %.6f (|det A|^1/2 %.6f, A = [%.2e %.2e; %.2e %.2e] - lambda I)\n", n,
           lam, lamA, A[0][0] - lam, A[0][1], A[1][0], A[1][1] - lam);
    printf("  |E|, |F| <= %.1e, %.1e (max entries); ||B^k||/lambda^k <= 1/2 from k = %d\n", Emax,
           Fmax, khalf);
    printf("  sum of omega %.3f (crude: 6 gamma = %.3f), C from hodographs %.3f\n", osum, 6 * gamma,
           Chod);
    printf("  |J| >= %.4f / %.4f / %.4f / %.4f (Bernstein, 1 / 2x2 / 4x4 / 8x8 pieces; sampled "
           "%.4f)\n",
           Jlow[0], Jlow[1], Jlow[2], Jlow[3], Jmax < 0 ? -Jmax : Jmin);
    printf("  gamma = sup ||B^k||/lambda^k = %.3f at k = %d (at k = 400: %.2e); J in [%.4f, %.4f], "
           "C_max %.3f\n",
           gamma, kmax, rowmax, Jmin, Jmax, Cmax);
    /* the bumpy 3D ring's levels: bound against sampled angles */
    printf("  level  bound (deg)  sampled (deg)  bound/sampled\n");
    for (int j = 0; j <= 22; j++) {
        /* T = L^T X, Y = Q X, ymax */
        double t1[3] = {0, 0, 0}, t2[3] = {0, 0, 0}, w[3], ymax = 0;
        for (int c = 0; c < N; c++)
            for (int k = 0; k < 3; k++) t1[k] += L1[c] * X[c][k], t2[k] += L2[c] * X[c][k];
        for (int r = 0; r < N; r++) {
            for (int k = 0; k < 3; k++) {
                double s = 0;
                for (int c = 0; c < N; c++) s += Q[r][c] * X[c][k];
                Y[r][k] = s;
            }
            ymax = fmax(ymax, norm3(Y[r]));
        }
        cross(t1, t2, w);
        if (Jmax < 0)
            for (int k = 0; k < 3; k++) w[k] = -w[k];
        double e = 0;
        for (int r = 0; r < N; r++) e += omega[r] * norm3(Y[r]);
        (void)gamma;
        if (getenv("EV_CRUDE")) e = 6 * gamma * ymax;
        double rho = (2 * Chod * fmax(norm3(t1), norm3(t2)) * e + e * e) / (Jbest * norm3(w));
        double bound = rho < 1 ? asin(rho) * 180 / M_PI : 90;
        /* sampled: patches E_p S^k X for k = 0..30 */
        double worst = 0;
        memcpy(Xk, X, sizeof Xk);
        for (int k = 0; k <= 30; k++) {
            for (int p = 0; p < 3; p++) {
                double net[16][3];
                for (int q = 0; q < 16; q++)
                    for (int d = 0; d < 3; d++) {
                        double s = 0;
                        for (int c = 0; c < N; c++) s += E[p][q][c] * Xk[c][d];
                        net[q][d] = s;
                    }
                for (int a = 0; a <= 8; a++)
                    for (int b = 0; b <= 8; b++) {
                        double du[3], dv[3], ng[3];
                        bez_d((const double(*)[3])net, 3, a / 8., b / 8., du, dv);
                        cross(du, dv, ng);
                        double cr[3];
                        cross(ng, w, cr);
                        double ang = atan2(norm3(cr), ng[0] * w[0] + ng[1] * w[1] + ng[2] * w[2]);
                        worst = fmax(worst, ang * 180 / M_PI);
                    }
            }
            double Z[NMAX][3];
            for (int r = 0; r < N; r++)
                for (int d = 0; d < 3; d++) {
                    double s = 0;
                    for (int c = 0; c < N; c++) s += S[r][c] * Xk[c][d];
                    Z[r][d] = s;
                }
            center(Z);
            memcpy(Xk, Z, sizeof Z);
        }
        printf("  %5d  %11.3e  %13.3e  %8.1f%s\n", j, bound, worst, bound / worst,
               worst > bound ? "  VIOLATION" : "");
        double Z[NMAX][3];
        for (int r = 0; r < N; r++)
            for (int d = 0; d < 3; d++) {
                double s = 0;
                for (int c = 0; c < N; c++) s += S[r][c] * X[c][d];
                Z[r][d] = s;
            }
        center(Z);
        memcpy(X, Z, sizeof Z);
    }
}

int main(int argc, char **argv)
{
    int vals[] = {3, 5, 6, 8};
    if (argc > 1)
        for (int a = 1; a < argc; a++) study(atoi(argv[a]));
    else
        for (int q = 0; q < 4; q++) study(vals[q]);
    return 0;
}

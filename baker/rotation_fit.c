/* SPDX-License-Identifier: MIT */
/* The rotation that best maps one point set onto another (rotation_fit.h): Horn's quaternion
 * method, solved in closed form with a Jacobi fallback. */
#include <math.h>
#include <string.h>
#include "rotation_fit.h"

/* Largest-eigenvalue eigenvector of a symmetric 4x4 matrix by cyclic Jacobi rotations. */
static void eigen_max4(double A[4][4], double q[4])
{
    double V[4][4] = { { 1, 0, 0, 0 }, { 0, 1, 0, 0 }, { 0, 0, 1, 0 }, { 0, 0, 0, 1 } };
    for (int sweep = 0; sweep < 20; sweep++) {
        double off = 0, diag = 0;
        for (int i = 0; i < 4; i++) {
            diag += A[i][i] * A[i][i];
            for (int j = i + 1; j < 4; j++) off += A[i][j] * A[i][j];
        }
        if (off <= 1e-30 * diag || off == 0) break;
        for (int p = 0; p < 3; p++)
            for (int r = p + 1; r < 4; r++) {
                if (A[p][r] == 0) continue;
                double theta = (A[r][r] - A[p][p]) / (2 * A[p][r]);
                double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 4; k++) {
                    double akp = A[k][p], akr = A[k][r];
                    A[k][p] = c * akp - s * akr;
                    A[k][r] = s * akp + c * akr;
                }
                for (int k = 0; k < 4; k++) {
                    double apk = A[p][k], ark = A[r][k];
                    A[p][k] = c * apk - s * ark;
                    A[r][k] = s * apk + c * ark;
                }
                for (int k = 0; k < 4; k++) {
                    double vkp = V[k][p], vkr = V[k][r];
                    V[k][p] = c * vkp - s * vkr;
                    V[k][r] = s * vkp + c * vkr;
                }
            }
    }
    int best = 0;
    for (int i = 1; i < 4; i++) if (A[i][i] > A[best][best]) best = i;
    for (int k = 0; k < 4; k++) q[k] = V[k][best];
}

/* Horn's symmetric 4x4 matrix of S: its top eigenvector is the quaternion of the rotation
 * maximizing tr(R S). */
static void horn_matrix(const double S[9], double N[4][4])
{
    double sxx = S[0], sxy = S[1], sxz = S[2], syx = S[3], syy = S[4], syz = S[5],
           szx = S[6], szy = S[7], szz = S[8];
    double m[4][4] = {
        { sxx + syy + szz, syz - szy, szx - sxz, sxy - syx },
        { syz - szy, sxx - syy - szz, sxy + syx, szx + sxz },
        { szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy },
        { sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz },
    };
    memcpy(N, m, sizeof m);
}

/* Row-major rotation of quaternion q = (w, x, y, z), normalized here; identity if q is 0. */
static void quaternion_rotation(const double q[4], double R[9])
{
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(l > 0)) { memset(R, 0, 9 * sizeof(double)); R[0] = R[4] = R[8] = 1; return; }
    double w = q[0] / l, x = q[1] / l, y = q[2] / l, z = q[3] / l;
    R[0] = 1 - 2 * (y * y + z * z); R[1] = 2 * (x * y - w * z);     R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z);     R[4] = 1 - 2 * (x * x + z * z); R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y);     R[7] = 2 * (y * z + w * x);     R[8] = 1 - 2 * (x * x + y * y);
}

/* Rotation R (row-major) maximizing tr(R S) for S = sum w e e'^T (rest e, deformed e'). */
static void best_rotation(const double S[9], double R[9])
{
    double N[4][4];
    horn_matrix(S, N);
    double q[4];
    eigen_max4(N, q);
    quaternion_rotation(q, R);
}

static double det3(double a, double b, double c, double d, double e, double f, double g, double h,
                   double i)
{
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
}

/* Rotation maximizing tr(R S): Horn's 4x4 matrix N, its largest eigenvalue by Newton's method on
 * the characteristic polynomial (Theobald's QCP, Acta Cryst. A 2005), the eigenvector from the
 * adjugate of N - lambda I. About 500 flops instead of a Jacobi eigensolve; degenerate cases
 * (a repeated top eigenvalue, e.g. a vertex whose one-ring collapsed) use the Jacobi solver. */
void bake_fit_rotation(const double S[9], double R[9])
{
    double N[4][4];
    horn_matrix(S, N);
    /* N is symmetric and traceless: det(lambda I - N) = l^4 + c2 l^2 + c1 l + c0 with
     * c2 = -tr(N^2)/2, c1 = -tr(N^3)/3, c0 = det N (Newton's identities). */
    double N2[4][4], p2 = 0, p3 = 0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double acc = 0;
            for (int k = 0; k < 4; k++) acc += N[i][k] * N[k][j];
            N2[i][j] = acc;
        }
    for (int i = 0; i < 4; i++) {
        p2 += N2[i][i];
        for (int k = 0; k < 4; k++) p3 += N2[i][k] * N[k][i];
    }
    if (!(p2 > 1e-300)) { memset(R, 0, 9 * sizeof(double)); R[0] = R[4] = R[8] = 1; return; }
    double det = 0;
    /* determinant by expansion along the first row */
    {
        int c[4][3] = { { 1, 2, 3 }, { 0, 2, 3 }, { 0, 1, 3 }, { 0, 1, 2 } };
        for (int j = 0; j < 4; j++) {
            double m = det3(N[1][c[j][0]], N[1][c[j][1]], N[1][c[j][2]], N[2][c[j][0]], N[2][c[j][1]],
                            N[2][c[j][2]], N[3][c[j][0]], N[3][c[j][1]], N[3][c[j][2]]);
            det += (j & 1 ? -1 : 1) * N[0][j] * m;
        }
    }
    double c2 = -0.5 * p2, c1 = -p3 / 3, c0 = det;
    /* sqrt(tr N^2) bounds every |eigenvalue|: Newton from above converges to the largest root. */
    double l = sqrt(p2);
    for (int it = 0; it < 60; it++) {
        double l2 = l * l;
        double P = (l2 + c2) * l2 + c1 * l + c0, dP = 4 * l2 * l + 2 * c2 * l + c1;
        if (!(fabs(dP) > 1e-300)) break;
        double step = P / dP;
        l -= step;
        if (fabs(step) < 1e-13 * sqrt(p2)) break;
    }
    /* Eigenvector: the largest column of adj(N - l I). */
    double M[4][4];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) M[i][j] = N[i][j] - (i == j ? l : 0);
    int c[4][3] = { { 1, 2, 3 }, { 0, 2, 3 }, { 0, 1, 3 }, { 0, 1, 2 } };
    double best[4] = { 0, 0, 0, 0 }, best_norm = 0;
    for (int row = 0; row < 4; row++) {
        /* cofactors C[row][j] for j = 0..3 (the adjugate is symmetric here) */
        const int *r = c[row];
        double v[4];
        for (int j = 0; j < 4; j++) {
            const int *k = c[j];
            double m = det3(M[r[0]][k[0]], M[r[0]][k[1]], M[r[0]][k[2]], M[r[1]][k[0]], M[r[1]][k[1]],
                            M[r[1]][k[2]], M[r[2]][k[0]], M[r[2]][k[1]], M[r[2]][k[2]]);
            v[j] = ((row + j) & 1 ? -1 : 1) * m;
        }
        double nv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3];
        if (nv > best_norm) { best_norm = nv; memcpy(best, v, sizeof best); }
    }
    /* |adj| ~ product of the 3 other eigenvalue gaps; tiny means a repeated top eigenvalue. */
    if (!(sqrt(best_norm) > 1e-9 * p2 * sqrt(p2))) {
        best_rotation(S, R);
        return;
    }
    quaternion_rotation(best, R);
}

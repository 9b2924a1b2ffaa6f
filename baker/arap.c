/* SPDX-License-Identifier: MIT */
/* As-rigid-as-possible surface deformation, local/global iterations on the factored Laplacian.
 *
 * Papers:
 * - O. Sorkine, M. Alexa, "As-Rigid-As-Possible Surface Modeling", SGP 2007: energy
 *   sum_i sum_j w_ij |(p'_i - p'_j) - R_i (p_i - p_j)|^2 with cotangent weights, alternating
 *   the local step (best rotation per one-ring) and the global step
 *   L p' = b, b_i = sum_j w_ij/2 (R_i + R_j)(p_i - p_j).
 * - B. K. P. Horn, "Closed-form solution of absolute orientation using unit quaternions",
 *   JOSA A 1987: the rotation maximizing tr(R S) is the quaternion of the top eigenvector of
 *   a symmetric 4x4 matrix built from S. Always a proper rotation (no reflection fix-up as
 *   with the SVD), fine for rank-deficient S (flat one-rings).
 * - D. L. Theobald, "Rapid calculation of RMSDs using a quaternion-based characteristic
 *   polynomial", Acta Cryst. A 2005 (QCP): that eigenvalue by Newton's method on the quartic,
 *   the eigenvector from the adjugate; Jacobi rotations only for degenerate cases.
 * Local step: R_i maximizes tr(R_i S_i), S_i = sum_j w_ij e_ij e'_ij^T (rest e, deformed e'),
 * i.e. A = S_i^T.
 *
 * Conventions fixed here:
 * - L is the cotangent (or uniform) Laplacian with a positive diagonal (L_ii = sum_j w_ij,
 *   L_ij = -w_ij), so constants span its kernel; it does not change between iterations or
 *   amplitudes: one analyze + factorize per bake (laplacian.c), 3 right-hand sides per solve.
 * - Initial guess: the global step with every R_i = I (the naive Laplacian solution with the
 *   handles in place); then params.iterations local/global rounds (default 10, as libigl).
 * - Hard constraints are eliminated; soft ones add w^2 (p' - c) to the energy.
 */
#include <math.h>
#include <string.h>
#include "surface_edit_internal.h"
#include "bake_util.h"

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

/* Global step: rhs from the rotations (NULL = identity), solve, write s->solution. */
static mk_result global_step(mk_surface_edit *s, int identity, mk_error *err)
{
    uint32_t n = s->welded, nu = s->unknown_count;
    if (nu == 0) {
        memcpy(s->solution, s->target, 3 * (size_t)n * sizeof(double));
        return MK_OK;
    }
    double *b = s->spd.rhs->x;
    memset(b, 0, 3 * (size_t)nu * sizeof(double));
    double w2 = s->params.soft ? s->params.soft_weight * s->params.soft_weight : 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t u = s->unknown[i];
        if (u == UINT32_MAX) continue;
        const double *pi = s->rest + 3 * (size_t)i;
        double acc[3] = { 0, 0, 0 };
        for (uint32_t k = s->offsets[i]; k < s->offsets[i + 1]; k++) {
            uint32_t j = s->neighbors[k];
            double w = s->edge_weights[k];
            const double *pj = s->rest + 3 * (size_t)j;
            double e[3] = { pi[0] - pj[0], pi[1] - pj[1], pi[2] - pj[2] }, r[3];
            if (identity) { r[0] = e[0]; r[1] = e[1]; r[2] = e[2]; }
            else {
                double Rs[9];
                const double *Ri = s->rotations + 9 * (size_t)i, *Rj = s->rotations + 9 * (size_t)j;
                for (int q = 0; q < 9; q++) Rs[q] = 0.5 * (Ri[q] + Rj[q]);
                mat3_mul_vec(r, Rs, e);
            }
            for (int c = 0; c < 3; c++) acc[c] += w * r[c];
            /* Hard constraints: move the known column to the right-hand side. */
            if (s->unknown[j] == UINT32_MAX)
                for (int c = 0; c < 3; c++) acc[c] += w * s->target[3 * (size_t)j + c];
        }
        if (w2 > 0 && s->constraint[i] >= 0)
            for (int c = 0; c < 3; c++) acc[c] += w2 * s->target[3 * (size_t)i + c];
        for (int c = 0; c < 3; c++) b[(size_t)c * nu + u] = acc[c];
    }
    mk_result r = edit_solve(s, err);
    if (r != MK_OK) return r;
    const double *x = s->spd.x->x;
    for (uint32_t v = 0; v < n; v++)
        for (int c = 0; c < 3; c++) {
            size_t i = 3 * (size_t)v + (size_t)c;
            s->solution[i] = s->unknown[v] != UINT32_MAX ? x[(size_t)c * nu + s->unknown[v]] : s->target[i];
        }
    return MK_OK;
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
static void fit_rotation(const double S[9], double R[9])
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

/* Local step: R_i for the current positions. Returns the ARAP energy of those positions with
 * those rotations, E = sum_i sum_j w_ij |f_ij - R_i e_ij|^2 (+ 2 w^2 |p' - c|^2 per soft
 * constraint, the factor that makes the global step its exact minimizer), from
 * |f - R e|^2 = |e|^2 + |f|^2 - 2 f.(R e) and sum_j w_ij f.(R e) = tr(R_i S_i); *scale gets
 * sum w (|e|^2 + |f|^2), the size of the rounding error of E. */
static double local_step(mk_surface_edit *s, double *scale)
{
    double energy = 0, magnitude = 0;
    for (uint32_t i = 0; i < s->welded; i++) {
        double S[9] = { 0 }, squares = 0;
        const double *pi = s->rest + 3 * (size_t)i, *qi = s->solution + 3 * (size_t)i;
        for (uint32_t k = s->offsets[i]; k < s->offsets[i + 1]; k++) {
            uint32_t j = s->neighbors[k];
            double w = s->edge_weights[k];
            const double *pj = s->rest + 3 * (size_t)j, *qj = s->solution + 3 * (size_t)j;
            double e[3] = { pi[0] - pj[0], pi[1] - pj[1], pi[2] - pj[2] };
            double f[3] = { qi[0] - qj[0], qi[1] - qj[1], qi[2] - qj[2] };
            squares += w * (vec3_dot(e, e) + vec3_dot(f, f));
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++) S[3 * a + c] += w * e[a] * f[c];
        }
        double *R = s->rotations + 9 * (size_t)i;
        fit_rotation(S, R);
        double trace = 0;
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) trace += R[3 * c + a] * S[3 * a + c];
        energy += squares - 2 * trace;
        magnitude += squares;
    }
    if (s->params.soft) {
        double w2 = s->params.soft_weight * s->params.soft_weight;
        for (uint32_t i = 0; i < s->welded; i++) {
            if (s->constraint[i] < 0) continue;
            double d[3];
            vec3_sub(d, s->solution + 3 * (size_t)i, s->target + 3 * (size_t)i);
            energy += 2 * w2 * vec3_dot(d, d);
        }
    }
    *scale = magnitude;
    return energy > 0 ? energy : 0;
}

static double dot(const double *a, const double *b, size_t n)
{
    double acc = 0;
    for (size_t i = 0; i < n; i++) acc += a[i] * b[i];
    return acc;
}

/* Anderson mixing coefficients: theta minimizing |f - sum_j theta_j dF_j| from the normal
 * equations G theta = dF^T f (G = dF^T dF, m <= EDIT_ANDERSON_HISTORY), Cholesky with a small
 * ridge. Returns 0 when G is too ill-conditioned to trust (the caller takes the plain step). */
static int anderson_coefficients(double G[EDIT_ANDERSON_HISTORY][EDIT_ANDERSON_HISTORY],
                                 const double *rhs, uint32_t m, double *theta)
{
    double L[EDIT_ANDERSON_HISTORY][EDIT_ANDERSON_HISTORY], y[EDIT_ANDERSON_HISTORY];
    double ridge = 0;
    for (uint32_t a = 0; a < m; a++) ridge += G[a][a];
    ridge *= 1e-10 / m;
    for (uint32_t a = 0; a < m; a++)
        for (uint32_t b = 0; b <= a; b++) {
            double v = G[a][b] + (a == b ? ridge : 0);
            for (uint32_t k = 0; k < b; k++) v -= L[a][k] * L[b][k];
            if (a == b) {
                if (!(v > 1e-300)) return 0;
                L[a][a] = sqrt(v);
            } else L[a][b] = v / L[b][b];
        }
    for (uint32_t a = 0; a < m; a++) {
        double v = rhs[a];
        for (uint32_t k = 0; k < a; k++) v -= L[a][k] * y[k];
        y[a] = v / L[a][a];
    }
    for (uint32_t a = m; a-- > 0;) {
        double v = y[a];
        for (uint32_t k = a + 1; k < m; k++) v -= L[k][a] * theta[k];
        theta[a] = v / L[a][a];
    }
    for (uint32_t a = 0; a < m; a++)
        if (!isfinite(theta[a])) return 0;
    return 1;
}

/* Local/global iterations from the global step with identity rotations, as a fixed-point map
 * x -> G(x) = global(local(x)) on the stacked positions (constrained entries are constant).
 * Plain: x_{k+1} = G(x_k); each iteration cannot raise the energy (both steps minimize it).
 * Anderson (H. Peng, J. Deng, J. Zhou, J. Liu, "Anderson Acceleration for Geometry
 * Optimization and Physics Simulation", SIGGRAPH 2018): with f_k = G(x_k) - x_k and the last m
 * differences dF, dG of f and G, x_{k+1} = G(x_k) - dG theta with theta = argmin
 * |f_k - dF theta|; if the energy at x_{k+1} exceeds the energy at x_k, x_{k+1} = G(x_k)
 * instead (the plain step, whose energy cannot be higher) and the history restarts, so the
 * accepted energies decrease monotonically either way.
 * Stops when an iteration lowers the energy by no more than params.convergence times the
 * previous energy (or the energy is at the rounding level, 1e-14 of its terms), or after
 * params.iterations global steps. */
mk_result edit_arap_solve(mk_surface_edit *s, mk_error *err)
{
    const size_t n3 = 3 * (size_t)s->welded;
    const uint32_t cap = s->params.iterations, window = EDIT_ANDERSON_HISTORY;
    const double tolerance = s->params.convergence;
    mk_result r = global_step(s, 1, err);
    if (r != MK_OK) return r;
    double *x = s->solution, *previous = s->work;
    double *g_prev = NULL, *f_prev = NULL, *dF = NULL, *dG = NULL;
    if (s->anderson) {
        g_prev = s->anderson;
        f_prev = g_prev + n3;
        dF = f_prev + n3;
        dG = dF + window * n3;
    }
    double gram[EDIT_ANDERSON_HISTORY][EDIT_ANDERSON_HISTORY];
    uint32_t history = 0, head = 0, it = 0;
    int accelerated = 0;
    double energy_prev = INFINITY, energy = 0;
    for (;; it++) {
        double t0 = bake_now(), scale;
        energy = local_step(s, &scale);
        if (accelerated && !(energy <= energy_prev)) {
            memcpy(x, g_prev, n3 * sizeof(double));
            energy = local_step(s, &scale);
            history = 0;
            s->stats.rejected_steps++;
        }
        s->local_seconds += bake_now() - t0;
        if (it == 0) s->stats.start_energy = energy;
        if (s->params.iteration_done) s->params.iteration_done(s->params.user, it, energy);
        if (energy <= 1e-14 * scale) break;
        if (it > 0 && tolerance >= 0 && energy_prev - energy <= tolerance * energy_prev) break;
        if (it == cap) { s->stats.unconverged++; break; }
        energy_prev = energy;
        if (s->anderson) memcpy(previous, x, n3 * sizeof(double));
        if ((r = global_step(s, 0, err)) != MK_OK) return r;
        accelerated = 0;
        if (!s->anderson) continue;
        /* x now holds G(previous). New differences into slot head of the ring. */
        t0 = bake_now();
        double *df = dF + head * n3, *dg = dG + head * n3;
        for (size_t i = 0; i < n3; i++) {
            double f = x[i] - previous[i];
            if (it > 0) { df[i] = f - f_prev[i]; dg[i] = x[i] - g_prev[i]; }
            f_prev[i] = f;
            g_prev[i] = x[i];
        }
        if (it == 0) continue;  /* the plain first step: no differences yet */
        if (history < window) history++;
        for (uint32_t a = 0; a < history; a++) {
            uint32_t slot = (head + window - a) % window;
            double v = dot(df, dF + slot * n3, n3);
            gram[head][slot] = gram[slot][head] = v;
        }
        /* Work in ring order; theta per slot. */
        double Gm[EDIT_ANDERSON_HISTORY][EDIT_ANDERSON_HISTORY], rhs[EDIT_ANDERSON_HISTORY],
               theta[EDIT_ANDERSON_HISTORY];
        uint32_t slots[EDIT_ANDERSON_HISTORY];
        for (uint32_t a = 0; a < history; a++) slots[a] = (head + window - a) % window;
        for (uint32_t a = 0; a < history; a++) {
            rhs[a] = dot(dF + slots[a] * n3, f_prev, n3);
            for (uint32_t b = 0; b < history; b++) Gm[a][b] = gram[slots[a]][slots[b]];
        }
        head = (head + 1) % window;
        if (!anderson_coefficients(Gm, rhs, history, theta)) { history = 0; continue; }
        for (uint32_t a = 0; a < history; a++) {
            const double *col = dG + slots[a] * n3;
            for (size_t i = 0; i < n3; i++) x[i] -= theta[a] * col[i];
        }
        accelerated = 1;
        s->local_seconds += bake_now() - t0;
    }
    s->stats.evaluations++;
    s->stats.iterations += it;
    if (it > s->stats.max_iterations) s->stats.max_iterations = it;
    s->stats.energy = energy;
    return MK_OK;
}

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
 *   handles in place); then L-BFGS (the default), Anderson-accelerated or plain local/global
 *   iterations until the energy stops falling by more than params.convergence, at most
 *   params.iterations.
 * - Hard constraints are eliminated; soft ones add w^2 (p' - c) to the energy.
 */
#include <math.h>
#include <string.h>
#include "surface_edit_internal.h"
#include "bake_util.h"
#include "rotation_fit.h"

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
    return edit_solve_positions(s, s->target, NULL, err);
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
        bake_fit_rotation(S, R);
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

/* Gradient of E/4 at the current positions with the current rotations, per unknown (layout of
 * the solve: column c, row u): g_i = sum_j w_ij (f_ij - (R_i + R_j)/2 e_ij) + w^2 (p'_i - c_i).
 * The global step solves g = 0 for fixed rotations, so A^-1 g (A the factored matrix) is the
 * plain step's displacement, reversed. */
static void gradient(const mk_surface_edit *s, double *g)
{
    const uint32_t nu = s->unknown_count;
    const double w2 = s->params.soft ? s->params.soft_weight * s->params.soft_weight : 0;
    for (uint32_t i = 0; i < s->welded; i++) {
        uint32_t u = s->unknown[i];
        if (u == UINT32_MAX) continue;
        const double *pi = s->rest + 3 * (size_t)i, *qi = s->solution + 3 * (size_t)i, *Ri = s->rotations + 9 * (size_t)i;
        double acc[3] = { 0, 0, 0 };
        for (uint32_t k = s->offsets[i]; k < s->offsets[i + 1]; k++) {
            uint32_t j = s->neighbors[k];
            double w = s->edge_weights[k], Rs[9], r[3];
            const double *pj = s->rest + 3 * (size_t)j, *qj = s->solution + 3 * (size_t)j, *Rj = s->rotations + 9 * (size_t)j;
            double e[3] = { pi[0] - pj[0], pi[1] - pj[1], pi[2] - pj[2] };
            for (int q = 0; q < 9; q++) Rs[q] = 0.5 * (Ri[q] + Rj[q]);
            mat3_mul_vec(r, Rs, e);
            for (int c = 0; c < 3; c++) acc[c] += w * ((qi[c] - qj[c]) - r[c]);
        }
        if (w2 > 0 && s->constraint[i] >= 0)
            for (int c = 0; c < 3; c++) acc[c] += w2 * (qi[c] - s->target[3 * (size_t)i + c]);
        for (int c = 0; c < 3; c++) g[(size_t)c * nu + u] = acc[c];
    }
}

/* Adds t * d (solve layout) to the unknown positions. */
static void move_unknowns(mk_surface_edit *s, const double *base, const double *d, double t)
{
    const uint32_t nu = s->unknown_count;
    for (uint32_t v = 0; v < s->welded; v++) {
        uint32_t u = s->unknown[v];
        if (u == UINT32_MAX) continue;
        for (int c = 0; c < 3; c++)
            s->solution[3 * (size_t)v + c] = base[3 * (size_t)v + c] + t * d[(size_t)c * nu + u];
    }
}

/* L-BFGS (J. Nocedal, "Updating quasi-Newton matrices with limited storage", Math. Comp. 1980)
 * on E(x) = min_R E(x, R), whose gradient is 4 g (the rotations are optimal, so they do not
 * contribute), with the factored A as the initial Hessian of E/4 (T. Liu, S. Bouaziz, L. Kavan,
 * "Quasi-Newton Methods for Real-Time Simulation of Hyperelastic Materials", ACM TOG 2017): with
 * no history the direction is exactly the plain local/global step; the curvature pairs turn it
 * towards the energy's valleys that the plain step crosses slowly. Armijo backtracking from the
 * full step (halving, at most 8 times; if none descends, the plain step, which cannot raise the
 * energy, and the history restarts). Stops as edit_arap_solve. */
static mk_result arap_lbfgs(mk_surface_edit *s, mk_error *err)
{
    const uint32_t nu = s->unknown_count, m = EDIT_LBFGS_HISTORY, cap = s->params.iterations;
    const size_t n3 = 3 * (size_t)s->welded, u3 = 3 * (size_t)nu;
    const double tolerance = s->params.convergence;
    mk_result r = global_step(s, 1, err);
    if (r != MK_OK) return r;
    double *x_prev = s->work;                    /* welded layout */
    double *g = s->anderson, *g_new = g + n3, *d = g_new + n3, *q = d + n3;
    double *S = q + n3, *Y = S + m * n3;         /* pairs, solve layout */
    double rho[EDIT_LBFGS_HISTORY], alpha[EDIT_LBFGS_HISTORY];
    uint32_t history = 0, head = 0, it = 0;
    double scale, t0 = bake_now();
    double energy = local_step(s, &scale), energy_prev = INFINITY;
    s->local_seconds += bake_now() - t0;
    s->stats.start_energy = energy;
    gradient(s, g);
    for (;; it++) {
        if (s->params.iteration_done) s->params.iteration_done(s->params.user, it, energy);
        if (energy <= 1e-14 * scale || nu == 0) break;
        if (it > 0 && tolerance >= 0 && energy_prev - energy <= tolerance * energy_prev) break;
        if (it == cap) { s->stats.unconverged++; break; }
        /* Two-loop recursion: d = -H g, H0 = A^-1 (one solve). */
        memcpy(q, g, u3 * sizeof(double));
        for (uint32_t k = 0; k < history; k++) {
            uint32_t slot = (head + m - 1 - k) % m;
            alpha[slot] = rho[slot] * dot(S + slot * n3, q, u3);
            const double *y = Y + slot * n3;
            for (size_t i = 0; i < u3; i++) q[i] -= alpha[slot] * y[i];
        }
        memcpy(s->spd.rhs->x, q, u3 * sizeof(double));
        if ((r = edit_solve(s, err)) != MK_OK) return r;
        memcpy(d, s->spd.x->x, u3 * sizeof(double));
        for (uint32_t k = history; k-- > 0;) {
            uint32_t slot = (head + m - 1 - k) % m;
            double beta = rho[slot] * dot(Y + slot * n3, d, u3);
            const double *sv = S + slot * n3;
            for (size_t i = 0; i < u3; i++) d[i] += (alpha[slot] - beta) * sv[i];
        }
        for (size_t i = 0; i < u3; i++) d[i] = -d[i];
        double slope = dot(g, d, u3);            /* of E/4 along d */
        memcpy(x_prev, s->solution, n3 * sizeof(double));
        double step = 1, trial = INFINITY;      /* step: the fraction of d tried */
        int found = 0;
        t0 = bake_now();
        if (slope < 0)
            for (int tries = 0; tries < 8 && !found; tries++, step *= 0.5) {
                move_unknowns(s, x_prev, d, step);
                trial = local_step(s, &scale);
                found = trial / 4 <= energy / 4 + 1e-4 * step * slope;
            }
        s->local_seconds += bake_now() - t0;
        if (!found) {
            /* The plain step from x_prev: rotations of x_prev, one global solve. */
            memcpy(s->solution, x_prev, n3 * sizeof(double));
            local_step(s, &scale);
            if ((r = global_step(s, 0, err)) != MK_OK) return r;
            t0 = bake_now();
            trial = local_step(s, &scale);
            s->local_seconds += bake_now() - t0;
            history = 0;
            s->stats.rejected_steps++;
        }
        gradient(s, g_new);
        /* The new pair: s = x - x_prev, y = g_new - g (solve layout); kept when y.s > 0. */
        double *sv = S + head * n3, *yv = Y + head * n3;
        for (uint32_t v = 0; v < s->welded; v++) {
            uint32_t u = s->unknown[v];
            if (u == UINT32_MAX) continue;
            for (int c = 0; c < 3; c++)
                sv[(size_t)c * nu + u] = s->solution[3 * (size_t)v + c] - x_prev[3 * (size_t)v + c];
        }
        for (size_t i = 0; i < u3; i++) yv[i] = g_new[i] - g[i];
        double ys = dot(yv, sv, u3);
        if (ys > 1e-12 * dot(yv, yv, u3)) {
            rho[head] = 1 / ys;
            head = (head + 1) % m;
            if (history < m) history++;
        }
        memcpy(g, g_new, u3 * sizeof(double));
        energy_prev = energy;
        energy = trial;
    }
    s->stats.evaluations++;
    s->stats.iterations += it;
    if (it > s->stats.max_iterations) s->stats.max_iterations = it;
    s->stats.energy = energy;
    return MK_OK;
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
    if (s->params.acceleration == MK_ARAP_LBFGS) return arap_lbfgs(s, err);
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

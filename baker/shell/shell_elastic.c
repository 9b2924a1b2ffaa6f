/* SPDX-License-Identifier: MIT */
/* In-plane (membrane) elasticity of one triangle: the deformation gradient F (3x2) from a 2D rest
 * frame, four materials psi(F) with their stress P = dpsi/dF, and the element gradient
 * area * P Dm^-T. C = F^T F is 2x2; E = (C - I)/2.
 *
 * - StVK: psi = mu tr(E^2) + (lambda/2) tr(E)^2, P = F (2 mu E + lambda tr(E) I).
 * - Corotated linear: S = sqrt(C), R = F S^-1 (polar decomposition with R 3x2 orthonormal);
 *   psi = mu |S - I|^2 + (lambda/2) tr(S - I)^2, P = 2 mu (F - R) + lambda tr(S - I) R.
 * - Linear: the displacement gradient projected on the rest axes B = [e1 e2]:
 *   eps = sym(B^T F) - I, psi = mu eps:eps + (lambda/2) tr(eps)^2, P = B (2 mu eps + lambda tr(eps) I).
 *   Not rotation invariant (small strains only).
 * - Mooney-Rivlin (compressible, 2D invariants I1 = tr C, I2 = det C = J^2, C10 = C01 = mu/4):
 *   psi = C10 (I1 - 2) + C01 (I2 - 1) - 2 (C10 + C01) ln J + (lambda/2) (ln J)^2,
 *   P = 2 C10 F + 2 C01 F adj(C) + (lambda ln J - 2 (C10 + C01)) F C^-1.
 */
#include <math.h>
#include <string.h>
#include "shell.h"
#include "bake_util.h"

void shell_deformation_gradient(const double *x0, const double *x1, const double *x2,
                                const double Dm_inv[4], double F[6])
{
    for (int c = 0; c < 3; c++) {
        double d1 = x1[c] - x0[c], d2 = x2[c] - x0[c];
        F[c] = d1 * Dm_inv[0] + d2 * Dm_inv[2];
        F[3 + c] = d1 * Dm_inv[1] + d2 * Dm_inv[3];
    }
}

void shell_gradient_from_stress(const double P[6], const double Dm_inv[4], double area, double grad[9])
{
    for (int c = 0; c < 3; c++) {
        /* (P Dm^-T)[c][j] = sum_k P[c][k] Dm_inv[j][k] */
        double g1 = area * (P[c] * Dm_inv[0] + P[3 + c] * Dm_inv[1]);
        double g2 = area * (P[c] * Dm_inv[2] + P[3 + c] * Dm_inv[3]);
        grad[3 + c] = g1;
        grad[6 + c] = g2;
        grad[c] = -(g1 + g2);
    }
}

/* P = F S for a 2x2 S (row-major). */
static void f_times(const double F[6], const double S[4], double P[6])
{
    for (int c = 0; c < 3; c++) {
        double a = F[c], b = F[3 + c];
        P[c] = a * S[0] + b * S[2];
        P[3 + c] = a * S[1] + b * S[3];
    }
}


/* Membrane energy density psi(F) and its first Piola-Kirchhoff stress P = dpsi/dF of the
 * corotated, linear and Mooney-Rivlin materials. F and P are 3x2, column-major (F[0..2] = first
 * column, F[3..5] = second). basis (6 doubles: the rest triangle's in-plane unit axes e1, e2) is
 * used by the linear material only. */
static double material_psi(shell_material material, double mu, double lambda, const double F[6], const double basis[6],
                           double P[6])
{
    double C[4] = { vec3_dot(F, F), vec3_dot(F, F + 3), 0, vec3_dot(F + 3, F + 3) };
    C[2] = C[1];
    switch (material) {
    case SHELL_STVK:   /* shell_stvk_batch (shell_membrane_energy goes there) */
        break;
    case SHELL_COROTATED: {
        double det = C[0] * C[3] - C[1] * C[2];
        double sd = sqrt(fmax(det, 0)), den = sqrt(C[0] + C[3] + 2 * sd);
        if (!(den > 1e-150) || !(sd > 1e-150)) {
            /* Collapsed triangle: no rotation to measure against; push it open along F. */
            for (int i = 0; i < 6; i++) P[i] = 2 * mu * F[i];
            return mu * 2 + 0.5 * lambda * 4;
        }
        double S[4] = { (C[0] + sd) / den, C[1] / den, C[2] / den, (C[3] + sd) / den };
        double dS = S[0] * S[3] - S[1] * S[2];
        double Si[4] = { S[3] / dS, -S[1] / dS, -S[2] / dS, S[0] / dS };
        double R[6];
        f_times(F, Si, R);
        double tr = S[0] + S[3] - 2;
        for (int i = 0; i < 6; i++) P[i] = 2 * mu * (F[i] - R[i]) + lambda * tr * R[i];
        double s00 = S[0] - 1, s11 = S[3] - 1;
        return mu * (s00 * s00 + 2 * S[1] * S[1] + s11 * s11) + 0.5 * lambda * tr * tr;
    }
    case SHELL_LINEAR: {
        /* G = B^T F (2x2, row-major: G[i][j] = e_i . F_j). */
        double G[4] = { vec3_dot(basis, F), vec3_dot(basis, F + 3), vec3_dot(basis + 3, F), vec3_dot(basis + 3, F + 3) };
        double e[4] = { G[0] - 1, 0.5 * (G[1] + G[2]), 0.5 * (G[1] + G[2]), G[3] - 1 };
        double tr = e[0] + e[3];
        double S[4] = { 2 * mu * e[0] + lambda * tr, 2 * mu * e[1], 2 * mu * e[2], 2 * mu * e[3] + lambda * tr };
        for (int c = 0; c < 3; c++) {
            /* P = B S: P[c][j] = sum_i e_i[c] S[i][j] */
            P[c] = basis[c] * S[0] + basis[3 + c] * S[2];
            P[3 + c] = basis[c] * S[1] + basis[3 + c] * S[3];
        }
        return mu * (e[0] * e[0] + 2 * e[1] * e[1] + e[3] * e[3]) + 0.5 * lambda * tr * tr;
    }
    case SHELL_MOONEY_RIVLIN: {
        double c10 = 0.25 * mu, c01 = 0.25 * mu;
        double det = C[0] * C[3] - C[1] * C[2];
        if (det < 1e-24) det = 1e-24;  /* collapsed: finite, strongly repelling */
        double lnJ = 0.5 * log(det);
        double adj[4] = { C[3], -C[1], -C[2], C[0] };
        double k = (lambda * lnJ - 2 * (c10 + c01)) / det;
        double S[4];
        for (int i = 0; i < 4; i++) S[i] = 2 * c01 * adj[i] + k * adj[i];
        S[0] += 2 * c10;
        S[3] += 2 * c10;
        f_times(F, S, P);
        return c10 * (C[0] + C[3] - 2) + c01 * (det - 1) - 2 * (c10 + c01) * lnJ + 0.5 * lambda * lnJ * lnJ;
    }
    }
    return 0;
}

double shell_membrane_energy(shell_material material, double mu, double lambda, const double Dm_inv[4],
                             const double basis[6], double area, const double *x0, const double *x1,
                             const double *x2, double grad[9])
{
    if (material == SHELL_STVK) {   /* the one StVK: the batched form, for one triangle */
        const double *xs[1][3] = { { x0, x1, x2 } };
        double W[1], g[1][12];
        shell_stvk_batch(mu, lambda, 1, xs, &Dm_inv, &area, W, g);
        memcpy(grad, g[0], 9 * sizeof(double));
        return W[0];
    }
    double F[6], P[6];
    shell_deformation_gradient(x0, x1, x2, Dm_inv, F);
    double psi = material_psi(material, mu, lambda, F, basis, P);
    shell_gradient_from_stress(P, Dm_inv, area, grad);
    return area * psi;
}

/* The StVK membrane (the formulas at the top) of up to SHELL_BATCH triangles at once, each stage
 * for all of them before the next, so that the triangles' independent chains interleave instead
 * of one triangle's multiplications waiting for the one before; each triangle's arithmetic does
 * not depend on the others (a batch gives what one triangle at a time gives, bit for bit). */
void shell_stvk_batch(double mu, double lambda, uint32_t count, const double *x[][3], const double *const Dm_inv[],
                      const double area[], double W[], double grad[][12])
{
    enum { B = SHELL_BATCH };
    double F[6][B], E0[B], E1[B], E3[B], tr[B], S0[B], S1[B], S3[B], P[6][B];
    for (uint32_t j = 0; j < count; j++)
        for (int c = 0; c < 3; c++) {
            const double *Dm = Dm_inv[j];
            double d1 = x[j][1][c] - x[j][0][c], d2 = x[j][2][c] - x[j][0][c];
            F[c][j] = d1 * Dm[0] + d2 * Dm[2];
            F[3 + c][j] = d1 * Dm[1] + d2 * Dm[3];
        }
    for (uint32_t j = 0; j < count; j++) {
        double C0 = F[0][j] * F[0][j] + F[1][j] * F[1][j] + F[2][j] * F[2][j];
        double C1 = F[0][j] * F[3][j] + F[1][j] * F[4][j] + F[2][j] * F[5][j];
        double C3 = F[3][j] * F[3][j] + F[4][j] * F[4][j] + F[5][j] * F[5][j];
        E0[j] = 0.5 * (C0 - 1);
        E1[j] = 0.5 * C1;
        E3[j] = 0.5 * (C3 - 1);
        tr[j] = E0[j] + E3[j];
        S0[j] = 2 * mu * E0[j] + lambda * tr[j];
        S1[j] = 2 * mu * E1[j];
        S3[j] = 2 * mu * E3[j] + lambda * tr[j];
    }
    for (uint32_t j = 0; j < count; j++)
        for (int c = 0; c < 3; c++) {
            double a = F[c][j], b = F[3 + c][j];
            P[c][j] = a * S0[j] + b * S1[j];   /* S is symmetric: S[2] = S[1] */
            P[3 + c][j] = a * S1[j] + b * S3[j];
        }
    for (uint32_t j = 0; j < count; j++) {
        double psi = mu * (E0[j] * E0[j] + 2 * E1[j] * E1[j] + E3[j] * E3[j]) + 0.5 * lambda * tr[j] * tr[j];
        W[j] = area[j] * psi;
        const double *Dm = Dm_inv[j];
        for (int c = 0; c < 3; c++) {
            double g1 = area[j] * (P[c][j] * Dm[0] + P[3 + c][j] * Dm[1]);
            double g2 = area[j] * (P[c][j] * Dm[2] + P[3 + c][j] * Dm[3]);
            grad[j][3 + c] = g1;
            grad[j][6 + c] = g2;
            grad[j][c] = -(g1 + g2);
        }
    }
}

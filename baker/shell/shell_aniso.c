/* SPDX-License-Identifier: MIT */
/* Anisotropic energies along a fibre a (unit, in the triangle's 2D rest frame), after Kim, de Goes
 * and Iben, "Anisotropic Elasticity for Inversion-Safety and Element Rehabilitation" (2019):
 * I5 = |F a|^2 is the squared stretch along the fibre, dI5/dF = 2 (F a) a^T.
 * - arap: psi = (mu/2)(sqrt(I5) - s)^2, s = sign(I4). A 3x2 F carries no orientation, so the
 *   caller gives s: the sign of (F_0 x F_1) . n_ref with n_ref the current normal of the
 *   triangle's neighbourhood (-1: the triangle is flipped against its neighbours, and the energy
 *   pushes the fibre back through zero length instead of letting it stay inverted).
 *   P = mu (1 - s / sqrt(I5)) (F a) a^T.
 * - sqrt: the same with s = 1 (a fibre may flip without penalty).
 * - stvk: psi = (mu/8)(I5 - 1)^2, P = (mu/2)(I5 - 1)(F a) a^T.
 */
#include <math.h>
#include "shell.h"

double shell_aniso_energy(shell_aniso_kind kind, double mu, double sign, const double fibre[2],
                          const double Dm_inv[4], double area, const double *x0, const double *x1,
                          const double *x2, double grad[9])
{
    double F[6], P[6], Fa[3];
    shell_deformation_gradient(x0, x1, x2, Dm_inv, F);
    for (int c = 0; c < 3; c++) Fa[c] = F[c] * fibre[0] + F[3 + c] * fibre[1];
    double I5 = Fa[0] * Fa[0] + Fa[1] * Fa[1] + Fa[2] * Fa[2];
    double psi, k;
    if (kind == SHELL_ANISO_STVK) {
        psi = mu / 8 * (I5 - 1) * (I5 - 1);
        k = mu / 2 * (I5 - 1);
    } else {
        double s = kind == SHELL_ANISO_ARAP ? (sign < 0 ? -1 : 1) : 1, r = sqrt(I5);
        psi = mu / 2 * (r - s) * (r - s);
        /* A fibre of zero length has no direction to push along. */
        k = r > 1e-150 ? mu * (1 - s / r) : 0;
    }
    for (int c = 0; c < 3; c++) {
        P[c] = k * Fa[c] * fibre[0];
        P[3 + c] = k * Fa[c] * fibre[1];
    }
    shell_gradient_from_stress(P, Dm_inv, area, grad);
    return area * psi;
}

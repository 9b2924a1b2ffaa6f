/* SPDX-License-Identifier: MIT */
/* Isometric bending of one hinge (Bergou et al. 2006, "A Quadratic Bending Model for Inextensible
 * Surfaces"): the cotangent stencil K of the interior edge gives v = sum_j K_j x_j, the discrete
 * mean-curvature vector of the hinge (zero for a flat hinge, unchanged by isometric motions).
 * The quadratic model (kB/2) 3/(A0 + A1) |v|^2 assumes a flat rest shape; a closed shell is
 * curved at rest, so the energy measures the change of |v| from its rest value:
 * W = (kB/2) scale (|v| - |v_rest|)^2, zero and stationary at rest, invariant under rigid motions.
 * The stencil itself is built in shell_mesh.c. */
#include <math.h>
#include "shell.h"

double shell_bending_energy(const double K[4], double scale, double rest, double kB, const double *const x[4],
                            double grad[12])
{
    double v[3] = { 0, 0, 0 };
    for (int j = 0; j < 4; j++)
        for (int c = 0; c < 3; c++) v[c] += K[j] * x[j][c];
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    double d = len - rest;
    /* dW/dx_j = kB scale d K_j v / |v|; at |v| = 0 the direction is undefined: no force. */
    double k = len > 1e-300 ? kB * scale * d / len : 0;
    for (int j = 0; j < 4; j++)
        for (int c = 0; c < 3; c++) grad[3 * j + c] = k * K[j] * v[c];
    return 0.5 * kB * scale * d * d;
}

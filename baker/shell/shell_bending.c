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

/* v = sum_j K_j x_j; returns |v|. */
static double hinge_vector(const double K[4], const double *const x[4], double v[3])
{
    v[0] = v[1] = v[2] = 0;
    for (int j = 0; j < 4; j++)
        for (int c = 0; c < 3; c++) v[c] += K[j] * x[j][c];
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

double shell_bending_energy(const double K[4], double scale, double rest, double kB, const double *const x[4],
                            double grad[12])
{
    double v[3];
    double len = hinge_vector(K, x, v);
    double d = len - rest;
    /* dW/dx_j = kB scale d K_j v / |v|; at |v| = 0 the direction is undefined: no force. */
    double k = len > 1e-300 ? kB * scale * d / len : 0;
    for (int j = 0; j < 4; j++)
        for (int c = 0; c < 3; c++) grad[3 * j + c] = k * K[j] * v[c];
    return 0.5 * kB * scale * d * d;
}

/* The projection of the sweeps (shell_sim.c) for hinges. The generic one uses C = sqrt(2W) = root
 * |d|, whose gradient flips where d = |v| - rest changes sign; the signed C = root d gives the
 * same step wherever d keeps its sign (the multiplier then only changes sign with it) and is
 * smooth through d = 0. It also needs one square root and one division instead of two of
 * each: the hinges were most of a sweep's time, waiting on those. */
double shell_bending_step(const double K[4], const double w[4], double root, double rest, double alpha,
                          const double *const x[4], double *lambda, double u[3])
{
    /* Written so that neither division waits for the other: 1 / (sum w |grad C|^2 + alpha) needs
     * no position, and root / |v| starts as soon as the square root is done. */
    double wk = w[0] * K[0] * K[0] + w[1] * K[1] * K[1] + w[2] * K[2] * K[2] + w[3] * K[3] * K[3];
    double inv_den = 1 / (root * root * wk + alpha), v[3];
    double len = hinge_vector(K, x, v);
    double C = root * (len - rest), f = 0;
    if (len > 1e-300) {   /* as above: no direction, no step */
        double along = root / len, dl = (-C - alpha * *lambda) * inv_den;
        *lambda += dl;
        f = along * dl;
    }
    for (int c = 0; c < 3; c++) u[c] = f * v[c];
    return 0.5 * C * C;
}

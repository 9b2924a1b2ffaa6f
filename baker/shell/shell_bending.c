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
 * smooth through d = 0. It also needs one square root instead of two, and its two divisions do
 * not wait for each other: the hinges were most of a sweep's time, waiting on those. */
void shell_bending_steps(uint32_t count, const double *const K[], double w[][4], const double root[],
                         const double rest[], double alpha, const double *x[][4], double *const lambda[], double W[],
                         double u[][3])
{
    /* Stage by stage for all the hinges, so that their square roots and divisions overlap, and
     * written so that neither division waits for the other: 1 / (sum w |grad C|^2 + alpha)
     * needs no position, and root / |v| starts as soon as the square root is done. */
    enum { B = SHELL_BATCH };
    double inv_den[B], v[B][3], len[B];
    for (uint32_t j = 0; j < count; j++) {
        const double *k = K[j];
        const double *wj = w[j];
        double wk = wj[0] * k[0] * k[0] + wj[1] * k[1] * k[1] + wj[2] * k[2] * k[2] + wj[3] * k[3] * k[3];
        double den = root[j] * root[j] * wk + alpha;
        inv_den[j] = den > 0 ? 1 / den : 0;   /* nothing to move (alpha 0 and no mass or stiffness): no step */
    }
    for (uint32_t j = 0; j < count; j++) len[j] = hinge_vector(K[j], x[j], v[j]);
    for (uint32_t j = 0; j < count; j++) {
        double C = root[j] * (len[j] - rest[j]), f = 0;
        W[j] = 0.5 * C * C;
        if (len[j] > 1e-300) {   /* as above: no direction, no step */
            double along = root[j] / len[j], dl = (-C - alpha * *lambda[j]) * inv_den[j];
            *lambda[j] += dl;
            f = along * dl;
        }
        for (int c = 0; c < 3; c++) u[j][c] = f * v[j][c];
    }
}

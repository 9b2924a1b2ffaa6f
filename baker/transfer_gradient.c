/* SPDX-License-Identifier: MIT */
/* Deformation gradients of triangles (transfer_internal.h): the edge matrix with the fourth
 * vertex, and T = V~ V^-1 as coefficients on the corners, shared by the correspondence phase
 * (transfer_register.c) and the transfer (transfer.c). */
#include <math.h>
#include "transfer_internal.h"
#include "bake_util.h"
#include "mesh_groups.h"

void bake_transfer_edge_matrix(double V[9], const double a[3], const double b[3], const double c[3])
{
    double e1[3], e2[3], n[3];
    vec3_sub(e1, b, a);
    vec3_sub(e2, c, a);
    mk_triangle_normal(a, b, c, n);
    double l = vec3_length(n), s = l > 0 ? 1 / sqrt(l) : 0;
    for (int r = 0; r < 3; r++) {
        V[3 * r] = e1[r];
        V[3 * r + 1] = e2[r];
        V[3 * r + 2] = n[r] * s;
    }
}

int bake_transfer_coefficients(double k[12], const double a[3], const double b[3], const double c[3])
{
    double V[9], W[9];
    bake_transfer_edge_matrix(V, a, b, c);
    if (!mat3_inverse(W, V, TRANSFER_EDGE_MIN_DET)) return 0;
    for (int col = 0; col < 3; col++) {
        double *kc = k + 4 * col;
        kc[1] = W[col]; kc[2] = W[3 + col]; kc[3] = W[6 + col];
        kc[0] = -(kc[1] + kc[2] + kc[3]);
    }
    return 1;
}

/* SPDX-License-Identifier: MIT */
/* Free-form deformation lattices (Sederberg-Parry Bernstein, uniform cubic B-spline). See ffd.c. */
#ifndef MK_FFD_H
#define MK_FFD_H

#include "raw.h"

typedef enum mk_ffd_basis {
    MK_FFD_BERNSTEIN = 0,  /* Sederberg-Parry: global trivariate Bernstein, degree dims-1 per axis */
    MK_FFD_BSPLINE = 1     /* uniform cubic B-spline with clamped indices (Blender's Lattice) */
} mk_ffd_basis;

typedef struct mk_ffd_lattice {
    mk_ffd_basis basis;
    uint32_t dims[3];      /* control points along S, T, U; each >= 2 */
    double origin[3];      /* X0: corner of the parallelepiped (mesh units) */
    double axes[3][3];     /* edge vectors S, T, U (mesh units) */
    /* Displacement P'_ijk - P_ijk of each control point (mesh units), 3 doubles per point,
     * point (i, j, k) at index i + dims[0] * (j + dims[1] * k). Owned by the caller. */
    const double *displacements;
    /* Filled by mk_ffd_prepare: rows of M^-1 with M = [S T U], i.e. (T x U)/((T x U).S), ... */
    double inverse[9];
} mk_ffd_lattice;

/* Rest position of control point (i, j, k): X0 + i/(l-1) S + j/(m-1) T + k/(n-1) U. */
void mk_ffd_control_point(const mk_ffd_lattice *lattice, uint32_t i, uint32_t j, uint32_t k,
                          double out[3]);

/* Checks dims, finiteness and that S, T, U span a volume (|det| > 1e-9 |S||T||U|). */
mk_result mk_ffd_prepare(mk_ffd_lattice *lattice, mk_error *err);

/* Deforms one point with the displacements scaled by the amplitude and gives the Jacobian
 * (row-major). user is a const mk_ffd_lattice * (bake_point_map). */
void mk_ffd_map(const void *lattice, double amplitude, const double p[3], double out[3], double J[9]);

/* Lattice parameters (s, t, u) of a point: (s,t,u) = M^-1 (X - X0). */
void mk_ffd_parameters(const mk_ffd_lattice *lattice, const double p[3], double stu[3]);

#endif

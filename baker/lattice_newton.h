/* SPDX-License-Identifier: MIT */
/* Pieces shared by the extended FFD lattices (ffd_cylinder.c, ffd_prism.c): a 3x3 solve, and the
 * damped Newton iteration that inverts a lattice block's rest map (the Bernstein basis they share
 * with ffd.c is bake_bernstein, bake_util.h). Internal to baker/. */
#ifndef BAKE_LATTICE_NEWTON_H
#define BAKE_LATTICE_NEWTON_H

#include <stdint.h>
#include "raw.h"

/* Solves J x = b for a 3x3 row-major J: x = J^-1 b (mat3_inverse, bake_util.h); 0 when J is
 * singular relative to its size (|det J| <= 1e-14 max|J_ij|^3), where a Newton step would be
 * huge and the caller holds a coordinate instead. Deformation transfer inverts its edge matrices
 * with no such cut on purpose (transfer.c). */
int bake_solve3(const double J[9], const double b[3], double x[3]);

/* A block's rest map F(q) and, when J is not NULL, its Jacobian (row-major, column c = dF/dq_c). */
typedef void (*bake_rest_map)(const void *user, const double q[3], double F[3], double J[9]);

typedef struct bake_newton {
    bake_rest_map map;
    const void *user;
    double lower[3], upper[3];  /* every trial point is clamped into [lower, upper] */
    int held;                   /* coordinate left unchanged when J is singular; -1: stop there */
    double target;              /* converged when |F(q) - p| <= target */
    uint32_t max_iterations;
} bake_newton;

/* Damped Newton's method for F(q) = p starting from q: each step solves J step = F(q) - p and
 * is halved (up to 30 times) until the residual falls. Returns the final |F(q) - p|; q holds
 * the last iterate and *iterations (if not NULL) the number of steps taken. */
double bake_newton_solve(const bake_newton *newton, const double p[3], double q[3], uint32_t *iterations);

/* The frame of a lattice around an axis: frame[2] the unit axis, frame[0] the reference made
 * perpendicular to it, frame[1] = frame[2] x frame[0]; *height the axis's length. Errors name
 * `axis` (zero length) or `reference` (parallel to the axis). */
mk_result bake_axial_frame(const double axis[3], const double reference[3], double frame[3][3], double *height,
                           mk_error *err);

/* Where p lies in a lattice: its coordinates (stride doubles) or an error saying why not. */
typedef mk_result (*bake_locate)(const void *lattice, const double p[3], double *coords, mk_error *err);

/* Locates every vertex of mesh (coords: stride doubles per vertex); the first vertex that
 * fails is named in the error with its position. */
mk_result bake_lattice_bind(const void *lattice, bake_locate locate, uint32_t stride, const mk_raw_mesh *mesh,
                            double *coords, mk_error *err);

#endif

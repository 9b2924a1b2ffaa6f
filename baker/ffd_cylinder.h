/* SPDX-License-Identifier: MIT */
/* Extended FFD with a cylindrical lattice (rings x sectors x layers). See ffd_cylinder.c. */
#ifndef MK_FFD_CYLINDER_H
#define MK_FFD_CYLINDER_H

#include "raw.h"

typedef struct mk_cylinder_lattice {
    uint32_t dims[3];        /* rings (>= 2), sectors (>= 3, periodic), layers (>= 2) */
    double center[3];        /* a point on the axis: the centre of the first layer (mesh units) */
    double axis[3];          /* the cylinder's axis; length = height (mesh units) */
    double reference[3];     /* direction of sector 0 (any length, not parallel to axis) */
    double inner_radius;     /* radius of ring 0 (>= 0; 0 puts ring 0 on the axis) */
    double outer_radius;     /* radius of the last ring's control points (> inner_radius) */
    /* Displacement of each control point (mesh units), 3 per point, point (i, j, k) at index
     * i + dims[0] * (j + dims[1] * k). Owned by the caller. With inner_radius 0 the points of
     * ring 0 of one layer coincide: give them one displacement (the recipe averages them). */
    const double *displacements;
    /* Filled by mk_cylinder_prepare: orthonormal frame (e1 = sector 0, e2, unit axis), height. */
    double frame[3][3];
    double height;
} mk_cylinder_lattice;

/* Checks dims, finiteness, radii and the frame. */
mk_result mk_cylinder_prepare(mk_cylinder_lattice *lattice, mk_error *err);

/* Rest position of control point (i, j, k): center + r_i (cos a_j e1 + sin a_j e2) + k/(l-1) axis,
 * r_i evenly spaced from inner to outer radius, a_j = 2 pi j / sectors. */
void mk_cylinder_control_point(const mk_cylinder_lattice *lattice, uint32_t i, uint32_t j, uint32_t k,
                               double out[3]);

/* Lattice coordinates (s, t, u) of a rest-space point by damped Newton iteration on the rest
 * map (t periodic in [0, 1)). Fails with MK_ERROR_INVALID_ARGUMENT when the point lies outside
 * the lattice or Newton does not reach 1e-10 of the lattice size; *iterations gets the count. */
mk_result mk_cylinder_coordinates(const mk_cylinder_lattice *lattice, const double p[3], double stu[3],
                                  uint32_t *iterations, mk_error *err);

/* Deformed position of the rest point p whose coordinates are stu: p + amplitude * sum w(stu) d. */
void mk_cylinder_eval(const mk_cylinder_lattice *lattice, double amplitude, const double stu[3], const double p[3],
                      double out[3]);

/* Smallest radius of the rest lattice's ring curve for a unit control radius (about 0.90 for 8
 * sectors): a control radius of R / ratio encloses everything within R of the axis. */
double mk_cylinder_ring_ratio(uint32_t sectors);

/* Coordinates of every vertex of mesh into stu (3 per vertex); the error names the first
 * vertex outside the lattice or where Newton failed. */
mk_result mk_cylinder_bind(const mk_cylinder_lattice *lattice, const mk_raw_mesh *mesh, double *stu, mk_error *err);

#endif

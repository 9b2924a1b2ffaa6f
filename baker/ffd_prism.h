/* SPDX-License-Identifier: MIT */
/* Extended FFD with a prism lattice: a regular polygon cross-section extruded along an axis,
 * split into wedge-shaped blocks joined across their seams. See ffd_prism.c. */
#ifndef MK_FFD_PRISM_H
#define MK_FFD_PRISM_H

#include "raw.h"

typedef struct mk_prism_lattice {
    uint32_t sides;          /* wedges (and polygon sides) around the centre, >= 3 */
    uint32_t degree;         /* Bernstein triangle degree n in the cross-section, >= 1 */
    uint32_t layers;         /* control point layers along the axis (Bernstein degree layers-1), >= 2 */
    double center[3];        /* centre of the first layer's cross-section (mesh units) */
    double axis[3];          /* the prism's axis; length = height (mesh units) */
    double reference[3];     /* direction of corner 0 (any length, not parallel to axis) */
    double radius;           /* regular polygon: distance from the centre to a corner (> 0) */
    /* Explicit cross-section instead of the regular polygon (NULL: regular): sides corners, 2
     * doubles each, (x, y) in mesh units along (e1, e2) from the centre, counter-clockwise
     * about the axis; every triangle (centre, corner w, corner w + 1) must turn left, and
     * together they must go round the centre once (a polygon star-shaped from the centre). */
    const double *section;
    /* Control points: per layer the centre (ring 0), then ring r = 1..n with sides * r points
     * each (mk_prism_index). rest: rest positions (3 per point) or NULL for the regular lattice
     * (mk_prism_control_point); displacements: moved - rest (3 per point). Owned by the caller. */
    const double *rest;
    const double *displacements;
    /* Filled by mk_prism_prepare: orthonormal frame (e1 = reference, e2 = axis x e1, unit axis),
     * height, and size = the larger of height and the farthest corner (Newton's scale). */
    double frame[3][3];
    double height;
    double size;
} mk_prism_lattice;

/* Checks the counts, finiteness, radius or section and the frame. */
mk_result mk_prism_prepare(mk_prism_lattice *lattice, mk_error *err);

/* Control points per layer (1 + sides n (n + 1) / 2) and in all (times layers). */
uint32_t mk_prism_layer_points(const mk_prism_lattice *lattice);
uint32_t mk_prism_point_count(const mk_prism_lattice *lattice);
/* Index of the control point at ring r (0..n), position m around the ring (0..sides r - 1;
 * ring 0 has m = 0 only) and layer k: k * layer_points + (r ? 1 + sides r (r - 1) / 2 + m : 0). */
uint32_t mk_prism_index(const mk_prism_lattice *lattice, uint32_t ring, uint32_t position, uint32_t layer);

/* Regular rest position of a control point: with wedge w = m / r and c = m mod r, the point
 * center + (r - c)/n V_w + c/n V_(w+1) + k/(layers-1) axis, with corner V_w = radius (cos a_w e1 +
 * sin a_w e2), a_w = 2 pi w / sides, or the section's corner w: ring r is the polygon scaled by
 * r/n, each side split evenly. */
void mk_prism_control_point(const mk_prism_lattice *lattice, uint32_t ring, uint32_t position, uint32_t layer,
                            double out[3]);

/* Local coordinates of a rest-space point: coords = (wedge, l1, l2, u) with (1 - l1 - l2, l1, l2)
 * its barycentric coordinates in the wedge's triangle (centre, corner w, corner w + 1) and u
 * along the axis, by damped Newton iteration on the wedge's rest map. Fails with
 * MK_ERROR_INVALID_ARGUMENT when the point is outside every wedge or Newton does not reach 1e-10
 * of the lattice size; *iterations gets the steps of the accepted wedge. */
mk_result mk_prism_coordinates(const mk_prism_lattice *lattice, const double p[3], double coords[4],
                               uint32_t *iterations, mk_error *err);

/* Rest map of one wedge at q = (l1, l2, u) and its Jacobian d/d(l1, l2, u) (row-major; J may be
 * NULL): sum over the wedge's control points of B^n_abc(1 - l1 - l2, l1, l2) B_k(u) P. */
void mk_prism_rest_map(const mk_prism_lattice *lattice, uint32_t wedge, const double q[3], double out[3],
                       double J[9]);

/* Deformed position of the rest point p with coordinates coords: p + amplitude * sum w d. */
void mk_prism_eval(const mk_prism_lattice *lattice, double amplitude, const double coords[4], const double p[3],
                   double out[3]);

/* Coordinates of every vertex of mesh into coords (4 per vertex); the error names the first
 * vertex outside the lattice or where Newton failed. */
mk_result mk_prism_bind(const mk_prism_lattice *lattice, const mk_raw_mesh *mesh, double *coords, mk_error *err);

#endif

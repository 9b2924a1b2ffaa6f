/* SPDX-License-Identifier: MIT */
/* Cage deformation with mean value coordinates for closed triangle cages. See cage_mvc.c. */
#ifndef MK_CAGE_MVC_H
#define MK_CAGE_MVC_H

#include "raw.h"

typedef struct mk_cage {
    uint32_t vertex_count;
    const double *rest;        /* 3 per cage vertex (mesh units) */
    const double *deformed;    /* 3 per cage vertex: the cage at amplitude 1 */
    uint32_t triangle_count;
    const uint32_t *triangles; /* 3 per triangle, consistently oriented, closed */
} mk_cage;

/* Mean value coordinates of x with respect to the rest cage (vertex_count weights summing to
 * 1, linear precision sum w_j p_j = x, inside and outside). eps_d: distance under which x
 * snaps to a cage vertex (mesh units; the recipe uses 1e-8 x cage diagonal). */
void mk_mvc_coordinates(const mk_cage *cage, const double x[3], double eps_d, double *weights);

/* Checks the cage: at least 4 vertices, indices in range, finite coordinates, no degenerate
 * triangle, every directed edge used once and its reverse once (closed and consistently
 * oriented: mixed orientation silently breaks linear precision), nonzero signed volume.
 * A cage with all triangles facing inward is fine (reversing every triangle leaves the
 * coordinates unchanged). */
mk_result mk_cage_validate(const mk_cage *cage, mk_error *err);

typedef struct mk_cage_binding mk_cage_binding;
/* Computes the coordinates of every mesh vertex once (dense: vertex_count x cage vertices). */
mk_result mk_cage_bind(const mk_raw_mesh *mesh, const mk_cage *cage, const mk_allocator *allocator,
                       mk_cage_binding **out, mk_error *err);
/* mk_deformer.eval: x' = x + a * sum_j w_j (deformed_j - rest_j). */
mk_result mk_cage_eval(void *binding, double amplitude, double *positions, double *normals,
                       double *tangents, uint32_t *inverted, mk_error *err);
void mk_cage_unbind(mk_cage_binding *binding);

#endif

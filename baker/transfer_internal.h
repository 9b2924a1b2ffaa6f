/* SPDX-License-Identifier: MIT */
/* Deformation transfer internals shared by transfer.c and transfer_correspond.c (baker/ only). */
#ifndef BAKE_TRANSFER_INTERNAL_H
#define BAKE_TRANSFER_INTERNAL_H

#include "raw.h"

/* The source -> target alignment p' = A p + t (A = s R, row-major) fitted to the markers in the
 * least-squares sense: none -> identity; one -> translation; two -> uniform scale and
 * translation; three or more -> similarity (Horn's rotation, Umeyama's scale). *residual gets
 * the RMS marker distance after alignment. Fails when the source markers coincide. */
mk_result bake_transfer_align(const mk_raw_mesh *source, const mk_raw_mesh *target, uint32_t count,
                              const uint32_t (*markers)[2], double A[9], double t[3], double *residual,
                              mk_error *err);

/* A uniform grid over a mesh's triangles at the given positions (3 doubles per vertex; cells about
 * twice a triangle's extent, at most about 8 cells per triangle) for closest-point queries.
 * Degenerate triangles are left out. */
typedef struct bake_tri_grid {
    const mk_raw_mesh *mesh;
    const double *positions;
    double *normal;            /* 3 per triangle, unnormalized */
    unsigned char *bad;        /* 1 per triangle: degenerate */
    uint32_t *seen, stamp;     /* per triangle: the last query that tried it */
    double lo[3], h;
    int32_t dims[3];
    uint32_t *first, *tris;    /* CSR: cell -> triangles */
} bake_tri_grid;
/* exclude (may be NULL): triangles to leave out as well (1 each). */
mk_result bake_tri_grid_build(bake_tri_grid *g, const mk_raw_mesh *mesh, const double *positions,
                              const unsigned char *exclude, mk_arena *arena, mk_error *err);
/* Whether triangle t of mesh at positions (NULL: the mesh's own) is degenerate: twice its area
 * at most TRANSFER_DEGENERATE of its longest edge squared. */
int bake_triangle_degenerate(const mk_raw_mesh *mesh, const double *positions, uint32_t t);
/* The triangle whose closest point to p is nearest among those whose normal makes a positive dot
 * product with n (ties: the lower index), the barycentric coordinates of that point and its
 * squared distance (d2 may be NULL); UINT32_MAX when none faces n's way. *away_nearer (may be
 * NULL): whether a triangle facing away was nearer. The same answer as trying every triangle:
 * rings of cells around p's cell until the cells not visited are all farther than the best. A
 * point that is not finite matches nothing. */
uint32_t bake_tri_grid_closest(bake_tri_grid *g, const double p[3], const double n[3], double bary[3], double *d2,
                               int *away_nearer);

/* Per target triangle: the source triangle (at the positions `aligned`, 3 doubles per source
 * vertex; those with exclude[s] set left out, exclude may be NULL) whose closest point to the target triangle's centroid is nearest among those facing the
 * same way (normals with a positive dot product), and the barycentric coordinates of that closest
 * point. match[t] = UINT32_MAX for a degenerate target triangle or when no source triangle faces
 * its way (counted in *unmatched); *flipped counts triangles whose nearest source triangle overall
 * faced away. target_positions: 3 doubles per target vertex, NULL for the mesh's own. */
mk_result bake_transfer_correspond(const mk_raw_mesh *source, const double *aligned, const unsigned char *exclude,
                                   const mk_raw_mesh *target, const double *target_positions, mk_arena *arena,
                                   uint32_t *match, double *barycentric, uint32_t *flipped, uint32_t *unmatched,
                                   mk_error *err);

/* The correspondence phase of Sumner & Popovic (2004), section 5 (transfer_register.c): the source,
 * starting at `deformed` (its aligned rest positions, 3 doubles per source vertex), is deformed
 * towards the target by minimizing w_S E_S + w_I E_I + w_C E_C over its vertices (and one fourth
 * vertex per triangle): E_S = sum over triangles sharing an edge of |T_i - T_j|_F^2 (smoothness),
 * E_I = sum of |T_i - I|_F^2 (identity), E_C = sum over vertices of |v_i - c_i|^2 / L^2 (c_i the
 * closest point of the target whose triangle faces the vertex normal's way, L the target's
 * bounding-box diagonal), the marker vertices held at their target vertices. One solve with
 * w_C = 0 (components without a marker held where they are), then one per weight of the schedule
 * (closest points found again before each), all with one symbolic factorization; working memory
 * from allocator, freed before returning. On return `deformed` holds the fitted source. */
typedef struct bake_register_params {
    const mk_raw_mesh *source, *target;
    bake_tri_grid *target_grid;    /* over the target's triangles at its positions */
    uint32_t marker_count;
    const uint32_t (*markers)[2];
    uint32_t step_count;           /* closest-point weights w_C, increasing */
    const double *steps;
    double smoothness, identity;   /* w_S, w_I */
} bake_register_params;
typedef struct bake_register_stats {
    double mean_distance, max_distance;   /* fitted source vertices to the target, x diagonal */
    double marker_distance;               /* largest marker pair distance after the fit, x diagonal */
    uint32_t solves, factorizations;
    double seconds;
} bake_register_stats;
mk_result bake_transfer_register(const bake_register_params *params, double *deformed, const mk_allocator *allocator,
                                 bake_register_stats *stats, mk_error *err);

/* Edge matrix [v2 - v1, v3 - v1, v4 - v1] (columns, row-major storage) with the fourth vertex
 * v4 = v1 + n / sqrt(|n|), n = (v2 - v1) x (v3 - v1) (v4 = v1 for a collapsed triangle). */
void bake_transfer_edge_matrix(double V[9], const double a[3], const double b[3], const double c[3]);
/* The deformation gradient T = V~ V^-1 of triangle abc as coefficients on its corners: column c of
 * T is sum over q of k[4 c + q] v~_q (v~_3: the fourth vertex). 0 when the edge matrix has no
 * inverse (its determinant is not finite or not above TRANSFER_EDGE_MIN_DET). */
int bake_transfer_coefficients(double k[12], const double a[3], const double b[3], const double c[3]);
/* Edge matrices are inverted whenever their determinant is finite and nonzero (mat3_inverse's
 * min_det 0), not with the lattices' relative cut (bake_solve3): det V = |n|^(3/2), so a cut at
 * 1e-14 max|V_ij|^3 would call singular the triangles between TRANSFER_DEGENERATE (1e-12 of the
 * longest edge squared, where the correspondence stops) and about 4.6e-10, and such a source
 * triangle would hand a zero gradient to the target triangles matched to it. */
#define TRANSFER_EDGE_MIN_DET 0

/* The closest-point weights w_C of the iterative correspondence by default: 1 to 5000 in four
 * geometric steps, after a first solve without (as Sumner & Popovic's schedule). */
#define TRANSFER_DEFAULT_STEPS 1.0, 17.1, 292.4, 5000.0
/* The recipe's fit_tolerance by default: the fit has converged when the fitted source's vertices
 * lie within this fraction of the target's diagonal from it on average. */
#define TRANSFER_FIT_TOLERANCE 0.01
/* The aligned meshes coincide when every target triangle's centroid lies within this fraction of
 * the target's diagonal from its matched source point. */
#define TRANSFER_COINCIDE 1e-4

/* Area of a triangle below which it counts as degenerate: relative to its longest edge squared. */
#define TRANSFER_DEGENERATE 1e-12

#endif

/* SPDX-License-Identifier: MIT */
/* Deformation transfer (Sumner & Popovic 2004): a source mesh's deformations carried onto a
 * target mesh with another vertex count and triangulation.
 *
 * Each deformed source triangle is an affine map, its deformation gradient S = V~ V^-1 from the
 * edge matrix V = [v2 - v1, v3 - v1, v4 - v1] with the fourth vertex
 * v4 = v1 + (v2 - v1) x (v3 - v1) / sqrt(|(v2 - v1) x (v3 - v1)|). Every target triangle gets the
 * gradient of its corresponding source triangle (transfer_correspond.c), and the target's new
 * vertices (and one fourth vertex per triangle) are the least-squares fit of its triangles'
 * gradients to those: one sparse SPD system factored once (CHOLMOD) and solved with the three
 * coordinates as right-hand sides for every source shape. docs/baking.md ("transfer") writes the
 * system out, with the correspondence and the pinning of the free translation.
 */
#ifndef MK_TRANSFER_H
#define MK_TRANSFER_H

#include "raw.h"

/* How target triangles find their source triangles. */
typedef enum mk_transfer_correspondence {
    MK_TRANSFER_AUTO = 0,          /* closest when the aligned meshes coincide, else iterative */
    MK_TRANSFER_CLOSEST,           /* one pass: each target triangle's nearest aligned source triangle */
    MK_TRANSFER_ITERATIVE          /* the source fitted to the target first, then matches both ways */
} mk_transfer_correspondence;

typedef struct mk_transfer_params {
    const mk_raw_mesh *source;     /* rest pose: positions and triangles */
    const mk_raw_mesh *target;
    uint32_t marker_count;         /* pairs (source vertex, target vertex) aligning the source; with
                                    * the iterative correspondence they are also held together */
    const uint32_t (*markers)[2];
    mk_transfer_correspondence correspondence;
    uint32_t step_count;           /* iterative: the closest-point weights w_C, increasing; 0: the */
    const double *steps;           /* default (TRANSFER_DEFAULT_STEPS, docs/baking.md) */
} mk_transfer_params;

typedef struct mk_transfer_stats {
    uint32_t unknowns;             /* per coordinate: welded target vertices + fourth vertices - pins */
    uint32_t components;           /* connected components of the target (one pinned vertex each) */
    uint32_t flipped;              /* target triangles whose nearest source triangle faced away
                                    * (the nearest compatible one was used instead) */
    uint32_t unmatched;            /* target triangles without any compatible source triangle */
    uint32_t pairs;                /* (target, source) triangle pairs in the system */
    int iterative;                 /* the correspondence used: 1 iterative, 0 closest */
    double fit_mean, fit_max;      /* iterative: distance of the fitted source's vertices to the
                                    * target (nearest point facing their way), x target diagonal */
    double marker_distance;        /* iterative: largest marker pair distance after the fit, x diagonal */
    double register_seconds;       /* iterative: the fit */
    uint32_t register_solves;
    double alignment[12];          /* the source -> target map: row-major 3x3 A (s R) then t */
    double alignment_residual;     /* RMS marker distance after alignment, mesh units */
    double correspond_seconds;     /* alignment + closest triangles */
    double factor_seconds;
    double solve_seconds;          /* all solves */
    uint32_t solves;
} mk_transfer_stats;

typedef struct mk_transfer mk_transfer;

/* Aligns the source to the target from the markers, finds each target triangle's source
 * triangle, builds and factors the system. Both meshes must outlive the transfer. */
mk_result mk_transfer_create(const mk_transfer_params *params, const mk_allocator *allocator,
                             mk_transfer **out, mk_error *err);
/* Target positions (3 doubles per target render vertex) for the source deformed to
 * source_positions (3 doubles per source render vertex). */
mk_result mk_transfer_apply(mk_transfer *transfer, const double *source_positions, double *target_positions,
                            mk_error *err);
/* Source triangle matched to target triangle t (UINT32_MAX: none) and the barycentric
 * coordinates of the closest point to t's centroid on it (for tests and diagnostics). */
uint32_t mk_transfer_match(const mk_transfer *transfer, uint32_t t, double barycentric[3]);
void mk_transfer_stats_get(const mk_transfer *transfer, mk_transfer_stats *stats);
void mk_transfer_destroy(mk_transfer *transfer);

/* Adds to raw a channel on mesh `mesh` named `name` (origin: recipe JSON or NULL) that carries
 * source_channel (a channel of source_mesh, the transfer's source) over: one target per source
 * in-between at the same full weight, positions from mk_transfer_apply, normal deltas recomputed
 * from the deformed surface when the mesh has normals. */
mk_result mk_transfer_channel(mk_raw_asset *raw, uint32_t mesh, const char *name, const char *origin,
                              mk_transfer *transfer, const mk_raw_mesh *source_mesh,
                              const mk_raw_channel *source_channel, uint32_t *moved, mk_error *err);

#endif

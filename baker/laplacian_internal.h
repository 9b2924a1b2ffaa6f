/* Shared state of laplacian.c and arap.c (internal to baker/). */
#ifndef MK_LAPLACIAN_INTERNAL_H
#define MK_LAPLACIAN_INTERNAL_H

#include <suitesparse/cholmod.h>
#include "laplacian.h"

struct mk_surface_edit {
    mk_arena arena;
    const mk_raw_mesh *mesh;
    mk_edit_params params;
    uint32_t welded;          /* welded vertex count */
    uint32_t *weld;           /* render vertex -> welded vertex */
    double *rest;             /* 3 per welded vertex */
    /* Adjacency (CSR, both directions) with symmetric edge weights w_ij. */
    uint32_t *offsets;        /* welded + 1 */
    uint32_t *neighbors;
    double *edge_weights;
    double *weight_sums;      /* d_i = sum_j w_ij */
    /* Constraints: -1 free, 0 anchor (or an unreferenced vertex kept at rest), h + 1 handle h. */
    int32_t *constraint;
    uint32_t *unknown;        /* welded -> row of the factored system, UINT32_MAX if eliminated */
    uint32_t unknown_count;
    double (*handle_rotation)[9]; /* per handle at the current amplitude */
    double *target;           /* 3 per welded vertex: constrained positions at the current amplitude */
    double *solution;         /* 3 per welded vertex */
    double *work;             /* 3 per welded vertex */
    double *rotations;        /* ARAP: 9 per welded vertex */
    double local_seconds;     /* ARAP: time in local steps */
    cholmod_common cm;
    int cm_started;
    cholmod_factor *factor;
    cholmod_dense *rhs, *x, *y, *e;
    mk_solver_stats stats;
};

/* Solves the factored system for the right-hand sides in edit->rhs (3 columns) into edit->x. */
mk_result mk_edit_solve(mk_surface_edit *edit, mk_error *err);
/* Constrained positions of every constrained welded vertex at amplitude a into edit->target. */
void mk_edit_targets(mk_surface_edit *edit, double amplitude);
/* ARAP: local/global iterations from edit->solution (holds the initial guess). */
mk_result mk_arap_iterate(mk_surface_edit *edit, mk_error *err);

#endif

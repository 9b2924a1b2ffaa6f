/* SPDX-License-Identifier: MIT */
/* Surface editing internals: the core state and the functions its methods share (baker/ only). */
#ifndef MK_SURFACE_EDIT_INTERNAL_H
#define MK_SURFACE_EDIT_INTERNAL_H

#include "sparse_spd.h"
#include "surface_edit.h"

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
    double *anderson;         /* ARAP with Anderson acceleration: (2 + 2 * EDIT_ANDERSON_HISTORY)
                               * vectors of 3 per welded vertex (arap.c) */
    double local_seconds;     /* ARAP: time in local steps */
    bake_spd spd;             /* the factored system; spd.rhs / spd.x hold 3 columns */
    mk_solver_stats stats;
};

/* Anderson acceleration window (previous iterates combined per step), Peng et al. 2018 use 5-6. */
#define EDIT_ANDERSON_HISTORY 5
/* L-BFGS history (curvature pairs kept). */
#define EDIT_LBFGS_HISTORY 8

/* ---- the core (surface_edit.c) ---- */

/* Row v of L = I - D^-1 W as (column, value) pairs: writes count entries, column v first. */
uint32_t edit_laplacian_row(const mk_surface_edit *edit, uint32_t v, uint32_t *cols, double *vals);
/* Constrained positions of every constrained welded vertex at amplitude a into edit->target. */
void edit_targets(mk_surface_edit *edit, double amplitude);
/* Solves the factored system for the right-hand sides in edit->spd.rhs (3 columns) into edit->spd.x. */
mk_result edit_solve(mk_surface_edit *edit, mk_error *err);
/* Solves, then edit->solution = base + (the solution for unknowns, known[i] for eliminated
 * vertices), base NULL meaning zero (3 per welded vertex each). */
mk_result edit_solve_positions(mk_surface_edit *edit, const double *known, const double *base, mk_error *err);

/* ---- the methods, leaves on the core (edit.c picks one) ---- */

/* Laplacian editing (laplacian.c): edit->solution from edit->target. */
mk_result edit_laplacian_solve(mk_surface_edit *edit, mk_error *err);
/* ARAP (arap.c): local/global iterations from the solve with identity rotations. */
mk_result edit_arap_solve(mk_surface_edit *edit, mk_error *err);

#endif

/* SPDX-License-Identifier: MIT */
/* A symmetric positive definite sparse system factored once with CHOLMOD and solved for several
 * right-hand sides at a time: the part Laplacian/ARAP editing and deformation transfer share.
 * Internal to baker/. */
#ifndef BAKE_SPARSE_SPD_H
#define BAKE_SPARSE_SPD_H

#include <suitesparse/cholmod.h>
#include "raw.h"

typedef struct bake_spd {
    cholmod_common cm;
    int started;
    cholmod_factor *factor;
    cholmod_dense *rhs;        /* n x columns: fill rhs->x (column-major) before bake_spd_solve */
    cholmod_dense *x;          /* the solution of the last solve (column-major) */
    cholmod_dense *y, *e;      /* CHOLMOD's workspace for cholmod_solve2 */
    uint32_t factorizations;   /* 1 after bake_spd_factor, one more per bake_spd_refactor */
    uint32_t solves;
    double factor_seconds;     /* cholmod_analyze + every cholmod_factorize */
    double solve_seconds;      /* all solves */
    double factor_nonzeros;    /* nonzeros of the Cholesky factor */
} bake_spd;

/* Clears s and starts CHOLMOD (quiet). simplicial: 1 forces a simplicial factor (stencils with little fill
 * solve faster that way), 0 leaves CHOLMOD's choice. few_solves: 1 orders with AMD only, for a
 * system solved only a few times (CHOLMOD's default also tries METIS on large systems, whose
 * analysis can cost more than the fill it saves), 0 leaves CHOLMOD's choice of ordering. */
void bake_spd_start(bake_spd *s, int simplicial, int few_solves);
/* Analyzes and factors the matrix of the triplets T (upper triangle, stype 1, duplicates summed;
 * T is freed here either way), then allocates the n x columns right-hand sides. Fails with a
 * clear message when the matrix is not positive definite or numerically singular
 * (rcond <= 1e-15). */
mk_result bake_spd_factor(bake_spd *s, cholmod_triplet **T, uint32_t columns, mk_error *err);
/* The same for a matrix in CHOLMOD's compressed form (upper triangle, stype 1), which the caller
 * keeps and frees. */
mk_result bake_spd_factor_matrix(bake_spd *s, cholmod_sparse *A, uint32_t columns, mk_error *err);
/* Factors A again with the analysis of the first factorization: A has the same pattern, other
 * numbers (checked as bake_spd_factor does). factorizations and factor_seconds add up. */
mk_result bake_spd_refactor(bake_spd *s, cholmod_sparse *A, mk_error *err);
/* Solves A x = rhs for every column of s->rhs into s->x. */
mk_result bake_spd_solve(bake_spd *s, mk_error *err);
/* Frees everything CHOLMOD holds (safe on a zeroed or never-started struct). */
void bake_spd_finish(bake_spd *s);

#endif

/* SPDX-License-Identifier: MIT */
/* Laplacian surface editing and as-rigid-as-possible deformation with handles and anchors,
 * solved with CHOLMOD (one factorization per bake). See laplacian.c and arap.c. */
#ifndef MK_SURFACE_EDIT_H
#define MK_SURFACE_EDIT_H

#include "raw.h"

typedef enum mk_edit_method {
    MK_EDIT_LAPLACIAN = 0,     /* Sorkine et al. 2004, differential coordinates kept */
    MK_EDIT_ARAP = 1           /* Sorkine & Alexa 2007, local/global iterations */
} mk_edit_method;

typedef enum mk_laplacian_weights {
    MK_WEIGHTS_COTANGENT = 0,  /* w_ij = (cot a_ij + cot b_ij) / 2, clamped to |w| <= 1e5 */
    MK_WEIGHTS_UNIFORM = 1     /* w_ij = 1 per edge */
} mk_laplacian_weights;

typedef enum mk_arap_acceleration {
    MK_ARAP_LBFGS = 0,         /* L-BFGS on the energy with the Laplacian as its initial Hessian
                                * (Liu, Bouaziz, Kavan 2017) and an Armijo line search; its first
                                * step is the plain one */
    MK_ARAP_ANDERSON = 1,      /* Anderson acceleration of the local/global map (Peng et al. 2018),
                                * an accelerated step that raises the energy is replaced by the
                                * plain one */
    MK_ARAP_PLAIN = 2          /* plain local/global iterations (Sorkine & Alexa 2007) */
} mk_arap_acceleration;

/* A set of vertices moved rigidly: at amplitude a a handle vertex goes to
 * pivot + R(axis, a * angle) (x - pivot) + a * translate. */
typedef struct mk_edit_handle {
    uint32_t count;
    const uint32_t *vertices;  /* render-vertex indices */
    double translate[3];       /* mesh units at amplitude 1 */
    double axis[3];            /* rotation axis (any length; ignored when angle == 0) */
    double angle;              /* radians at amplitude 1 */
    double pivot[3];           /* mesh units */
} mk_edit_handle;

typedef struct mk_edit_params {
    mk_edit_method method;
    mk_laplacian_weights weights;
    int soft;                  /* 0: hard constraints (eliminated); 1: soft, weight soft_weight */
    double soft_weight;        /* soft: w in w^2 |x_c - c|^2; 0 = 100 */
    uint32_t anchor_count;     /* vertices that stay at rest */
    const uint32_t *anchors;
    uint32_t handle_count;
    const mk_edit_handle *handles;
    uint32_t iterations;       /* ARAP: cap on local/global iterations (a safety limit); 0 = 1000 */
    double convergence;        /* ARAP: stop when the energy drops by less than this fraction in
                                * one iteration; 0 = 1e-6; negative = run all iterations */
    mk_arap_acceleration acceleration; /* ARAP: default Anderson */
    /* ARAP: called after each iteration's local step with the energy of the current positions
     * (iteration 0: the initial guess); may be NULL. */
    void (*iteration_done)(void *user, uint32_t iteration, double energy);
    void *user;
} mk_edit_params;

typedef struct mk_solver_stats {
    uint32_t factorizations;   /* cholmod_factorize calls (1 per bake) */
    uint32_t solves;           /* cholmod_solve2 calls, 3 right-hand sides each */
    double factor_seconds;     /* cholmod_analyze + cholmod_factorize */
    double solve_seconds;      /* all solves */
    double setup_seconds;      /* building the operator and the matrix */
    double local_seconds;      /* ARAP: all local (rotation fitting) steps */
    uint32_t unknowns;         /* size of the factored system */
    double factor_nonzeros;    /* nonzeros of the Cholesky factor */
    /* ARAP, over all evaluations of the edit: */
    uint32_t evaluations;      /* mk_surface_edit_eval calls */
    uint32_t iterations;       /* local/global iterations, all evaluations */
    uint32_t max_iterations;   /* most iterations of one evaluation */
    uint32_t unconverged;      /* evaluations stopped by the iteration cap */
    uint32_t rejected_steps;   /* Anderson steps replaced by the plain step */
    double energy;             /* ARAP energy of the last evaluation's result (arap.c) */
    double start_energy;       /* ... and of its initial guess (rotations fitted to it) */
} mk_solver_stats;

typedef struct mk_surface_edit mk_surface_edit;

/* Builds the operator on the position-welded mesh, checks that every connected component has
 * a constraint (a component without one makes the system singular and CHOLMOD would not say
 * so), and factors once. The mesh and params must outlive the edit (handles are read at each
 * evaluation). allocator may be NULL. */
mk_result mk_surface_edit_create(const mk_raw_mesh *mesh, const mk_edit_params *params,
                                 const mk_allocator *allocator, mk_surface_edit **out,
                                 mk_error *err);
/* Deformed positions at amplitude a (mk_deformer.eval signature; normals/tangents unused,
 * they are recomputed from the deformed surface). */
mk_result mk_surface_edit_eval(void *edit, double amplitude, double *positions, double *normals,
                               double *tangents, uint32_t *inverted, mk_error *err);
/* Applies the edit's operator to per-render-vertex values x (3 per vertex) on the welded mesh:
 * L = I - D^-1 W (Laplacian editing) or the positive-diagonal L_ii = sum w_ij, L_ij = -w_ij
 * (ARAP); out gets 3 per render vertex. For tests: constants are in the kernel. */
void mk_surface_edit_apply_operator(const mk_surface_edit *edit, const double *x, double *out);
void mk_surface_edit_stats(const mk_surface_edit *edit, mk_solver_stats *stats);
void mk_surface_edit_destroy(mk_surface_edit *edit);

#endif

/* SPDX-License-Identifier: MIT */
/* Thin shell contracting under external pressure: a position-based dynamics simulation
 * (docs/baking.md, "shell"). Internal to baker/.
 *
 * Everything works on the position-welded mesh in double precision. Per substep (a frame has
 * enough of them for the sweeps to carry the membrane's stress across the mesh, shell_steps.c):
 * symplectic Euler prediction under the pressure force, a few nonlinear Gauss-Seidel sweeps
 * projecting the elastic, bending and anisotropic energies as XPBD constraints C = sqrt(2 W) with
 * compliance 1 (so that (1/2) C^2 is the energy W itself), velocities from positions. Per frame:
 * continuous collision handling over the frame's motion.
 *
 * The element energies are pure functions of positions (shell_elastic.c, shell_bending.c,
 * shell_aniso.c) returning W and its gradient, so tests compare them with finite differences.
 */
#ifndef SHELL_H
#define SHELL_H

#include "raw.h"
#include "parallel.h"

typedef enum shell_material {
    SHELL_STVK, SHELL_COROTATED, SHELL_LINEAR, SHELL_MOONEY_RIVLIN
} shell_material;

typedef enum shell_aniso_energy {
    SHELL_ANISO_ARAP, SHELL_ANISO_SQRT, SHELL_ANISO_STVK
} shell_aniso_kind;

/* Deformation gradient F = [x1 - x0, x2 - x0] Dm^-1 (3x2, column-major); Dm_inv is 2x2
 * row-major. */
void shell_deformation_gradient(const double *x0, const double *x1, const double *x2,
                                const double Dm_inv[4], double F[6]);
/* Gradient of area * psi with respect to x0, x1, x2 (9 doubles) from P: [g1 g2] = area P Dm^-T,
 * g0 = -(g1 + g2). */
void shell_gradient_from_stress(const double P[6], const double Dm_inv[4], double area, double grad[9]);

/* In-plane elastic energy of one triangle (area * psi) and its gradient (9 doubles). */
double shell_membrane_energy(shell_material material, double mu, double lambda, const double Dm_inv[4],
                             const double basis[6], double area, const double *x0, const double *x1,
                             const double *x2, double grad[9]);

/* shell_membrane_energy with SHELL_STVK for count <= SHELL_BATCH triangles (corners x[j][0..2],
 * their Dm_inv and area), bit for bit the same, written to overlap the triangles' work. */
void shell_stvk_batch(double mu, double lambda, uint32_t count, const double *x[][3], const double *const Dm_inv[],
                      const double area[], double W[], double grad[][12]);

/* Bending energy of one hinge: (kB / 2) * scale * (|v| - rest)^2 with v = sum_j K_j x_j
 * (x0, x1 the hinge edge, x2, x3 the opposite vertices), scale = 3 / (A0 + A1). Gradient:
 * 12 doubles. */
double shell_bending_energy(const double K[4], double scale, double rest, double kB, const double *const x[4],
                            double grad[12]);

/* XPBD projections of count <= SHELL_BATCH hinges that share no vertex, each with the signed
 * constraint C = root (|v| - rest), whose square is 2W of shell_bending_energy (root =
 * sqrt(kB scale)), inverse masses w (read only): grad_j C = root K_j v / |v|, so sum_j w_j |grad_j C|^2 =
 * root^2 sum_j w_j K_j^2 does not depend on the positions. Adds each step to *lambda[i] and gives
 * u[i]: vertex j of hinge i moves by w_j K_j u[i]. W[i]: the energy before the step. */
void shell_bending_steps(uint32_t count, const double *const K[], double w[][4], const double root[],
                         const double rest[], double alpha, const double *x[][4], double *const lambda[], double W[],
                         double u[][3]);

/* Anisotropic energy of one triangle, area * psi_a with I5 = |F a|^2 along the unit fibre a (2D,
 * rest frame): arap (mu/2)(sqrt(I5) - s)^2 with s = sign(I4) given by the caller (+1 or -1),
 * sqrt (mu/2)(sqrt(I5) - 1)^2, stvk (mu/8)(I5 - 1)^2. Gradient: 9 doubles. */
double shell_aniso_energy(shell_aniso_kind kind, double mu, double sign, const double fibre[2],
                          const double Dm_inv[4], double area, const double *x0, const double *x1,
                          const double *x2, double grad[9]);

/* The welded mesh and its rest data. */
typedef struct shell_mesh {
    uint32_t n;               /* welded vertices */
    uint32_t *weld;           /* render vertex -> welded vertex */
    uint32_t tri_count;
    uint32_t *tris;           /* 3 welded indices per triangle */
    double *rest;             /* 3 per welded vertex */
    double *Dm_inv;           /* 4 per triangle (2x2 row-major) */
    double *basis;            /* 6 per triangle: rest axes e1, e2 */
    double *area;             /* per triangle, rest */
    uint32_t hinge_count;
    uint32_t *hinges;         /* 4 per interior edge: edge x0, x1, opposite x2, x3 */
    double *hinge_K;          /* 4 per hinge */
    double *hinge_scale;      /* 3 / (A0 + A1) */
    double *hinge_rest;       /* |sum K_j X_j| at rest */
    uint32_t *hinge_tri;      /* a triangle with the edge x0 x1 and the vertex x2 */
    double *inv_mass;         /* per welded vertex */
    uint32_t *corner_start;   /* per welded vertex (n + 1): its corners corners[corner_start[v] ..) */
    uint32_t *corners;        /* 3 t + k for corner k of triangle t, increasing per vertex */
    double volume0;
} shell_mesh;

/* Welds the render mesh, checks it is closed (every edge shared by exactly two triangles, in
 * opposite directions) and encloses a positive volume, builds the rest data. density: mass per
 * unit area. Memory from arena. */
mk_result shell_mesh_build(const mk_raw_mesh *mesh, double density, mk_arena *arena, shell_mesh *out, mk_error *err);

/* A sweep's order of its elements (shell_order.c): phases, one after the other; phase f has
 * parts phase_part[f] .. phase_part[f + 1], which share no vertex with each other (swept at the
 * same time); part q is batches part_batch[q] .. part_batch[q + 1]; batch b is
 * order[start[b] .. start[b + 1]): at most SHELL_BATCH elements that share no vertex, taken from
 * the next SHELL_BATCH_WINDOW elements of its part not yet placed, in mesh order. The first
 * phases have up to count / SHELL_PART_MIN parts (at least 1, at most SHELL_PARTS_MAX), the last
 * possible one (SHELL_PHASES_MAX) one part. */
#define SHELL_BATCH 4
#define SHELL_BATCH_WINDOW 32
#define SHELL_PART_MIN 2048
#define SHELL_PARTS_MAX 16
#define SHELL_PHASES_MAX 4
typedef struct shell_sweep_order {
    uint32_t *order;
    uint32_t *start;          /* batch_count + 1 */
    uint32_t batch_count;
    uint32_t phase_count;
    uint32_t phase_part[SHELL_PHASES_MAX + 1];
    uint32_t part_count;
    uint32_t part_batch[SHELL_PHASES_MAX * SHELL_PARTS_MAX + 1];
} shell_sweep_order;

/* The most parts a phase of count elements has: count / SHELL_PART_MIN, at least 1, at most
 * SHELL_PARTS_MAX. */
uint32_t shell_sweep_parts(uint32_t count);
/* The order of count elements of k vertex indices each (idx), vertices below n. */
mk_result shell_sweep_order_build(const uint32_t *idx, int k, uint32_t count, uint32_t n, mk_arena *arena,
                                  shell_sweep_order *out, mk_error *err);

/* Enclosed volume (1/6) sum x_a . (x_b x_c), and optionally its gradient (3 per vertex). */
double shell_volume(const shell_mesh *m, const double *x, double *grad);
/* The volume's gradient at vertices [first, last) alone (grad holds 3 per vertex), the same
 * bits as shell_volume's: each vertex sums its triangles' terms in triangle order. Vertex ranges
 * can run on several threads. */
void shell_volume_gradient(const shell_mesh *m, const double *x, double *grad, uint32_t first, uint32_t last);
/* Area-weighted unit vertex normals of positions x (3 per vertex). */
void shell_vertex_normals(const shell_mesh *m, const double *x, double *normals);

typedef struct shell_params {
    double pressure;          /* external pressure P: force -P dV/dx */
    double ramp;              /* seconds over which the pressure rises linearly from 0 to P (0: at once) */
    double dt;                /* seconds per frame */
    uint32_t frames;          /* frame limit */
    uint32_t iterations;      /* Gauss-Seidel sweeps per substep */
    uint32_t substeps;        /* substeps per frame; 0: shell_substeps chooses */
    double density;           /* mass per unit area */
    double damping;           /* velocities scaled by (1 - damping) each frame */
    shell_material material;
    double mu, lambda;        /* Lame parameters of the membrane (per unit area) */
    double kB;                /* bending stiffness */
    double epsilon;           /* stop when V / V0 < epsilon */
    double thickness;         /* collision thickness (mesh units); 0 = no collision handling */
    /* Anisotropic region: per welded vertex flag (NULL: none); a triangle is in the region when
     * all its vertices are. */
    const unsigned char *aniso_region;
    shell_aniso_kind aniso_energy;
    double aniso_mu;          /* stiffness of the anisotropic energy */
    double aniso_kA;          /* inward pressure on region vertices (force k_A times the vertex's rest area) */
    double aniso_direction[3];/* fibre direction (world), projected into each triangle */
    uint32_t threads;         /* threads for the sweeps (0: one per core); the result does not depend on it */
} shell_params;

/* Upper limit of the automatic substep count. */
#define SHELL_MAX_SUBSTEPS 64

/* Area-weighted mean over the triangles of their natural in-plane frequency (rad/s), from the
 * membrane's (and the anisotropic region's) stiffness, the rest areas and the lumped masses
 * (shell_steps.c). */
double shell_membrane_frequency(const shell_mesh *m, const shell_params *p);
/* p->substeps if set, else the fewest substeps h = dt / n with h omega <= sqrt(iterations)
 * (omega from shell_membrane_frequency), at most SHELL_MAX_SUBSTEPS. */
uint32_t shell_substeps(const shell_mesh *m, const shell_params *p);

/* What one frame measured (the log). */
typedef struct shell_frame_stats {
    double time;              /* seconds simulated */
    double volume_ratio;      /* V / V0 */
    double membrane, bending, aniso;  /* energies at the end of the frame */
    uint32_t vt_hits, ee_hits;        /* collisions found (vertex-triangle, edge-edge) */
    uint32_t collision_rounds;        /* CCD rounds this frame */
    double ms_step, ms_collision;     /* wall time: whole frame, collision part */
} shell_frame_stats;

typedef struct shell_run {
    uint32_t frames;          /* frames simulated (the last one is frames) */
    uint32_t substeps;        /* substeps per frame used */
    float *positions;         /* (frames + 1) * 3n floats: frame f at 3 n f (frame 0 = rest) */
    shell_frame_stats *stats; /* frames + 1 entries (entry 0: the rest state) */
    int stopped_by_epsilon;
} shell_run;

/* Runs the simulation (memory from arena). progress(user, fraction) may be NULL. */
mk_result shell_simulate(const shell_mesh *m, const shell_params *p, mk_arena *arena,
                         void (*progress)(void *user, double fraction), void *user, shell_run *run,
                         mk_error *err);

/* Collision handling (shell_collide.c): the broad phase's hierarchy over the triangles, built
 * once on the rest mesh and refitted every frame. NULL when out of memory. */
typedef struct shell_collider shell_collider;
shell_collider *shell_collider_create(const shell_mesh *m, mk_arena *arena);

/* Collision handling between the collision-free positions x and the new positions p: moves
 * colliding vertices back until no vertex-triangle or edge-edge pair crosses over the step and
 * no vertex is closer than thickness to a triangle it did not start closer to. Returns the hits
 * found (*vt, *ee) and rounds. The box tests and the narrow phase run on team (may be NULL);
 * the result does not depend on it. */
mk_result shell_collide(shell_collider *col, const shell_mesh *m, const double *x, double *p, double thickness,
                        mk_team *team, mk_arena *arena, uint32_t *vt, uint32_t *ee, uint32_t *rounds, mk_error *err);

/* The per-frame log as CSV (a header line, then one line per frame): *size bytes of arena memory,
 * NUL-terminated; NULL when out of memory. */
char *shell_log_csv(const shell_run *run, mk_arena *arena, size_t *size);

#endif

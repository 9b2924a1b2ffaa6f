/* SPDX-License-Identifier: MIT */
/* Turning a deformation into a channel: targets, in-betweens, playback error.
 *
 * A deformer is a function of an amplitude a in [0, 1] (0 = rest, 1 = full deformation). The
 * channel's weight w plays amplitude w: the runtime interpolates piecewise linearly between
 * the targets (docs/semantics.md, with the implicit zero key at w = 0), so a
 * deformation that is not linear in a (a twist, a bend, ARAP) needs in-between targets to
 * follow its curved path. mk_bake_channel places them, fixed or adaptively.
 */
#ifndef MK_INBETWEEN_H
#define MK_INBETWEEN_H

#include "raw.h"

typedef struct mk_deformer {
    /* Deformed positions at amplitude a: 3 doubles per render vertex (required output).
     * normals / tangents (3 doubles per vertex, unit) are requested only when
     * analytic_normals is set and the mesh has base normals / tangents; NULL otherwise.
     * inverted (may be NULL) receives the number of vertices where det J <= 0. Must be
     * deterministic, and a = 0 must give the rest positions. */
    mk_result (*eval)(void *user, double amplitude, double *positions, double *normals,
                      double *tangents, uint32_t *inverted, mk_error *err);
    void *user;
    int analytic_normals;  /* 1: targets get normal deltas from eval; 0: recomputed from the surface */
    int expensive;         /* 1: one evaluation costs a solve; fixed counts skip the grid check */
} mk_deformer;

typedef struct mk_inbetween_options {
    uint32_t count;        /* fixed number of targets at weights k/count; 0 = adaptive ("auto") */
    double tolerance;      /* adaptive: max playback error, fraction of the bbox diagonal; 0 = 0.001 */
    uint32_t samples;      /* sampled weights are k/samples, k = 1..samples; 0 = 100 (step 0.01) */
    uint32_t max_targets;  /* adaptive: fail above this many targets; 0 = 64 */
    const double *weights; /* fixed count: the targets' full weights (count increasing values in
                            * (0, 1], the last 1); NULL = k/count */
} mk_inbetween_options;

typedef struct mk_inbetween_result {
    uint32_t targets;           /* targets written */
    uint32_t evaluations;       /* deformer evaluations */
    double max_error;           /* playback error, fraction of the bbox diagonal */
    int error_on_grid;          /* 1: measured at every sampled weight; 0: at span midpoints */
    uint32_t moved_vertices;    /* vertices stored in the last target */
    uint32_t inverted_vertices; /* max over targets of the deformer's inverted count */
    /* With error_on_grid: the playback error at every sampled weight k / curve_samples,
     * k = 0..curve_samples (fraction of the bbox diagonal), and the targets' full weights;
     * from raw's arena (they live as long as raw). NULL / 0 otherwise. */
    const double *error_curve;
    uint32_t curve_samples;
    const float *key_weights;
    double tolerance;           /* the tolerance the placement aimed at (adaptive), or 0 */
} mk_inbetween_result;

/* Adds one channel named `name` (origin: recipe JSON or NULL) to `mesh` of raw, holding the
 * deformation as targets. Adaptive placement: starting at w = 0, each next in-between is the
 * largest sampled weight such that linear playback between it and the previous key stays
 * within 0.99 x tolerance at every sampled weight in between (greedy, which is optimal for
 * covering an interval when the error grows with span length); the last target is at w = 1.
 * Vertices whose position delta is below 1e-7 x diagonal and whose normal/tangent deltas are
 * below 1e-6 are not stored (sparse targets). On error raw keeps its previous channels. */
mk_result mk_bake_channel(mk_raw_asset *raw, uint32_t mesh, const char *name, const char *origin,
                          const mk_deformer *deformer, const mk_inbetween_options *options,
                          void (*progress)(void *user, const char *stage, double fraction),
                          void *user, mk_inbetween_result *result, mk_error *err);

/* Appends one target (full weight `weight`, named `name`) to `channel` of mesh `mesh`: the deltas
 * of pos (3 doubles per vertex) from the base positions, and of nrm / tan (3 per vertex, NULL:
 * none stored) from the base normals / tangents. Vertices moving less than 1e-7 x diagonal (and
 * whose normal/tangent deltas are below 1e-6) are not stored; *moved gets the stored count.
 * Fails on a value that is not finite. The one way every baker writes a target. */
mk_result bake_store_target(mk_raw_asset *raw, mk_raw_channel *channel, uint32_t mesh, double weight,
                            const char *name, double diagonal, const double *pos, const double *nrm,
                            const double *tan, uint32_t *moved, mk_error *err);

#endif

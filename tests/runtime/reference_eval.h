/* SPDX-License-Identifier: MIT */
/* A second evaluator, for tests only: docs/semantics.md ("Channel displacement", "Stacking",
 * "Normals and tangents") written out in double precision, one vertex and one channel at a
 * time, straight from the raw model (offline/raw.h). It shares nothing with the runtime or
 * the writer: no blocks, no blob layout, no per-job coefficient tables or suffix products, no
 * mk_channel_span. Sequential stacking is the recurrence d_c = (1 - beta_c) d_{c-1} + D_c(w_c)
 * as written, not its unrolled form.
 *
 * Besides the values it returns bounds on how far a correct float32 runtime reading the
 * written blob may be from them (float rounding, and the quantization error of quantized deltas
 * the writer reports), and ref_compare checks runtime outputs against both. */
#ifndef MK_REFERENCE_EVAL_H
#define MK_REFERENCE_EVAL_H

#include <stdint.h>
#include "raw.h"

/* Largest error of one stored delta component, per attribute: 0 for a float32 blob, the
 * writer's reported max quantization errors (mk_write_report) for a quantized one. */
typedef struct ref_stored_error {
    double position, normal, tangent;
} ref_stored_error;

typedef struct ref_job {
    const mk_raw_asset *raw;
    uint32_t mesh;
    uint32_t first_channel, channel_count;  /* the mesh's channels in the raw model (set by ref_job_init) */
    const float *weights;                   /* one per channel of the mesh, mesh-local order */
    mk_stacking stacking;                   /* MK_STACKING_ADDITIVE or MK_STACKING_SEQUENTIAL */
    mk_normal_mode normal_mode;
    ref_stored_error stored;
} ref_job;

typedef struct ref_vertex {
    double position[3];
    double normal[3];              /* normalize(B_n + d_n), or B_n where that sum is shorter than 1e-8 */
    double tangent[4];             /* xyz as the normal (nlerp), w = base w */
    double normal_length;          /* |B_n + d_n| before normalizing */
    double tangent_length;         /* |B_t + d_t| */
    /* Bounds on |runtime - reference| (tolerance bookkeeping, not semantics): */
    double position_tolerance[3];  /* per component */
    double normal_error;           /* of the vector B_n + d_n (Euclidean length) */
    double tangent_error;          /* of B_t + d_t */
    int normal_unstable;           /* slerp ends so nearly opposite, or a sum so close to the
                                    * 1e-8 fallback threshold, that float32 may take the other
                                    * branch: the normal is not comparable */
} ref_vertex;

/* Fills job for mesh `mesh` of raw (channels grouped by mesh, as mk_raw_validate requires). */
void ref_job_init(ref_job *job, const mk_raw_asset *raw, uint32_t mesh, const float *weights, mk_stacking stacking,
                  mk_normal_mode normal_mode, ref_stored_error stored);

/* Evaluates render vertex v of the job's mesh. */
void ref_eval_vertex(const ref_job *job, uint32_t v, ref_vertex *out);

/* The first mismatch ref_compare found. */
typedef struct ref_mismatch {
    uint32_t vertex;
    const char *what;              /* "position", "normal", "tangent", ... */
    int component;                 /* 0..3, or -1 for an angle */
    double got, expected, tolerance;
} ref_mismatch;

typedef struct ref_stats {
    uint64_t vertices;             /* compared */
    uint64_t normals_skipped;      /* unstable normals (see ref_vertex) */
    double worst_ratio[3];         /* largest |error| / tolerance (nonzero tolerances) of
                                    * positions, normal angles, tangent angles */
} ref_stats;

/* Evaluates every vertex of the job's mesh into out[vertex_count]. */
void ref_eval_mesh(const ref_job *job, ref_vertex *out);

/* Compares runtime outputs for the job's vertices [first, first + count) (outputs packed: 3,
 * 3 and 4 floats per vertex, addressing vertex `first`; normals/tangents may be NULL) with the
 * reference values `expected` (indexed by vertex, from ref_eval_mesh). Returns the number of
 * mismatching values; the first one goes to *mismatch. */
uint32_t ref_compare(const ref_job *job, const ref_vertex *expected, uint32_t first, uint32_t count,
                     const float *positions, const float *normals, const float *tangents, ref_mismatch *mismatch,
                     ref_stats *stats);

#endif

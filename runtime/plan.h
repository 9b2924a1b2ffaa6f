/* SPDX-License-Identifier: MIT */
/* A frame's plan (private): what the weights of one frame make of a mesh's targets, computed
 * once per frame and read by every block. The CPU evaluator keeps it in its scratch; the GPU
 * path uploads the same bytes (mk_gpu_plan_run), so both read one layout, written by one
 * function:
 *
 *   [0, A)        float   coef[target_count]           A = align16(4 * target_count)
 *   [A, 2A)       int32   slerp_channel[target_count]  mesh-local channel, or -1
 *   [2A, 2A + S)  mk_plan_span spans[channel_count]    S = 16 * channel_count
 *
 * coef[t] is target t's displacement factor (docs/semantics.md: the channel's span factor times
 * the sequential suffix product; 0 for inactive targets). With slerp normals, the targets of a
 * channel's active span name that channel in slerp_channel, and its span says which two targets
 * it interpolates, where in the span the weight lies and its sequential factor. */
#ifndef MK_RUNTIME_PLAN_H
#define MK_RUNTIME_PLAN_H

#include <stddef.h>
#include <stdint.h>
#include "format.h"
#include "morphkit.h"

typedef struct mk_plan_span {
    int32_t target_a, target_b;  /* mesh-local targets, -1 = implicit zero key */
    float t;                     /* position in the span (may be outside [0,1]: extrapolation) */
    float scale;                 /* sequential suffix product (1 for additive) */
} mk_plan_span;

/* Pointers into a plan's bytes. */
typedef struct mk_plan {
    float *coef;
    int32_t *slerp_channel;
    mk_plan_span *spans;
} mk_plan;

/* Bytes of the plan of a mesh with these counts (each part 16-aligned). */
size_t mk_plan_bytes(uint32_t target_count, uint32_t channel_count);

/* The plan's parts in memory of mk_plan_bytes (16-byte aligned). */
mk_plan mk_plan_at(void *memory, uint32_t target_count);

/* Checks the frame's inputs as every job does: weight count, finite weights, known stacking and
 * normal mode. */
mk_result mk_plan_validate_weights(const mk_blob_mesh *m, const float *weights, uint32_t weight_count,
                                   mk_stacking stacking, mk_normal_mode normal_mode, const char *job, mk_error *err);

/* Fills the plan of mesh m for valid weights (one per mesh channel). stacking: the job's
 * (MK_STACKING_ASSET takes the mesh's); slerp: whether normals slerp. Costs O(targets +
 * channels), nothing per vertex. */
void mk_plan_fill(const mk_asset *a, const mk_blob_mesh *m, const float *weights, mk_stacking stacking, int slerp,
                  const mk_plan *plan);

#endif

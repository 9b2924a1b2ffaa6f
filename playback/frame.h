/* SPDX-License-Identifier: MIT */
/* One evaluated frame of an asset through the runtime's public jobs: weights from a clip or
 * the defaults, a mesh's positions and normals, the world transform. Shared by play, conform,
 * bench, render and the tests. */
#ifndef MK_PB_FRAME_H
#define MK_PB_FRAME_H

#include "morphkit.h"

/* weights (asset channel count) = channel defaults, then the clip sampled at time if clip >= 0. */
mk_result pb_frame_weights(const mk_asset *asset, int32_t clip, double time, float *weights, mk_error *err);

/* Where a mesh is evaluated: the CPU runtime (a NULL evaluator or eval) or another path with
 * the same meaning, such as the GPU one (tools/gpu_eval.h). eval fills positions (3 floats per
 * vertex) and, where non-NULL, normals (3) and tangents (4) of the whole mesh for asset-wide
 * weights. */
typedef struct pb_evaluator {
    mk_result (*eval)(void *user, const mk_asset *asset, uint32_t mesh, const float *weights, mk_stacking stacking,
                      mk_normal_mode normal_mode, float *positions, float *normals, float *tangents, mk_error *err);
    void *user;
} pb_evaluator;

/* Evaluates mesh positions (and normals and tangents where non-NULL and the mesh has them) for
 * asset-wide weights through the evaluator. stacking 0 = the blob's. Scratch is allocated here
 * (tools may allocate). */
mk_result pb_eval_mesh_with(const pb_evaluator *evaluator, const mk_asset *asset, uint32_t mesh, const float *weights,
                            mk_stacking stacking, mk_normal_mode normals_mode, float *positions, float *normals,
                            float *tangents, mk_error *err);
/* pb_eval_mesh_with on the CPU runtime, without tangents. */
mk_result pb_eval_mesh(const mk_asset *asset, uint32_t mesh, const float *weights, mk_stacking stacking,
                       mk_normal_mode normals_mode, float *positions, float *normals, mk_error *err);

/* A mesh's surface-normal topology and scratch (mk_surface_*), built once and used for any
 * number of frames. */
typedef struct pb_surface {
    const mk_asset *asset;
    uint32_t mesh;
    void *topology, *scratch;
    size_t topology_size, scratch_size;
} pb_surface;

/* Builds s for mesh (MK_ERROR_UNSUPPORTED without normals or triangles); s is freed on error. */
mk_result pb_surface_prepare(pb_surface *s, const mk_asset *asset, uint32_t mesh, mk_error *err);
/* Surface normals (and tangents when non-NULL) of the whole mesh from its evaluated positions. */
mk_result pb_surface_run(const pb_surface *s, const float *positions, float *normals, float *tangents, mk_error *err);
void pb_surface_free(pb_surface *s);

/* prepare + run + free, for one frame. */
mk_result pb_surface_normals(const mk_asset *asset, uint32_t mesh, const float *positions, float *normals,
                             float *tangents, mk_error *err);

/* mk_channel_span for asset channel `channel` at weight w (any number of in-betweens): the
 * two contributing targets as indices into the channel's targets (-1 = implicit zero key). */
void pb_channel_span(const mk_asset *asset, uint32_t channel, float w, int32_t *ia, float *ca, int32_t *ib, float *cb);

/* In place: p = W p (points), n = normalize((W^-1)^T n). */
void pb_to_world(const float world[16], float *positions, float *normals, uint32_t count);

#endif

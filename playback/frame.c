/* SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "frame.h"

mk_result pb_frame_weights(const mk_asset *asset, int32_t clip, double time, float *weights, mk_error *err)
{
    for (uint32_t c = 0; c < asset->channel_count; c++) {
        mk_channel_info info;
        mk_channel_get(asset, c, &info);
        weights[c] = info.default_weight;
    }
    if (clip < 0) return MK_OK;
    mk_sample_job job = {
        .asset = asset, .clip = (uint32_t)clip, .time = time, .weights = weights, .weight_count = asset->channel_count
    };
    return mk_sample_run(&job, err);
}

mk_result pb_eval_mesh_with(const pb_evaluator *evaluator, const mk_asset *asset, uint32_t mesh, const float *weights,
                            mk_stacking stacking, mk_normal_mode normals_mode, float *positions, float *normals,
                            float *tangents, mk_error *err)
{
    mk_mesh_info m;
    if (!mk_mesh_get(asset, mesh, &m))
        return mk_error_set(err, MK_ERROR_OUT_OF_RANGE, UINT64_MAX, "mesh %u does not exist (%u meshes)", mesh,
                            asset->mesh_count);
    if (!m.has_normals) normals = NULL;
    if (!m.has_tangents) tangents = NULL;
    if (evaluator && evaluator->eval)
        return evaluator->eval(evaluator->user, asset, mesh, weights, stacking, normals_mode, positions, normals,
                               tangents, err);
    size_t scratch_size = mk_eval_scratch_size(asset, mesh);
    void *scratch = aligned_alloc(16, (scratch_size + 31) & ~(size_t)15); /* never 0 bytes */
    if (!scratch) return mk_error_oom(err, "evaluation scratch");
    mk_eval_job job = {
        .asset = asset,
        .mesh = mesh,
        .vertex_count = MK_VERTICES_TO_END,
        .weights = weights + m.first_channel,
        .weight_count = m.channel_count,
        .stacking = stacking,
        .normal_mode = normals_mode,
        .scratch = scratch,
        .scratch_size = scratch_size,
        .positions = positions,
        .positions_size = (size_t)m.vertex_count * 12,
        .normals = normals,
        .normals_size = (size_t)m.vertex_count * 12,
        .tangents = tangents,
        .tangents_size = (size_t)m.vertex_count * 16,
    };
    mk_result r = mk_eval_run(&job, err);
    free(scratch);
    return r;
}

mk_result pb_eval_mesh(const mk_asset *asset, uint32_t mesh, const float *weights, mk_stacking stacking,
                       mk_normal_mode normals_mode, float *positions, float *normals, mk_error *err)
{
    return pb_eval_mesh_with(NULL, asset, mesh, weights, stacking, normals_mode, positions, normals, NULL, err);
}

mk_result pb_surface_prepare(pb_surface *s, const mk_asset *asset, uint32_t mesh, mk_error *err)
{
    memset(s, 0, sizeof *s);
    s->asset = asset;
    s->mesh = mesh;
    s->topology_size = mk_surface_topology_size(asset, mesh);
    s->scratch_size = mk_surface_scratch_size(asset, mesh);
    if (s->topology_size) {
        s->topology = aligned_alloc(16, (s->topology_size + 15) & ~(size_t)15);
        s->scratch = aligned_alloc(16, (s->scratch_size + 15) & ~(size_t)15);
        if (!s->topology || !s->scratch) {
            pb_surface_free(s);
            return mk_error_oom(err, "surface topology");
        }
    }
    mk_result r = mk_surface_topology_build(asset, mesh, s->topology, s->topology_size, err);
    if (r != MK_OK) pb_surface_free(s);
    return r;
}

mk_result pb_surface_run(const pb_surface *s, const float *positions, float *normals, float *tangents, mk_error *err)
{
    mk_mesh_info m;
    mk_mesh_get(s->asset, s->mesh, &m);
    mk_surface_job job = {
        .asset = s->asset,
        .mesh = s->mesh,
        .topology = s->topology,
        .topology_size = s->topology_size,
        .positions = positions,
        .positions_size = (size_t)m.vertex_count * 12,
        .vertex_count = MK_VERTICES_TO_END,
        .normals = normals,
        .normals_size = (size_t)m.vertex_count * 12,
        .tangents = tangents,
        .tangents_size = (size_t)m.vertex_count * 16,
        .scratch = s->scratch,
        .scratch_size = s->scratch_size,
    };
    return mk_surface_run(&job, err);
}

void pb_surface_free(pb_surface *s)
{
    free(s->topology);
    free(s->scratch);
    s->topology = s->scratch = NULL;
}

mk_result pb_surface_normals(const mk_asset *asset, uint32_t mesh, const float *positions, float *normals,
                             float *tangents, mk_error *err)
{
    pb_surface s;
    mk_result r = pb_surface_prepare(&s, asset, mesh, err);
    if (r == MK_OK) r = pb_surface_run(&s, positions, normals, tangents, err);
    pb_surface_free(&s);
    return r;
}

void pb_channel_span(const mk_asset *asset, uint32_t channel, float w, int32_t *ia, float *ca, int32_t *ib, float *cb)
{
    mk_channel_info ch;
    mk_channel_get(asset, channel, &ch);
    float small[64], *full = ch.target_count <= 64 ? small : malloc(ch.target_count * sizeof(float));
    uint32_t n = full ? ch.target_count : 0;
    for (uint32_t k = 0; k < n; k++) {
        mk_target_info t;
        mk_target_get(asset, channel, k, &t);
        full[k] = t.full_weight;
    }
    mk_channel_span(full, n, w, ia, ca, ib, cb, NULL);
    if (full != small) free(full);
}

void pb_to_world(const float w[16], float *positions, float *normals, uint32_t count)
{
    /* Column-major: x' = w[0] x + w[4] y + w[8] z + w[12]. */
    double a = w[0], b = w[4], c = w[8], d = w[1], e = w[5], f = w[9], g = w[2], h = w[6], i = w[10];
    double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    /* Cofactor matrix = det * (M^-1)^T: normals only need its direction. */
    double cof[9] = { e * i - f * h,    -(d * i - f * g), d * h - e * g,    -(b * i - c * h), a * i - c * g,
                      -(a * h - b * g), b * f - c * e,    -(a * f - c * d), a * e - b * d };
    double sign = det < 0 ? -1.0 : 1.0;
    for (uint32_t v = 0; v < count; v++) {
        float *p = &positions[3u * v];
        double x = p[0], y = p[1], z = p[2];
        p[0] = (float)(w[0] * x + w[4] * y + w[8] * z + w[12]);
        p[1] = (float)(w[1] * x + w[5] * y + w[9] * z + w[13]);
        p[2] = (float)(w[2] * x + w[6] * y + w[10] * z + w[14]);
        if (!normals) continue;
        float *n = &normals[3u * v];
        double nx = n[0], ny = n[1], nz = n[2];
        double ox = sign * (cof[0] * nx + cof[1] * ny + cof[2] * nz);
        double oy = sign * (cof[3] * nx + cof[4] * ny + cof[5] * nz);
        double oz = sign * (cof[6] * nx + cof[7] * ny + cof[8] * nz);
        double len = sqrt(ox * ox + oy * oy + oz * oz);
        if (len > 0) {
            n[0] = (float)(ox / len);
            n[1] = (float)(oy / len);
            n[2] = (float)(oz / len);
        }
    }
}

/* SPDX-License-Identifier: MIT */
/* A frame's per-target coefficients (plan.h): the part of an evaluation that depends on the
 * weights alone, shared by the CPU evaluator (eval.c) and the GPU path (mk_gpu_plan_run).
 *
 * Every target of the mesh gets one scalar coefficient from the channel weights
 * (mk_channel_span: piecewise-linear through the implicit (0,0) key and the targets' full
 * weights, extrapolated at both ends). Sequential stacking
 *     d_c = (1 - beta_c) d_{c-1} + D_c(w_c)
 * unrolls to d = sum_c D_c * prod_{c' > c} (1 - beta_c'), so it only multiplies each channel's
 * coefficients by a suffix product: it costs what additive costs. */
#include <math.h>
#include <string.h>
#include "plan.h"
#include "error.h"
#include "determinism.h"

/* Full weights read with a byte stride, so the plan can read them straight from the target
 * records and tools from a plain float array. */
static float full_weight_at(const float *full_weights, size_t stride, uint32_t k)
{
    return *(const float *)(const void *)((const uint8_t *)full_weights + stride * k);
}

static void channel_span_strided(const float *full_weights, size_t stride, uint32_t count, float w,
                                 int32_t *ia, float *ca, int32_t *ib, float *cb, float *t_out)
{
    /* Key points sorted by full weight with the implicit zero key inserted after the
     * negative ones: virtual index j -> (weight, target), target -1 = the zero key. */
    if (count == 0) {       /* no targets: D(w) = 0 */
        *ia = *ib = -1;
        *ca = *cb = 0.0f;
        if (t_out) *t_out = 0.0f;
        return;
    }
    uint32_t zero = 0;
    while (zero < count && full_weight_at(full_weights, stride, zero) < 0) zero++;
#define KEY_W(j) ((j) < zero ? full_weight_at(full_weights, stride, (j)) \
                  : (j) == zero ? 0.0f : full_weight_at(full_weights, stride, (j) - 1))
#define KEY_T(j) ((j) < zero ? (int32_t)(j) : (j) == zero ? -1 : (int32_t)(j) - 1)
    /* Span j covers [key j, key j+1]; outside the range the first/last span extrapolates.
     * Linear search: channels have few in-betweens and the search runs once per frame. */
    uint32_t j = 0;
    while (j + 1 < count && w > KEY_W(j + 1)) j++;
    float wa = KEY_W(j), wb = KEY_W(j + 1);
    float t = (w - wa) / (wb - wa);
    *ia = KEY_T(j);
    *ib = KEY_T(j + 1);
    *ca = 1.0f - t;
    *cb = t;
    if (t_out) *t_out = t;
#undef KEY_W
#undef KEY_T
}

void mk_channel_span(const float *full_weights, uint32_t count, float w,
                     int32_t *ia, float *ca, int32_t *ib, float *cb, float *t_out)
{
    channel_span_strided(full_weights, sizeof(float), count, w, ia, ca, ib, cb, t_out);
}

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

size_t mk_plan_bytes(uint32_t target_count, uint32_t channel_count)
{
    return 2 * align16((size_t)target_count * sizeof(float)) + align16((size_t)channel_count * sizeof(mk_plan_span));
}

mk_plan mk_plan_at(void *memory, uint32_t target_count)
{
    uint8_t *p = memory;
    const size_t per_target = align16((size_t)target_count * sizeof(float));
    mk_plan plan = {
        .coef = (float *)(void *)p,
        .slerp_channel = (int32_t *)(void *)(p + per_target),
        .spans = (mk_plan_span *)(void *)(p + 2 * per_target),
    };
    return plan;
}

/* "JOB: WHAT" as the job's error. */
static mk_result job_fail(mk_error *err, mk_result code, const char *job, const char *what)
{
    mk_error_start(err, code, MK_NO_OFFSET);
    mk_error_text(err, job);
    mk_error_text(err, what);
    return mk_error_end(err, code);
}

mk_result mk_plan_validate_weights(const mk_blob_mesh *m, const float *weights, uint32_t weight_count,
                                   mk_stacking stacking, mk_normal_mode normal_mode, const char *job, mk_error *err)
{
    if (weight_count != m->channel_count)
        return job_fail(err, MK_ERROR_OUT_OF_RANGE, job, ": weight_count differs from the mesh's channel count");
    if (m->channel_count && !weights) return job_fail(err, MK_ERROR_INVALID_ARGUMENT, job, ": weights is NULL");
    for (uint32_t c = 0; c < m->channel_count; c++)
        if (!isfinite(weights[c])) return job_fail(err, MK_ERROR_NOT_FINITE, job, ": a weight is NaN or infinite");
    if ((unsigned)stacking > MK_STACKING_SEQUENTIAL)
        return job_fail(err, MK_ERROR_INVALID_ARGUMENT, job, ": unknown stacking mode");
    if ((unsigned)normal_mode > MK_NORMALS_SLERP)
        return job_fail(err, MK_ERROR_INVALID_ARGUMENT, job, ": unknown normal mode");
    return MK_OK;
}

void mk_plan_fill(const mk_asset *a, const mk_blob_mesh *m, const float *weights, mk_stacking stacking, int slerp,
                  const mk_plan *plan)
{
    const mk_blob_target *targets = &a->targets[m->first_target];
    if (stacking == MK_STACKING_ASSET) stacking = (mk_stacking)m->stacking;
    for (uint32_t t = 0; t < m->target_count; t++) { plan->coef[t] = 0.0f; plan->slerp_channel[t] = -1; }
    float suffix = 1.0f;
    for (uint32_t c = m->channel_count; c-- > 0;) {
        const mk_blob_channel *ch = &a->channels[m->first_channel + c];
        uint32_t first = ch->first_target - m->first_target;
        float w = weights[c];
        mk_plan_span *s = &plan->spans[c];
        s->target_a = s->target_b = -1;
        s->t = 0.0f;
        s->scale = suffix;
        if (w != 0.0f && suffix != 0.0f) {
            int32_t ia, ib;
            float ca, cb;
            channel_span_strided(&targets[first].full_weight, sizeof(mk_blob_target), ch->target_count, w,
                                 &ia, &ca, &ib, &cb, &s->t);
            if (ia >= 0) { plan->coef[first + (uint32_t)ia] = ca * suffix; s->target_a = (int32_t)first + ia; }
            if (ib >= 0) { plan->coef[first + (uint32_t)ib] = cb * suffix; s->target_b = (int32_t)first + ib; }
            if (slerp) {
                if (ia >= 0) plan->slerp_channel[first + (uint32_t)ia] = (int32_t)c;
                if (ib >= 0) plan->slerp_channel[first + (uint32_t)ib] = (int32_t)c;
            }
        }
        if (stacking == MK_STACKING_SEQUENTIAL) {
            /* beta = clamp(w / f_first, 0, 1) with f_first the smallest positive full weight. */
            float f_first = 0.0f;
            for (uint32_t k = 0; k < ch->target_count; k++)
                if (targets[first + k].full_weight > 0) { f_first = targets[first + k].full_weight; break; }
            float beta = f_first > 0 ? w / f_first : 0.0f;
            beta = beta < 0 ? 0 : beta > 1 ? 1 : beta;
            suffix *= 1.0f - beta;
        }
    }
}

/* ---- the GPU path's plan (morphkit.h) ---- */

size_t mk_gpu_plan_size(const mk_asset *asset, uint32_t mesh)
{
    if (!asset || mesh >= asset->mesh_count) return 0;
    const mk_blob_mesh *m = &asset->meshes[mesh];
    return mk_plan_bytes(m->target_count, m->channel_count);
}

mk_result mk_gpu_plan_run(const mk_gpu_plan_job *job, mk_error *err)
{
    if (!job || !job->asset)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "gpu plan job or its asset is NULL");
    const mk_asset *a = job->asset;
    if (job->mesh >= a->mesh_count)
        return mk_error_fail(err, MK_ERROR_OUT_OF_RANGE, MK_NO_OFFSET, "gpu plan job: mesh index out of range");
    const mk_blob_mesh *m = &a->meshes[job->mesh];
    mk_result r = mk_plan_validate_weights(m, job->weights, job->weight_count, job->stacking, job->normal_mode,
                                           "gpu plan job", err);
    if (r != MK_OK) return r;
    if (!job->plan || (uintptr_t)job->plan % 16)
        return mk_error_fail(err, MK_ERROR_INVALID_ARGUMENT, MK_NO_OFFSET, "gpu plan job: plan is NULL or not 16-byte aligned");
    if (job->plan_size < mk_plan_bytes(m->target_count, m->channel_count))
        return mk_error_fail(err, MK_ERROR_BUFFER_TOO_SMALL, MK_NO_OFFSET, "gpu plan job: plan is smaller than mk_gpu_plan_size()");
    const mk_plan plan = mk_plan_at(job->plan, m->target_count);
    mk_plan_fill(a, m, job->weights, job->stacking, job->normal_mode == MK_NORMALS_SLERP, &plan);
    return MK_OK;
}

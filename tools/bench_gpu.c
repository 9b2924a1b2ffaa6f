/* SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "alloc.h"
#include "bench_gpu.h"
#include "gpu_eval.h"
#include "clock.h"
#if MK_HAVE_GPU
#include "harness.h"

enum { PASSES = 3, COPIES = 5 };

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, by_value);
    return n ? v[n / 2] : 0;
}

/* One mesh's evaluation into device-local outputs. */
typedef struct bench_mesh {
    mkg_host_buffer out;
    mkg_mesh *both, *positions;       /* positions + normals, positions only */
    uint32_t first_channel, channel_count;
} bench_mesh;

typedef struct bench_state {
    cli_gpu *gpu;                     /* the device, opened as for --gpu of the other commands */
    mkg_harness *h;
    mkg_asset *asset;
    bench_mesh *meshes;
    uint32_t mesh_count;
    VkQueryPool queries;
} bench_state;

/* Ticks between two timestamps, within the queue's valid bits (the counter wraps there). */
static uint64_t tick_span(const mkg_harness *h, const uint64_t ticks[2])
{
    const uint64_t mask = h->timestamp_bits >= 64 ? ~(uint64_t)0 : (((uint64_t)1 << h->timestamp_bits) - 1);
    return (ticks[1] - ticks[0]) & mask;
}

/* Records and runs one frame between two timestamps; returns the GPU ns, adds the CPU ns of the
 * plans and recording to *record_ns. */
static mk_result time_frame(bench_state *s, const float *weights, int normals, double *gpu_ns, double *record_ns,
                            mk_error *err)
{
    mk_result r = mkg_harness_begin(s->h, err);
    if (r != MK_OK) return r;
    vkCmdResetQueryPool(s->h->cmd, s->queries, 0, 2);
    vkCmdWriteTimestamp(s->h->cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, s->queries, 0);
    double t0 = bench_now_ns();
    for (uint32_t m = 0; m < s->mesh_count && r == MK_OK; m++) {
        const bench_mesh *bm = &s->meshes[m];
        mkg_frame f = { .weights = weights + bm->first_channel, .weight_count = bm->channel_count };
        r = mkg_mesh_record(normals && bm->both ? bm->both : bm->positions, s->h->cmd, &f, err);
    }
    *record_ns += bench_now_ns() - t0;
    vkCmdWriteTimestamp(s->h->cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s->queries, 1);
    mk_error ignored;
    mk_result submitted = mkg_harness_submit(s->h, r == MK_OK ? err : &ignored);
    if (r != MK_OK) return r;
    if (submitted != MK_OK) return submitted;
    uint64_t ticks[2];
    VkResult vr = vkGetQueryPoolResults(s->h->device, s->queries, 0, 2, sizeof ticks, ticks, sizeof ticks[0],
                                        VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    if (vr != VK_SUCCESS) return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "reading timestamps failed");
    *gpu_ns = (double)tick_span(s->h, ticks) * s->h->props.limits.timestampPeriod;
    return MK_OK;
}

/* The device's copy bandwidth: a buffer of `size` bytes copied into another, best of COPIES,
 * as bytes read + written per ns. */
static mk_result copy_bandwidth(bench_state *s, VkDeviceSize size, double *bytes_per_ns, mk_error *err)
{
    mkg_host_buffer a, b;
    mk_result r = mkg_device_buffer_create(s->h, size, &a, err);
    if (r != MK_OK) return r;
    r = mkg_device_buffer_create(s->h, size, &b, err);
    double best = 0;
    for (int k = 0; r == MK_OK && k < COPIES; k++) {
        r = mkg_harness_begin(s->h, err);
        if (r != MK_OK) break;
        vkCmdResetQueryPool(s->h->cmd, s->queries, 0, 2);
        vkCmdWriteTimestamp(s->h->cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, s->queries, 0);
        VkBufferCopy region = { 0, 0, size };
        vkCmdCopyBuffer(s->h->cmd, a.buffer, b.buffer, 1, &region);
        vkCmdWriteTimestamp(s->h->cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s->queries, 1);
        r = mkg_harness_submit(s->h, err);
        uint64_t ticks[2];
        if (r == MK_OK && vkGetQueryPoolResults(s->h->device, s->queries, 0, 2, sizeof ticks, ticks, sizeof ticks[0],
                                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT) == VK_SUCCESS) {
            double ns = (double)tick_span(s->h, ticks) * s->h->props.limits.timestampPeriod;
            if (ns > 0 && 2.0 * (double)size / ns > best) best = 2.0 * (double)size / ns;
        }
    }
    mkg_host_buffer_destroy(s->h, &b);
    mkg_host_buffer_destroy(s->h, &a);
    *bytes_per_ns = best;
    return r;
}

/* Frees everything and closes the device; nonzero when the validation layer reported messages. */
static int state_free(bench_state *s)
{
    for (uint32_t m = 0; s->meshes && m < s->mesh_count; m++) {
        mkg_mesh_destroy(s->meshes[m].both);
        mkg_mesh_destroy(s->meshes[m].positions);
        mkg_host_buffer_destroy(s->h, &s->meshes[m].out);
    }
    free(s->meshes);
    if (s->queries) vkDestroyQueryPool(s->h->device, s->queries, NULL);
    mkg_asset_destroy(s->asset);
    return cli_gpu_close(s->gpu);
}

/* The asset uploaded and each mesh's outputs and evaluations made. */
static mk_result prepare(bench_state *s, const mk_asset *a, cli_gpu_bench *out, mk_error *err)
{
    pb_evaluator unused;
    mk_result r = cli_gpu_open(&s->gpu, &unused, 1, err);
    if (r != MK_OK) return r;
    s->h = cli_gpu_harness(s->gpu);
    snprintf(out->device, sizeof out->device, "%s", s->h->props.deviceName);
    if (!s->h->timestamps)
        return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "%s has no timestamps on its compute queue",
                            out->device);
    VkQueryPoolCreateInfo qi = { .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO, .queryType = VK_QUERY_TYPE_TIMESTAMP,
                                 .queryCount = 2 };
    if (vkCreateQueryPool(s->h->device, &qi, NULL, &s->queries) != VK_SUCCESS)
        return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "creating a timestamp query pool failed");
    double t0 = bench_now_ns();
    r = mkg_asset_upload(s->h->ctx, a, s->h->queue, s->h->family, &s->asset, err);
    out->upload_ms = (bench_now_ns() - t0) / 1e6;
    s->mesh_count = a->mesh_count;
    s->meshes = calloc(a->mesh_count + 1u, sizeof *s->meshes);
    if (r == MK_OK && !s->meshes) r = mk_error_oom(err, "GPU bench");
    for (uint32_t m = 0; r == MK_OK && m < a->mesh_count; m++) {
        bench_mesh *bm = &s->meshes[m];
        mk_mesh_info mi;
        mk_mesh_get(a, m, &mi);
        bm->first_channel = mi.first_channel;
        bm->channel_count = mi.channel_count;
        const VkDeviceSize v = mi.vertex_count;
        r = mkg_device_buffer_create(s->h, 24 * v, &bm->out, err);
        mkg_mesh_desc d = { .mesh = m, .frames_in_flight = 1, .positions = { bm->out.buffer, 0, 12, 12 * v } };
        if (r == MK_OK) r = mkg_mesh_create(s->asset, &d, &bm->positions, err);
        d.normals = (mkg_output){ bm->out.buffer, 12 * v, 12, 12 * v };
        if (r == MK_OK && mi.has_normals) r = mkg_mesh_create(s->asset, &d, &bm->both, err);
    }
    return r;
}

mk_result cli_bench_gpu(const mk_asset *a, const float *weights, uint32_t frames, cli_gpu_bench *out, mk_error *err)
{
    memset(out, 0, sizeof *out);
    bench_state s;
    memset(&s, 0, sizeof s);
    mk_result r = prepare(&s, a, out, err);
    double *gpu = calloc((size_t)frames * PASSES + 1, sizeof *gpu), *gpu_p = calloc((size_t)frames * PASSES + 1, sizeof *gpu_p),
           *rec = calloc((size_t)frames * PASSES + 1, sizeof *rec);
    if (r == MK_OK && (!gpu || !gpu_p || !rec)) r = mk_error_oom(err, "GPU bench");
    /* Passes of positions + normals and positions only, alternating per frame; the first pass
     * warms up and is not kept. */
    size_t kept = 0;
    for (int pass = 0; r == MK_OK && pass <= PASSES; pass++)
        for (uint32_t f = 0; r == MK_OK && f < frames; f++) {
            const float *w = weights + (size_t)f * a->channel_count;
            double g = 0, gp = 0, rc = 0, ignored = 0;
            r = time_frame(&s, w, 1, &g, &rc, err);
            if (r == MK_OK) r = time_frame(&s, w, 0, &gp, &ignored, err);
            if (r == MK_OK && pass > 0) {
                gpu[kept] = g;
                gpu_p[kept] = gp;
                rec[kept++] = rc;
            }
        }
    if (r == MK_OK) {
        out->gpu_ns = median(gpu, kept);
        out->gpu_ns_min = gpu[0];   /* median sorted them */
        out->gpu_ns_positions = median(gpu_p, kept);
        out->record_ns = median(rec, kept);
        r = copy_bandwidth(&s, (VkDeviceSize)64 << 20, &out->copy_bytes_per_ns, err);
    }
    free(gpu);
    free(gpu_p);
    free(rec);
    if (s.gpu && state_free(&s) && r == MK_OK)
        r = mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "the Vulkan validation layer reported messages (above)");
    return r;
}

#else

mk_result cli_bench_gpu(const mk_asset *a, const float *weights, uint32_t frames, cli_gpu_bench *out, mk_error *err)
{
    (void)a;
    (void)weights;
    (void)frames;
    memset(out, 0, sizeof *out);
    cli_gpu *gpu;
    pb_evaluator unused;
    return cli_gpu_open(&gpu, &unused, 1, err);   /* says this build has no GPU path */
}

#endif

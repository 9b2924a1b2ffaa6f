/* SPDX-License-Identifier: MIT */
/* The GPU path next to the CPU runtime, headless: open a .morph file, upload its blob once to
 * a Vulkan device, and for a few frames of a clip evaluate every mesh on the GPU (compute) and
 * on the CPU (mk_eval_run), printing the largest difference between the two.
 *
 * An engine owns the instance, device and queues: it would call mkg_context_create with them,
 * mkg_asset_upload once, mkg_mesh_create once per mesh (outputs: its own vertex buffers) and
 * mkg_mesh_record per frame into its own command buffer (see morphkit_gpu.h). Here the
 * harness (gpu/harness.h) stands in for the engine: its own device, and mkg_harness_eval does
 * create + record + submit + read back in one call.
 *
 * usage: gpu_vulkan FILE.morph [CLIP]   (CLIP: a name or an index; default the first clip)
 * Exit status 77: no Vulkan device (skipped). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "harness.h"

#define FRAMES 10

static void *load(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) { perror(path); return NULL; }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    /* The runtime needs 16-byte aligned memory and keeps pointing into it. */
    void *blob = n > 0 ? aligned_alloc(16, ((size_t)n + 15) & ~(size_t)15) : NULL;
    if (!blob || fread(blob, 1, (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "cannot read %s\n", path);
        free(blob);
        blob = NULL;
    }
    fclose(f);
    *size = (size_t)n;
    return blob;
}

/* The angle between two directions, accurate for small angles too (unlike acos of the dot). */
static double angle(const float *a, const float *b)
{
    double cx = (double)a[1] * b[2] - (double)a[2] * b[1], cy = (double)a[2] * b[0] - (double)a[0] * b[2],
           cz = (double)a[0] * b[1] - (double)a[1] * b[0];
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2]);
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) { fprintf(stderr, "usage: gpu_vulkan FILE.morph [CLIP]\n"); return 2; }

    /* 1. The blob, opened in place as for the CPU runtime alone (samples/embed_minimal.c). */
    size_t size;
    void *blob = load(argv[1], &size);
    if (!blob) return 1;
    mk_asset asset;
    mk_error err;
    if (mk_asset_open(blob, size, &asset, &err) != MK_OK) {
        fprintf(stderr, "cannot open %s: %s\n", argv[1], err.message);
        free(blob);
        return 1;
    }
    int32_t clip = asset.clip_count ? 0 : -1;
    if (argc == 3) {
        char *end;
        unsigned long index = strtoul(argv[2], &end, 10);
        clip = mk_find_clip(&asset, argv[2]);
        if (clip < 0 && *argv[2] && !*end && index < asset.clip_count) clip = (int32_t)index;
        if (clip < 0) { fprintf(stderr, "%s has no clip '%s'\n", argv[1], argv[2]); free(blob); return 1; }
    }
    mk_clip_info info = { .name = "" };
    if (clip >= 0) mk_clip_get(&asset, (uint32_t)clip, &info);

    /* 2. The device (the engine's, in a game). */
    mkg_harness h;
    if (mkg_harness_open(&h, 0, &err) != MK_OK) {
        int skipped = err.code == MK_ERROR_UNSUPPORTED;
        fprintf(stderr, skipped ? "no Vulkan device: %s\n" : "%s\n", err.message);
        free(blob);
        return skipped ? 77 : 1;
    }

    /* 3. Upload once: the whole blob, unchanged, into a device-local buffer. The mk_asset and
     *    its blob stay alive: each frame is planned from them on the CPU. */
    mkg_asset *ga = NULL;
    int status = 1;
    if (mkg_asset_upload(h.ctx, &asset, h.queue, h.family, &ga, &err) != MK_OK) {
        fprintf(stderr, "upload failed: %s\n", err.message);
        mkg_harness_close(&h);
        free(blob);
        return 1;
    }

    /* Buffers for the largest mesh, and the bounding box of the rest pose (for scale). */
    uint32_t max_vertices = 1;
    size_t max_scratch = 0;
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (uint32_t m = 0; m < asset.mesh_count; m++) {
        mk_mesh_info mesh;
        mk_mesh_get(&asset, m, &mesh);
        if (mesh.vertex_count > max_vertices) max_vertices = mesh.vertex_count;
        if (mk_eval_scratch_size(&asset, m) > max_scratch) max_scratch = mk_eval_scratch_size(&asset, m);
        for (size_t i = 0; i < 3 * (size_t)mesh.vertex_count; i++) {
            lo[i % 3] = fminf(lo[i % 3], mesh.positions[i]);
            hi[i % 3] = fmaxf(hi[i % 3], mesh.positions[i]);
        }
    }
    float *weights = calloc(asset.channel_count + 1u, sizeof(float));
    float *out = malloc(4 * 3 * sizeof(float) * (size_t)max_vertices);   /* GPU and CPU positions and normals */
    float *gpu_pos = out, *gpu_nrm = out + 3 * (size_t)max_vertices;
    float *cpu_pos = out + 6 * (size_t)max_vertices, *cpu_nrm = out + 9 * (size_t)max_vertices;
    void *scratch = aligned_alloc(16, (max_scratch + 31) & ~(size_t)15);   /* never 0 bytes */
    if (!weights || !out || !scratch) { fprintf(stderr, "out of memory\n"); goto done; }

    /* Without a clip every channel keeps its default weight. */
    for (uint32_t c = 0; c < asset.channel_count; c++) {
        mk_channel_info ch;
        mk_channel_get(&asset, c, &ch);
        weights[c] = ch.default_weight;
    }

    /* 4. Per frame: weights on the CPU, then every mesh on both sides. */
    const int frames = clip >= 0 ? FRAMES : 1;
    double max_pos = 0, max_angle = 0;
    for (int frame = 0; frame < frames; frame++) {
        if (clip >= 0) {
            mk_sample_job sample = { .asset = &asset, .clip = (uint32_t)clip,
                                     .time = info.start + (double)info.duration * frame / (FRAMES - 1),
                                     .weights = weights, .weight_count = asset.channel_count };
            if (mk_sample_run(&sample, &err) != MK_OK) { fprintf(stderr, "%s\n", err.message); goto done; }
        }
        for (uint32_t m = 0; m < asset.mesh_count; m++) {
            mk_mesh_info mesh;
            mk_mesh_get(&asset, m, &mesh);
            const float *w = weights + mesh.first_channel;   /* mesh-local weights */
            if (mkg_harness_eval(&h, ga, m, w, mesh.channel_count, MK_STACKING_ASSET, MK_NORMALS_NLERP, gpu_pos,
                                 mesh.has_normals ? gpu_nrm : NULL, NULL, &err) != MK_OK) {
                fprintf(stderr, "GPU evaluation of mesh '%s' failed: %s\n", mesh.name, err.message);
                goto done;
            }
            mk_eval_job job = {
                .asset = &asset, .mesh = m, .vertex_count = MK_VERTICES_TO_END,
                .weights = w, .weight_count = mesh.channel_count,
                .scratch = scratch, .scratch_size = max_scratch,
                .positions = cpu_pos, .positions_size = 12 * (size_t)mesh.vertex_count,
                .normals = mesh.has_normals ? cpu_nrm : NULL, .normals_size = 12 * (size_t)mesh.vertex_count,
            };
            if (mk_eval_run(&job, &err) != MK_OK) { fprintf(stderr, "%s\n", err.message); goto done; }
            for (size_t i = 0; i < 3 * (size_t)mesh.vertex_count; i++)
                max_pos = fmax(max_pos, fabs((double)gpu_pos[i] - cpu_pos[i]));
            for (size_t v = 0; mesh.has_normals && v < mesh.vertex_count; v++)
                max_angle = fmax(max_angle, angle(gpu_nrm + 3 * v, cpu_nrm + 3 * v));
        }
    }

    /* 5. The report. */
    double dx = (double)hi[0] - lo[0], dy = (double)hi[1] - lo[1], dz = (double)hi[2] - lo[2];
    double diagonal = asset.mesh_count ? sqrt(dx * dx + dy * dy + dz * dz) : 0;
    printf("device: %s\n", h.props.deviceName);
    if (clip >= 0)
        printf("clip: '%s', %d frames over %.3f s\n", info.name, frames, (double)info.duration);
    else
        printf("no clip: default weights, 1 frame\n");
    printf("meshes: %u\n", asset.mesh_count);
    printf("largest difference: positions %.3g (%.3g of the bounding-box diagonal), normals %.3g rad\n", max_pos,
           diagonal > 0 ? max_pos / diagonal : 0.0, max_angle);
    status = 0;

done:
    free(scratch);
    free(out);
    free(weights);
    mkg_asset_destroy(ga);
    mkg_harness_close(&h);
    free(blob);
    return status;
}

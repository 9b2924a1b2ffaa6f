/* SPDX-License-Identifier: MIT */
/* An engine's conformance check against golden frames written by `morphkit frames DIR`: open
 * DIR/asset.morph with the runtime (here: morphkit's own; an engine links its port), and for
 * each frame of DIR/frames.list read the binary frame (docs/conformance.md, "Binary frames"),
 * sample its clip at its time and compare the weights, evaluate with its weights, stacking and
 * normal mode, and compare positions and normals. Prints the largest differences; exits 1 when
 * one passes the tolerance (relative to each mesh's size). Only the runtime is linked.
 * usage: golden_check DIR [TOLERANCE]   (default 1e-6 x the mesh's bounding-box diagonal) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "morphkit.h"

/* The whole file in 16-byte aligned memory, or NULL. */
static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    unsigned char *p = n >= 0 ? aligned_alloc(16, ((size_t)n + 16) & ~(size_t)15) : NULL;
    if (p && fread(p, 1, (size_t)n, f) != (size_t)n) { free(p); p = NULL; }
    fclose(f);
    *size = (size_t)n;
    return p;
}

/* Binary frames are little-endian; this reads them on any host. */
static uint32_t u32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static float f32(const unsigned char *p) { uint32_t u = u32(p); float f; memcpy(&f, &u, 4); return f; }

int main(int argc, char **argv)
{
    if (argc < 2) { fprintf(stderr, "usage: golden_check DIR [TOLERANCE]\n"); return 2; }
    double tolerance = argc > 2 ? atof(argv[2]) : 1e-6;
    char path[4096];
    size_t blob_size;
    snprintf(path, sizeof path, "%s/asset.morph", argv[1]);
    unsigned char *blob = read_all(path, &blob_size);
    mk_asset asset;
    mk_error err;
    if (!blob || mk_asset_open(blob, blob_size, &asset, &err) != MK_OK) { fprintf(stderr, "cannot open %s\n", path); return 1; }
    snprintf(path, sizeof path, "%s/frames.list", argv[1]);
    FILE *list = fopen(path, "r");
    if (!list) { perror(path); return 1; }
    float *weights = calloc(asset.channel_count + 1u, sizeof(float));
    char name[256];
    int frames = 0, failed = 0;
    double worst_position = 0, worst_normal = 0, worst_weight = 0;
    while (fscanf(list, "%255s", name) == 1) {
        snprintf(path, sizeof path, "%s/%s", argv[1], name);
        size_t size;
        unsigned char *frame = read_all(path, &size);
        /* Header: magic, version, mesh count, channel count, flags, clip, stacking, normal mode,
         * reserved, time (f64); then the weights; then per mesh 4 u32 and its arrays. */
        if (!frame || size < 48 || memcmp(frame, "MKFRAME1", 8) || u32(frame + 8) != 1 || u32(frame + 12) != asset.mesh_count
            || u32(frame + 16) != asset.channel_count || size < 48 + 4 * (size_t)asset.channel_count) {
            fprintf(stderr, "%s: not a frame of this asset\n", path);
            return 1;
        }
        int32_t clip = (int32_t)u32(frame + 24);
        mk_stacking stacking = (mk_stacking)u32(frame + 28);
        mk_normal_mode normal_mode = (mk_normal_mode)u32(frame + 32);
        double time;
        memcpy(&time, frame + 40, 8);   /* little-endian f64 on the hosts this sample targets */
        size_t at = 48;
        for (uint32_t c = 0; c < asset.channel_count; c++, at += 4) weights[c] = f32(frame + at);
        if (clip >= 0) {   /* the runtime's sampling must give the frame's weights */
            float *sampled = calloc(asset.channel_count + 1u, sizeof(float));
            mk_sample_job s = { .asset = &asset, .clip = (uint32_t)clip, .time = time, .weights = sampled,
                                .weight_count = asset.channel_count };
            if (mk_sample_run(&s, &err) != MK_OK) { fprintf(stderr, "%s: %s\n", name, err.message); return 1; }
            for (uint32_t c = 0; c < asset.channel_count; c++)
                if (fabs((double)sampled[c] - weights[c]) > worst_weight) worst_weight = fabs((double)sampled[c] - weights[c]);
            free(sampled);
        }
        for (uint32_t m = 0; m < asset.mesh_count; m++) {
            mk_mesh_info mesh;
            mk_mesh_get(&asset, m, &mesh);
            uint32_t n = u32(frame + at), flags = u32(frame + at + 12);
            at += 16;
            size_t need = 12 * (size_t)n * ((flags & 1) ? 2 : 1) + ((flags & 2) ? 16 * (size_t)n : 0);
            if (n != mesh.vertex_count || size - at < need) { fprintf(stderr, "%s: mesh %u does not match\n", name, m); return 1; }
            float *out = malloc(24 * (size_t)n + 24);
            size_t scratch_size = mk_eval_scratch_size(&asset, m);
            void *scratch = aligned_alloc(16, (scratch_size + 31) & ~(size_t)15);
            mk_eval_job job = { .asset = &asset, .mesh = m, .vertex_count = MK_VERTICES_TO_END,
                                .weights = weights + mesh.first_channel, .weight_count = mesh.channel_count,
                                .stacking = stacking, .normal_mode = normal_mode, .scratch = scratch,
                                .scratch_size = scratch_size, .positions = out, .positions_size = 12 * (size_t)n,
                                .normals = (flags & 1) ? out + 3 * (size_t)n : NULL, .normals_size = 12 * (size_t)n };
            if (mk_eval_run(&job, &err) != MK_OK) { fprintf(stderr, "%s: %s\n", name, err.message); return 1; }
            /* The frame's size: its bounding-box diagonal. */
            double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY }, e = 0, en = 0;
            for (size_t i = 0; i < 3 * (size_t)n; i++) {
                double ref = f32(frame + at + 4 * i);
                if (ref < lo[i % 3]) lo[i % 3] = ref;
                if (ref > hi[i % 3]) hi[i % 3] = ref;
                if (fabs(out[i] - ref) > e) e = fabs(out[i] - ref);
            }
            at += 12 * (size_t)n;
            if (flags & 1) {
                for (size_t i = 0; i < 3 * (size_t)n; i++)
                    if (fabs(out[3 * (size_t)n + i] - f32(frame + at + 4 * i)) > en) en = fabs(out[3 * (size_t)n + i] - f32(frame + at + 4 * i));
                at += 12 * (size_t)n;
            }
            if (flags & 2) at += 16 * (size_t)n;
            double diagonal = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
            if (e > tolerance * diagonal || en > 1e-5) failed++;
            if (e > worst_position) worst_position = e;
            if (en > worst_normal) worst_normal = en;
            free(out);
            free(scratch);
        }
        frames++;
        free(frame);
    }
    fclose(list);
    printf("%d frames: largest position difference %.3g, normal %.3g, sampled weight %.3g; %s\n", frames, worst_position,
           worst_normal, worst_weight, failed || worst_weight > 1e-6 || frames == 0 ? "FAIL" : "ok");
    free(weights);
    free(blob);
    return failed || worst_weight > 1e-6 || frames == 0 ? 1 : 0;
}

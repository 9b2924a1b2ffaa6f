/* SPDX-License-Identifier: MIT */
/* The smallest complete engine integration (docs/embedding.md walks through it):
 * load a .morph file into aligned memory, open it in place, and per frame sample the first
 * clip and evaluate every mesh into a vertex buffer. Only the runtime is linked. */
#include <stdio.h>
#include <stdlib.h>
#include "morphkit.h"

int main(int argc, char **argv)
{
    if (argc != 2) { fprintf(stderr, "usage: embed_minimal FILE.morph\n"); return 2; }

    /* 1. Load the blob (an engine would mmap it or use its asset system). The runtime needs
     *    16-byte aligned memory and keeps pointing into it: keep it alive. */
    FILE *f = fopen(argv[1], "rb");
    if (!f) { perror(argv[1]); return 1; }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    rewind(f);
    void *blob = aligned_alloc(16, ((size_t)size + 15) & ~(size_t)15);
    if (!blob || fread(blob, 1, (size_t)size, f) != (size_t)size) { fclose(f); return 1; }
    fclose(f);

    /* 2. Open: validates everything once. */
    mk_asset asset;
    mk_error err;
    if (mk_asset_open(blob, (size_t)size, &asset, &err) != MK_OK) {
        fprintf(stderr, "cannot open %s: %s\n", argv[1], err.message);
        return 1;
    }

    /* 3. Per-asset buffers: one weight per channel, cursors for fast forward playback. */
    float *weights = calloc(asset.channel_count + 1u, sizeof(float));
    mk_clip_info clip = { 0 };
    int has_clip = mk_clip_get(&asset, 0, &clip);
    uint32_t *cursors = calloc(clip.track_count + 1u, sizeof(uint32_t));

    for (int frame = 0; frame < 4; frame++) {
        float time = clip.start + clip.duration * (float)frame / 3.0f;
        /* 4. Sample the clip: one weight per channel (defaults where not animated). */
        if (has_clip) {
            mk_sample_job sample = { .asset = &asset, .clip = 0, .time = time, .weights = weights,
                                     .weight_count = asset.channel_count, .cursors = cursors,
                                     .cursor_count = clip.track_count };
            if (mk_sample_run(&sample, &err) != MK_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
        }
        /* 5. Evaluate each mesh into its vertex buffer (here: interleaved position + normal). */
        for (uint32_t m = 0; m < asset.mesh_count; m++) {
            mk_mesh_info mesh;
            mk_mesh_get(&asset, m, &mesh);
            size_t stride = 6 * sizeof(float);
            float *vertices = malloc(stride * mesh.vertex_count);
            size_t scratch_size = mk_eval_scratch_size(&asset, m);
            void *scratch = aligned_alloc(16, (scratch_size + 31) & ~(size_t)15);   /* never 0 bytes */
            mk_eval_job job = {
                .asset = &asset, .mesh = m, .vertex_count = MK_VERTICES_TO_END,
                .weights = weights + mesh.first_channel, .weight_count = mesh.channel_count,
                .scratch = scratch, .scratch_size = scratch_size,
                .positions = vertices, .positions_stride = stride, .positions_size = stride * mesh.vertex_count,
                .normals = mesh.has_normals ? vertices + 3 : NULL, .normals_stride = stride,
                .normals_size = stride * mesh.vertex_count - 12,
            };
            if (mk_eval_run(&job, &err) != MK_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
            const float *last = vertices + 6 * (size_t)(mesh.vertex_count - 1);
            printf("t=%.2f s  mesh '%s'  last vertex at (%.4f, %.4f, %.4f)\n", (double)time, mesh.name,
                   (double)last[0], (double)last[1], (double)last[2]);
            free(scratch);
            free(vertices);
        }
    }
    free(cursors);
    free(weights);
    free(blob);
    return 0;
}

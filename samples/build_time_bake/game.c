/* SPDX-License-Identifier: MIT */
/* The program of the build-time baking sample: its morph asset is compiled in (box_blob.c, made
 * by `morphkit embed` at build time), opened in place and played; only the runtime is linked. */
#include <stdio.h>
#include "box_blob.h"
#include "morphkit.h"

int main(void)
{
    mk_asset asset;
    mk_error err;
    if (mk_asset_open(box_blob, box_blob_size, &asset, &err) != MK_OK) {
        fprintf(stderr, "embedded blob: %s\n", err.message);
        return 1;
    }
    mk_mesh_info mesh;
    mk_mesh_get(&asset, 0, &mesh);
    float weights[16] = { 0 }, positions[3 * 64];
    static _Alignas(16) unsigned char scratch[4096];
    if (mesh.channel_count > 16 || mesh.vertex_count > 64 || mk_eval_scratch_size(&asset, 0) > sizeof scratch) return 1;
    /* Every channel from 0 to 1 in three steps. */
    for (int step = 0; step <= 2; step++) {
        for (uint32_t c = 0; c < mesh.channel_count; c++) weights[c] = (float)step / 2.0f;
        mk_eval_job job = { .asset = &asset, .mesh = 0, .vertex_count = MK_VERTICES_TO_END, .weights = weights,
                            .weight_count = mesh.channel_count, .scratch = scratch, .scratch_size = sizeof scratch,
                            .positions = positions, .positions_size = sizeof positions };
        if (mk_eval_run(&job, &err) != MK_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
        printf("weights %.1f: top corner at (%.3f, %.3f, %.3f)\n", (double)weights[0], (double)positions[18],
               (double)positions[19], (double)positions[20]);
    }
    for (uint32_t c = 0; c < mesh.channel_count; c++) {
        mk_channel_info ch;
        mk_channel_get(&asset, mesh.first_channel + c, &ch);
        printf("channel %u: %s\n", c, ch.name);
    }
    return 0;
}

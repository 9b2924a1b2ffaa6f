/* SPDX-License-Identifier: MIT */
/* libFuzzer target: mk_asset_open on arbitrary bytes, then (if it opens) sampling and
 * evaluation of every mesh/clip. Any crash, overread or UB is a bug. The checksum would stop
 * nearly every mutation at the door, so the first byte of the input selects whether the
 * checksum is recomputed first (letting the fuzzer reach the structural validation). */
#include <stdlib.h>
#include <string.h>
#include "format.h"
#include "morphkit.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    int fix = data[0] & 1;
    data++;
    size--;
    uint8_t *blob = NULL;
    if (posix_memalign((void **)&blob, 16, size ? size : 1) != 0) return 0;
    if (size) memcpy(blob, data, size);
    if (fix && size >= 64) {
        uint64_t sum = mk_checksum(blob + 32, size - 32);
        memcpy(blob + 24, &sum, 8);
    }
    mk_asset a;
    if (mk_asset_open(blob, size, &a, NULL) == MK_OK && a.channel_count <= 1024) {
        static float weights[1024], out[3 * 2048], out_n[3 * 2048], out_t[4 * 2048];
        static _Alignas(16) uint8_t scratch[1 << 16];
        for (uint32_t c = 0; c < a.clip_count; c++) {
            mk_sample_job s = { .asset = &a, .clip = c, .time = 0.5f, .weights = weights, .weight_count = 1024 };
            mk_sample_run(&s, NULL);
        }
        for (uint32_t c = 0; c < a.channel_count; c++) weights[c] = (float)(c % 5) - 1.5f;
        for (uint32_t m = 0; m < a.mesh_count; m++) {
            mk_mesh_info info;
            mk_mesh_get(&a, m, &info);
            if (info.vertex_count > 2048 || mk_eval_scratch_size(&a, m) > sizeof scratch) continue;
            mk_eval_job j = { .asset = &a, .mesh = m, .vertex_count = MK_VERTICES_TO_END, .weights = weights + info.first_channel,
                              .weight_count = info.channel_count, .normal_mode = (mk_normal_mode)(size & 1),
                              .scratch = scratch, .scratch_size = sizeof scratch, .positions = out,
                              .positions_size = sizeof out, .normals = info.has_normals ? out_n : NULL,
                              .normals_size = sizeof out_n, .tangents = info.has_tangents ? out_t : NULL,
                              .tangents_size = sizeof out_t };
            mk_eval_run(&j, NULL);
        }
    }
    free(blob);
    return 0;
}

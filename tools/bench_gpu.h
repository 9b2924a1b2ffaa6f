/* SPDX-License-Identifier: MIT */
/* `morphkit bench --gpu`: the GPU path's frame time from timestamp queries, the CPU time of
 * planning and recording a frame, and the device's own buffer-copy bandwidth measured in the
 * same run (docs/gpu.md, docs/performance.md). */
#ifndef MK_CLI_BENCH_GPU_H
#define MK_CLI_BENCH_GPU_H

#include "morphkit.h"

typedef struct cli_gpu_bench {
    char device[256];
    double gpu_ns, gpu_ns_min;        /* per frame, positions + normals: median and best */
    double gpu_ns_positions;          /* per frame, positions only: median */
    double record_ns;                 /* CPU per frame: plans written and dispatches recorded (median) */
    double upload_ms;                 /* the blob's one upload */
    double copy_bytes_per_ns;         /* device buffer copy: bytes read + written per ns (best) */
} cli_gpu_bench;

/* Times frames (asset-wide weight sets) through the GPU path; bytes is what one frame must touch
 * (the CPU bench's model). MK_ERROR_UNSUPPORTED without a device or in a build without the GPU
 * path. */
mk_result cli_bench_gpu(const mk_asset *asset, const float *weights, uint32_t frames, cli_gpu_bench *out, mk_error *err);

#endif

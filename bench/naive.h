/* SPDX-License-Identifier: MIT */
/* The naive baseline of the benchmark: dense float deltas, a loop over every vertex per active
 * target. */
#ifndef MK_BENCH_NAIVE_H
#define MK_BENCH_NAIVE_H

#include "asset.h"

/* ns per frame over the weight sets (best of BENCH_PASSES); *diff is its largest difference
 * from the runtime's last frame. */
double bench_naive_frames(const pb_asset *asset, const float *weight_sets, uint32_t frames, double *diff);

#endif

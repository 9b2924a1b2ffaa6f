/* SPDX-License-Identifier: MIT */
/* What surface normals cost: positions + surface normals against positions + nlerp normals,
 * one thread, the two timed alternately over the same weight sets. */
#ifndef MK_BENCH_SURFACE_H
#define MK_BENCH_SURFACE_H

#include "asset.h"

/* Best ns per frame of each over BENCH_PASSES alternating passes (summed over the meshes that
 * have surface normals); 0 when no mesh has them or on error. */
void bench_surface_frames(const pb_asset *asset, const float *weight_sets, uint32_t frames, double *ns_nlerp,
                          double *ns_surface);

#endif

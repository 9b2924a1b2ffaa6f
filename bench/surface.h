/* SPDX-License-Identifier: MIT */
/* What surface normals cost: positions + surface normals against positions + nlerp normals,
 * one thread, the two timed alternately on each weight set. The surface passes may play
 * another asset with the same meshes and channels: the same content without target normals,
 * which is what a program that only uses surface normals ships (its positions pass reads no
 * normal deltas). */
#ifndef MK_BENCH_SURFACE_H
#define MK_BENCH_SURFACE_H

#include "asset.h"

/* ns per frame of each: per weight set the best of BENCH_PASSES runs, alternating with the
 * other's, averaged over the weight sets (and summed over the meshes that have surface normals): nlerp on nlerp_asset, surface normals on surface_asset (which may be
 * the same). 0 when no mesh has them; a mesh that fails is left out. */
void bench_surface_frames(const pb_asset *nlerp_asset, const pb_asset *surface_asset, const float *weight_sets,
                          uint32_t frames, double *ns_nlerp, double *ns_surface);

#endif

/* SPDX-License-Identifier: MIT */
/* Writer-made FBX fixtures shared by the FBX tests, the fuzz seeds and the benchmark. */
#ifndef MK_TESTS_FBX_FIXTURES_H
#define MK_TESTS_FBX_FIXTURES_H

#include "fbx_writer.h"

/* A unit cube "Box" (8 control points, 6 quads, per-face normals: 24 render vertices, UVs)
 * with two channels:
 *   "Squash": one shape moving the top 4 points by (0, -0.5, 0), DeformPercent 25, animated by
 *             a cubic auto-tangent curve 0% (t=0) -> 100% (t=1) -> 0% (t=2);
 *   "Grow":   in-betweens written in connection order "Grow100" then "Grow50" with
 *             FullWeights {100, 50}: Grow50 moves point 0 by (-0.25, 0, 0) and Grow100 by
 *             (-1, 0, 0); its Indexes are listed unsorted and include one out-of-range entry
 *             (index 99) and one zero delta; animated linearly 0% (t=0) -> 100% (t=2).
 * The Box model has translation (1, 2, 3), rotation (0, 0, 90), rotation pivot (0.5, 0, 0),
 * geometric translation (0, 0, 0.25), and a parent "Root" (no geometry... a second mesh "Root"
 * is a single triangle with scaling 2) so the parent chain is exercised. */
void fixture_cube(fbxw_scene *scene, uint32_t version, int binary, int compress);

/* A hand-written FBX 6.1 ASCII file: Model "Tri" (3 control points, one triangle, T(10,0,0),
 * S(2,2,2)) with `Shape: "Up"` moving point 2 by (0,0,1), weight property Up = 40, and a Take
 * whose Key list is linear 0 -> 100 (t 0..1), constant-next to 50 (t 1..1.5), cubic after. */
extern const char fixture_legacy61[];

/* The KTime of t seconds. */
#define FIXTURE_KTIME(t) ((int64_t)((t) * (double)FBXW_KTIME_PER_SECOND))

#endif

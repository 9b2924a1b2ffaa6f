/* SPDX-License-Identifier: MIT */
/* Deformation transfer internals shared by transfer.c and transfer_correspond.c (baker/ only). */
#ifndef BAKE_TRANSFER_INTERNAL_H
#define BAKE_TRANSFER_INTERNAL_H

#include "raw.h"

/* The source -> target alignment p' = A p + t (A = s R, row-major) fitted to the markers in the
 * least-squares sense: none -> identity; one -> translation; two -> uniform scale and
 * translation; three or more -> similarity (Horn's rotation, Umeyama's scale). *residual gets
 * the RMS marker distance after alignment. Fails when the source markers coincide. */
mk_result bake_transfer_align(const mk_raw_mesh *source, const mk_raw_mesh *target, uint32_t count,
                              const uint32_t (*markers)[2], double A[9], double t[3], double *residual,
                              mk_error *err);

/* Per target triangle: the aligned source triangle whose closest point to the target triangle's
 * centroid is nearest among those facing the same way (aligned normals with a positive dot
 * product), and the barycentric coordinates of that closest point. match[t] = UINT32_MAX for a
 * degenerate target triangle or when no source triangle faces its way (counted in *unmatched);
 * *flipped counts triangles whose nearest source triangle overall faced away. aligned: the
 * source's rest positions mapped by the alignment, 3 doubles per vertex. */
mk_result bake_transfer_correspond(const mk_raw_mesh *source, const double *aligned, const mk_raw_mesh *target,
                                   mk_arena *arena, uint32_t *match, double *barycentric, uint32_t *flipped,
                                   uint32_t *unmatched, mk_error *err);

/* Area of a triangle below which it counts as degenerate: relative to its longest edge squared. */
#define TRANSFER_DEGENERATE 1e-12

#endif

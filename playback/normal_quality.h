/* SPDX-License-Identifier: MIT */
/* How far evaluated normals are from the normals of the evaluated surface (docs/semantics.md,
 * "Normal quality"). The reference of a vertex whose one-ring moved is
 *     normalize(B + N(P) - N(P0)),
 * B its authored base normal, N(P) the normal morphkit's importer computes for a surface
 * (smoothing groups, area-weighted face normals) at the evaluated positions P, N(P0) the same
 * at rest: the rule target normals are made with, applied to the combined shape. A single
 * target at a full weight therefore has no error under nlerp; combinations and in-betweens
 * show how far each normal mode is from the surface. Vertices whose one-ring did not move are
 * not measured. */
#ifndef MK_PB_NORMAL_QUALITY_H
#define MK_PB_NORMAL_QUALITY_H

#include "asset.h"
#include "mesh_groups.h"

/* The modes measured: the runtime's nlerp and slerp, its surface normals (mk_surface_run), and
 * base normals left as they are. */
enum { PB_QUALITY_NLERP, PB_QUALITY_SLERP, PB_QUALITY_SURFACE, PB_QUALITY_BASE, PB_QUALITY_MODES };

struct pb_quality_mesh;

/* Angles (degrees) collected over frames, per mode. Zero-initialize; every call adds a frame of
 * the same asset (the per-mesh groups, rest normals and surface topology are built on the
 * first). */
typedef struct pb_normal_quality {
    double *angles[PB_QUALITY_MODES];
    size_t count, capacity;            /* the same count for every mode */
    uint32_t frames;
    struct pb_quality_mesh *meshes;    /* per asset mesh, built on the first call */
    uint32_t mesh_count;
    mk_raw_asset *read_back;           /* the blob's meshes, when the caller has no raw model */
} pb_normal_quality;

typedef struct pb_normal_stats {
    size_t count;                      /* vertex-frames measured */
    double mean, p99, max;             /* degrees */
} pb_normal_stats;

/* Adds the moved vertices of every mesh with normals and triangles of `asset` (opened from
 * `raw`, which holds its meshes in the same order; NULL or a raw model without meshes, as for a
 * .morph input: the blob's meshes are read back once) for asset-wide `weights`, evaluated
 * with `stacking` (0 = the blob's). */
mk_result pb_normal_quality_add(pb_normal_quality *q, const mk_asset *asset, const mk_raw_asset *raw,
                                const float *weights, mk_stacking stacking, mk_error *err);

/* A mode's name in JSON keys ("nlerp", "slerp", "surface", "base") and its label in text. */
const char *pb_quality_name(int mode);
const char *pb_quality_label(int mode);

/* Per vertex, the angle in degrees between normal a[v] (any length) and the reference b[v]
 * (unit length) — the angle the statistics are made of, for drawing it. */
void pb_normal_angles(const float *a, const float *b, uint32_t count, float *degrees);

/* Mean, 99th percentile and largest angle of one mode (zeros when nothing was measured). */
pb_normal_stats pb_normal_quality_stats(const pb_normal_quality *q, int mode);

void pb_normal_quality_free(pb_normal_quality *q);

/* Reference normals (3 doubles per vertex) of mesh m at positions (3 floats per vertex), for
 * the vertices whose one-ring moved (moved[v] = 1; the others get 0 and keep no reference).
 * Returns the count of moved vertices, or -1 when out of memory. */
long pb_reference_normals(const mk_raw_mesh *m, const mk_normal_groups *groups, const double *rest_normals,
                          const float *positions, double *reference, unsigned char *moved, mk_arena *arena);

#endif

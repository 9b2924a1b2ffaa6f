/* SPDX-License-Identifier: MIT */
/* Which render vertices belong together: welding by position, and smoothing groups for
 * normals. One definition shared by the importer's target normals and the bakers' normals from
 * deformed surfaces, so seams and hard edges behave the same everywhere.
 *
 * A smoothing group is the set of render vertices with the same key (the same control point,
 * or the same base position bit for bit) and the same base normal (within 1e-5 per
 * component): vertices split only for UVs share a normal, vertices split for a hard edge keep
 * theirs. A group's normal is the normalized sum of the area-weighted face normals (cross
 * products) of the triangles around it. The grouping itself is the runtime's
 * mk_smoothing_groups, so surface normals at run time group exactly as the importer does. */
#ifndef MK_MESH_GROUPS_H
#define MK_MESH_GROUPS_H

#include "raw.h"

typedef enum mk_grouping {
    MK_GROUP_BY_CONTROL_POINT = 0,   /* the importer's rule (falls back to positions without control points) */
    MK_GROUP_BY_POSITION = 1         /* bit-identical base positions (-0 == +0) */
} mk_grouping;

typedef struct mk_normal_groups {
    uint32_t group_count;
    uint32_t *group_of;                      /* per render vertex */
    uint32_t *group_vert_first, *group_verts; /* CSR: group -> its vertices */
    uint32_t *group_tri_first, *group_tris;   /* CSR: group -> triangles with a corner in it (once each) */
} mk_normal_groups;

/* Lists items by key (a counting sort): with key[i] < keys for each of the items, first[k] ..
 * first[k + 1] of list are the items with key k, in item order (first: keys + 1 entries, list:
 * items). Memory from arena; 0 when out of memory. */
int mk_csr_build(mk_arena *arena, const uint32_t *key, uint32_t items, uint32_t keys, uint32_t **first, uint32_t **list);

/* Welds render vertices with bit-identical base positions: weld[v] = welded index, numbered in
 * order of first render vertex; returns NULL on OOM. */
uint32_t *mk_mesh_weld(const mk_raw_mesh *mesh, mk_arena *arena, uint32_t *welded_count);

/* Builds the smoothing groups of a mesh (memory from arena). */
mk_result mk_normal_groups_build(const mk_raw_mesh *mesh, mk_grouping grouping, mk_arena *arena, mk_normal_groups *out,
                                 mk_error *err);

/* The face normal of triangle (a, b, c): (b - a) x (c - a), not normalized (length = 2 x area),
 * facing the side from which a, b, c run counterclockwise: the one definition of a face normal
 * for the offline code and the bakers. Inline, so each caller's floating-point rules apply (the
 * bakers contract nothing). */
static inline void mk_triangle_normal(const double a[3], const double b[3], const double c[3], double out[3])
{
    const double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* mk_triangle_normal of triangle t of the mesh at positions (3 doubles per vertex; NULL: the
 * base positions). */
void mk_face_normal(const mk_raw_mesh *mesh, const double *positions, uint32_t t, double out[3]);

/* Unit normals of the mesh deformed to positions (3 doubles per vertex) into normals (3
 * doubles per vertex), for the vertices with flags[v] != 0 (flags NULL: all). A group without
 * area keeps its base normal (or 0 without base normals). Scratch from arena. */
mk_result mk_normal_groups_smooth(const mk_normal_groups *groups, const mk_raw_mesh *mesh, const double *positions,
                                  const unsigned char *flags, double *normals, mk_arena *arena, mk_error *err);

#endif

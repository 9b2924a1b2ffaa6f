/* SPDX-License-Identifier: MIT */
/* FBX mesh conversion and blend shape expansion (fbx_mesh.c). */
#ifndef MK_FBX_MESH_H
#define MK_FBX_MESH_H

#include "fbx_internal.h"

/* Control point -> render vertices of one converted mesh (scratch in the parse arena). */
typedef struct fbx_mesh_map {
    uint32_t control_point_count, vertex_count;
    uint32_t *first;            /* control_point_count + 1 offsets into vertices */
    uint32_t *vertices;         /* render vertices grouped by control point, increasing */
    const uint32_t *vertex_cp;  /* render vertex -> control point (the raw mesh's array) */
    /* Scratch for fbx_expand_shape, allocated at the mesh's first shape and reused by the
     * others (fresh arrays for every shape cost a zeroed page for every page touched). */
    uint32_t *cp_entry;         /* per control point: its entry in the shape, or a mark */
    uint32_t *entry_cp;         /* per entry (at most one per control point): its control point */
    double *sum_pos, *sum_nrm;  /* per entry: the summed position and normal deltas */
    void *pairs;                /* (render vertex, entry) pairs of a sparse shape */
} fbx_mesh_map;

/* Reads Vertices, PolygonVertexIndex and the normal/UV layers of `geometry` into `mesh`
 * (positions, normals, triangles, control_points; world and name are the caller's). A geometry
 * without control points is not an error: it returns MK_OK with mesh->vertex_count 0 and an
 * empty map, and the caller skips the mesh. */
mk_result fbx_build_mesh(fbx_doc *doc, mk_raw_asset *raw, const fbx_node *geometry, mk_raw_mesh *mesh,
                         fbx_mesh_map *map);
void fbx_mesh_map_free(fbx_doc *doc, fbx_mesh_map *map);

/* One shape: sparse deltas at control points. */
typedef struct fbx_shape_data {
    size_t count;
    const int32_t *indexes;
    const double *positions;       /* 3 per entry */
    const double *normals;         /* 3 per entry, or NULL (not used) */
    const double *vertex_weights;  /* Blender per-entry weights (0..1), or NULL */
    const char *path;              /* node path for messages */
    const fbx_node *node;          /* the Shape node (its Vertices/Normals name bad values) */
    const char *name;              /* shape name for messages */
    uint32_t name_length;
} fbx_shape_data;

/* Fills target->count/indices/positions/normals with the deltas on render vertices (strictly
 * increasing indices), the arrays allocated from `out`; scratch comes from doc->arena and the
 * map. Entries with out-of-range indices are skipped and counted. */
mk_result fbx_expand_shape(fbx_doc *doc, mk_arena *out, fbx_mesh_map *map, const fbx_shape_data *shape,
                           mk_raw_target *target, size_t *skipped);

#endif

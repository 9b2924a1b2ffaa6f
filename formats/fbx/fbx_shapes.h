/* SPDX-License-Identifier: MIT */
/* A mesh's blend shape channels into raw channels and targets (fbx_shapes.c). */
#ifndef MK_FBX_SHAPES_H
#define MK_FBX_SHAPES_H

#include "fbx_mesh.h"

typedef struct fbx_shape_ref {
    const fbx_node *node;     /* Geometry Shape or legacy Shape: node */
    const char *name;
    uint32_t name_length;
    double full_weight;       /* percent; set by fbx_add_channels */
} fbx_shape_ref;

/* One channel as the scene found it. */
typedef struct fbx_channel_plan {
    const char *name;
    uint32_t name_length;
    double default_percent;
    fbx_shape_ref *shapes;            /* in connection order; fbx_add_channels sorts them by full weight */
    uint32_t shape_count;
    const double *full_weights;       /* FullWeights values, or NULL */
    size_t full_weight_count;
    /* Blender's binary exporter writes a one-shape channel's vertex-group weights (one per
     * Indexes entry, 0..100) into FullWeights (ufbx PR #212; Blender export_fbx_bin.py): they
     * scale the deltas and the full weight is 100. Such a FullWeights node is given here
     * instead of full_weights and decoded by the shape's job (one per-vertex array per channel
     * would otherwise stay decoded until every shape is done). */
    const fbx_node *vertex_weights;
    uint32_t channel;                 /* out: the raw channel index, UINT32_MAX when every shape was unusable */
} fbx_channel_plan;

/* Adds the channels of `plans` to mesh `mesh` in plan order. The shapes' arrays are decoded and
 * expanded to render vertices (fbx_expand_shape) on options->threads worker threads; channels,
 * targets, warnings and the first error (in plan and in-between order) are then given as one
 * thread going through the shapes one by one would give them, so the result is the same for
 * any thread count. The map's expansion scratch is allocated if needed (fbx_mesh_map_free
 * releases it). */
mk_result fbx_add_channels(fbx_doc *doc, mk_raw_asset *raw, const mk_import_options *options, uint32_t mesh,
                           fbx_mesh_map *map, fbx_channel_plan *plans, uint32_t plan_count);

#endif

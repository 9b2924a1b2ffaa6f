/* SPDX-License-Identifier: MIT */
/* A reference frame made by other software (or by 'morphkit frames'), read into one shape:
 * meshes with the names that match them to the import, their channel weights, positions and
 * (where present) normals. Kinds and their matching rules: docs/conformance.md. */
#ifndef MK_PB_REFERENCE_H
#define MK_PB_REFERENCE_H

#include "manifest.h"

typedef struct pb_ref_mesh {
    const char *label;                            /* for reports */
    const char *node;                             /* FBX model / node name, or NULL */
    int32_t gltf_node, gltf_mesh, gltf_primitive; /* -1 when not given */
    int32_t mesh_index;         /* the asset's mesh (frames written by morphkit), or -1 */
    int has_channels;                             /* the reference lists channels (or weights) for this mesh */
    uint32_t weight_count;                        /* the channel weights the reference evaluated with */
    double *weights;
    uint32_t point_count; /* positions: 3 doubles per point */
    double *positions;
    double *normals; /* 3 per point, or NULL; directions (need not be unit) */
} pb_ref_mesh;

typedef struct pb_reference {
    mk_arena arena;
    uint32_t mesh_count;
    pb_ref_mesh *meshes;
} pb_reference;

/* Reads a reference file of the given kind. An OBJ gives one mesh (its v and vn lines). Free
 * with pb_reference_free, also on error. */
mk_result pb_reference_read(const char *path, pb_reference_kind kind, pb_reference *out, mk_error *err);
void pb_reference_free(pb_reference *r);

#endif

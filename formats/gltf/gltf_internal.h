/* SPDX-License-Identifier: MIT */
/* Shared between the glTF importer's C files (not a public header). */
#ifndef MK_GLTF_INTERNAL_H
#define MK_GLTF_INTERNAL_H

#include "gltf_accessor.h"
#include "gltf_import.h"

/* One raw mesh per (node, primitive) instance of a mesh with morph targets. */
typedef struct mk_gltf_instance {
    int32_t node, mesh, primitive;
    uint32_t raw_mesh;
    uint32_t target_count;         /* glTF targets of the mesh */
    uint32_t *target_channel;      /* per glTF target: raw channel index, UINT32_MAX = dropped */
    float *target_full_weight;     /* per glTF target: full weight inside its channel */
} mk_gltf_instance;

/* ---- sidecar (gltf_sidecar.c; format in docs/importing-gltf.md) ---- */
typedef struct mk_gltf_sidecar_channel {
    const char *name;
    const char *origin;            /* NULL when absent */
    uint32_t target_count;
    uint32_t *targets;             /* glTF target indices */
    float *full_weights;
    const char **target_names;     /* per target or NULL */
} mk_gltf_sidecar_channel;

typedef struct mk_gltf_sidecar_mesh {
    int32_t node, primitive;
    const char *name;              /* NULL: keep the node name */
    int stacking;                  /* 0 = keep the import option */
    uint32_t channel_count;
    mk_gltf_sidecar_channel *channels;
    uint32_t unused_count;
    uint32_t *unused;              /* glTF targets that carry no channel (padding) */
    uint32_t control_point_count;  /* 0: identity map */
    uint32_t control_point_map_count;
    uint32_t *control_points;      /* per glTF vertex */
} mk_gltf_sidecar_mesh;

typedef struct mk_gltf_sidecar_clip {
    float start, duration;        /* seconds */
} mk_gltf_sidecar_clip;

typedef struct mk_gltf_sidecar {
    uint32_t mesh_count;
    mk_gltf_sidecar_mesh *meshes;
    uint32_t clip_count;           /* 0: keep what the animations say */
    mk_gltf_sidecar_clip *clips;   /* per glTF animation, in order */
} mk_gltf_sidecar;

mk_result mk_gltf_sidecar_parse(mk_arena *arena, const char *text, size_t size, const char *where,
                                mk_gltf_sidecar *out, mk_error *err);

/* ---- animation (gltf_anim.c) ---- */
/* Adds one clip per glTF animation (index preserved). */
mk_result mk_gltf_import_animations(mk_gltf_reader *reader, const mk_gltf_instance *instances,
                                    uint32_t instance_count, mk_raw_asset *out, mk_error *err);

#endif

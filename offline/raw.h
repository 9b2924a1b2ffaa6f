/* SPDX-License-Identifier: MIT */
/* The raw model: an editable, offline description of meshes, channels, in-between targets
 * and weight clips (docs/architecture.md). Importers fill it, bakers add to it, the writer
 * turns it into a .morph blob, the reader turns a blob back into it.
 *
 * All memory of a raw asset comes from its arena: mk_raw_free releases everything. Fields are
 * plain arrays so importers and bakers can fill them directly; mk_raw_validate checks the
 * whole model before writing.
 */
#ifndef MK_RAW_H
#define MK_RAW_H

#include <stdint.h>
#include "alloc.h"
#include "morphkit.h"

typedef struct mk_raw_target {
    char *name;
    float full_weight;         /* normalized: FBX FullWeights / 100; glTF 1.0. Never 0. */
    uint32_t count;            /* moved vertices */
    uint32_t *indices;         /* render-vertex indices, strictly increasing */
    float *positions;          /* 3 * count position deltas */
    float *normals;            /* 3 * count normal deltas, or NULL */
    float *tangents;           /* 3 * count tangent (xyz) deltas, or NULL */
} mk_raw_target;

typedef struct mk_raw_channel {
    char *name;
    char *origin;              /* "" or NULL when imported; the recipe JSON for baked channels */
    uint32_t mesh;
    float default_weight;      /* normalized weight with no clip (FBX DeformPercent / 100) */
    uint32_t target_count;
    mk_raw_target *targets;    /* in increasing full weight after mk_raw_sort_targets */
} mk_raw_channel;

typedef struct mk_raw_mesh {
    char *name;                /* FBX model name / glTF node name */
    uint32_t vertex_count;
    float *positions;          /* 3 per vertex */
    float *normals;            /* 3 per vertex or NULL */
    float *tangents;           /* 4 per vertex (w = handedness) or NULL */
    uint32_t triangle_count;
    uint32_t *triangles;       /* 3 per triangle, render-vertex indices */
    uint32_t control_point_count;
    uint32_t *control_points;  /* per render vertex: source control point (FBX) / vertex (glTF) */
    float world[16];           /* column-major world transform of the node at rest */
    int32_t gltf_node, gltf_mesh, gltf_primitive; /* -1 when not glTF */
    int64_t fbx_geometry;      /* FBX 7.x: id of the source Geometry object (write-back finds it); 0 otherwise */
    mk_stacking stacking;      /* MK_STACKING_ADDITIVE or MK_STACKING_SEQUENTIAL */
} mk_raw_mesh;

typedef struct mk_raw_track {
    uint32_t channel;          /* asset channel index */
    uint32_t key_count;
    mk_key *keys;              /* strictly increasing times */
} mk_raw_track;

typedef struct mk_raw_clip {
    char *name;
    float start, duration;     /* seconds */
    uint32_t track_count;
    mk_raw_track *tracks;
} mk_raw_clip;

typedef struct mk_raw_warning {
    char message[200];
} mk_raw_warning;

typedef struct mk_raw_asset {
    mk_arena arena;
    uint32_t mesh_count, channel_count, clip_count;
    mk_raw_mesh *meshes;
    mk_raw_channel *channels;  /* grouped by mesh, meshes in order */
    mk_raw_clip *clips;
    uint32_t warning_count;    /* all warnings; only the first MK_RAW_MAX_WARNINGS are kept */
    mk_raw_warning *warnings;
    /* Import facts reported by `morphkit info` (0 / "" when unknown). */
    char source_format[32];    /* "fbx 7500 binary", "gltf", ... */
    char source_creator[128];
    float unit_scale;          /* FBX UnitScaleFactor (cm per unit) */
    int32_t up_axis;           /* FBX UpAxis (0 x, 1 y, 2 z), -1 unknown */
} mk_raw_asset;

#define MK_RAW_MAX_WARNINGS 256

void mk_raw_init(mk_raw_asset *raw, const mk_allocator *allocator);
void mk_raw_free(mk_raw_asset *raw);

/* Appends zeroed elements and returns a pointer to the first new one (NULL on OOM). */
mk_raw_mesh *mk_raw_add_meshes(mk_raw_asset *raw, uint32_t count);
mk_raw_channel *mk_raw_add_channels(mk_raw_asset *raw, uint32_t count);
mk_raw_clip *mk_raw_add_clips(mk_raw_asset *raw, uint32_t count);
mk_raw_target *mk_raw_add_targets(mk_raw_asset *raw, mk_raw_channel *channel, uint32_t count);

/* Records a warning (printf-style); never fails. */
void mk_raw_warn(mk_raw_asset *raw, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Sorts each channel's targets by full weight (stable). Equal full weights stay and are
 * reported by mk_raw_validate. */
void mk_raw_sort_targets(mk_raw_asset *raw);
/* Orders channels by mesh (stable) and remaps tracks, so the asset is ready to write. */
mk_result mk_raw_group_channels(mk_raw_asset *raw, mk_error *err);

/* Removes the meshes that have no channel (remapping channel mesh indices), with one warning
 * per mesh: "mesh 'NAME' has no morph targets; <what>" (what NULL: "skipped"). */
void mk_raw_drop_plain_meshes(mk_raw_asset *raw, const char *what);
/* Removes every target's normal deltas (mk_import_options.target_normals = none); positions
 * and tangent deltas stay. */
void mk_raw_drop_target_normals(mk_raw_asset *raw);

/* The length of the diagonal of the mesh's base positions' bounding box, in float (the writer's
 * default quantization tolerance is 1e-4 of it; writers of other formats compare deltas with it). */
float mk_raw_mesh_diagonal(const mk_raw_mesh *mesh);

/* Checks everything the writer and runtime rely on: counts, indices in range, strictly
 * increasing sparse indices and key times, finite values, nonzero and strictly increasing
 * full weights, channel grouping. The error names the element (mesh/channel/target/key). */
mk_result mk_raw_validate(const mk_raw_asset *raw, mk_error *err);

/* Computes normal deltas for every target of a mesh that has base normals but no normal
 * deltas (or when `force`), from the target positions with the base triangles. Vertices with
 * the same control point and the same base normal are smoothed together (UV seams merge,
 * hard edges stay hard). Δn = N(target) - N(base), both computed the same way, so the
 * authored base normals are kept at weight 0. Targets are computed in parallel on `threads`
 * threads (0: one per core; the result is the same for any count). */
mk_result mk_raw_compute_target_normals(mk_raw_asset *raw, uint32_t mesh, int force, uint32_t threads, mk_error *err);
/* The same for a model whose target arrays are each a block of the raw arena, pointed at by
 * nothing else (an importer's): a target's indices and positions grow in place (their pages
 * are kept, mk_arena_grow) and its replaced arrays go back to the arena as soon as its new
 * ones exist, so the old and new arrays of all targets are never alive at once. */
mk_result mk_raw_compute_target_normals_replacing(mk_raw_asset *raw, uint32_t mesh, int force, uint32_t threads,
                                                  mk_error *err);

#endif

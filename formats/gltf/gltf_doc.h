/* SPDX-License-Identifier: MIT */
/* A plain C view of a parsed glTF 2.0 document (.gltf or .glb).
 *
 * gltf_doc.cc parses the JSON and loads buffers with tinygltf (C++), decodes
 * KHR_draco_mesh_compression primitives with libdraco, and copies what the morph importer needs
 * into the plain structs below. Everything else (accessor decoding, sparse, quantization,
 * meshopt, building the raw model) is C in gltf_import.c and gltf_accessor.c.
 *
 * Indices into the arrays are the document's own indices; -1 means "absent". Nothing here has
 * been range-checked against the other arrays: the C side checks every index before use, so a
 * hostile document cannot make it read out of bounds. Byte ranges (offset + length) are also
 * unchecked here. Arrays and strings live in the arena given to mk_gltf_doc_load, buffer bytes
 * live in the document (freed by mk_gltf_doc_free).
 */
#ifndef MK_GLTF_DOC_H
#define MK_GLTF_DOC_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "alloc.h"

/* glTF componentType values (spec §3.6.2.2). */
enum {
    MK_GLTF_BYTE = 5120, MK_GLTF_UNSIGNED_BYTE = 5121, MK_GLTF_SHORT = 5122,
    MK_GLTF_UNSIGNED_SHORT = 5123, MK_GLTF_UNSIGNED_INT = 5125, MK_GLTF_FLOAT = 5126
};

typedef enum mk_gltf_meshopt_mode { MK_MESHOPT_ATTRIBUTES = 0, MK_MESHOPT_TRIANGLES, MK_MESHOPT_INDICES } mk_gltf_meshopt_mode;
typedef enum mk_gltf_meshopt_filter { MK_MESHOPT_NONE = 0, MK_MESHOPT_OCTAHEDRAL, MK_MESHOPT_QUATERNION, MK_MESHOPT_EXPONENTIAL } mk_gltf_meshopt_filter;

typedef struct mk_gltf_buffer {
    const uint8_t *data;
    uint64_t size;                /* bytes actually loaded */
} mk_gltf_buffer;

typedef struct mk_gltf_view {
    int32_t buffer;
    uint64_t offset, length;
    uint32_t stride;              /* 0 = tightly packed */
    /* EXT_meshopt_compression: the view's bytes are produced by decoding this range. */
    int meshopt;
    int32_t mo_buffer;
    uint64_t mo_offset, mo_length;
    uint32_t mo_stride;
    uint64_t mo_count;
    int mo_mode;                  /* mk_gltf_meshopt_mode, -1 when unknown */
    int mo_filter;                /* mk_gltf_meshopt_filter, -1 when unknown */
} mk_gltf_view;

typedef struct mk_gltf_accessor {
    int32_t view;                 /* -1: zeros (spec §3.6.2.3), possibly overridden by sparse */
    uint64_t offset;
    int component_type;           /* MK_GLTF_* or anything else (rejected later) */
    int components;               /* 1 SCALAR, 2..4 VECn, 4/9/16 MATn; 0 unknown */
    int normalized;
    uint64_t count;
    int sparse;
    uint64_t sparse_count;
    int32_t sparse_indices_view;
    uint64_t sparse_indices_offset;
    int sparse_indices_type;
    int32_t sparse_values_view;
    uint64_t sparse_values_offset;
} mk_gltf_accessor;

typedef struct mk_gltf_attribute {
    const char *semantic;         /* "POSITION", "NORMAL", ... */
    int32_t accessor;
} mk_gltf_attribute;

typedef struct mk_gltf_target {
    uint32_t attribute_count;
    mk_gltf_attribute *attributes;
} mk_gltf_target;

/* One attribute decoded from a Draco buffer, in the decoded vertex order. */
typedef struct mk_gltf_draco_attribute {
    const char *semantic;
    uint32_t components;
    float *values;                /* components * point_count; normalized integers already in [-1,1]/[0,1] */
} mk_gltf_draco_attribute;

typedef struct mk_gltf_primitive {
    int mode;                     /* 4 triangles (default), 5 strip, 6 fan, 0..3 points/lines */
    int32_t indices;
    uint32_t attribute_count;
    mk_gltf_attribute *attributes;
    uint32_t target_count;
    mk_gltf_target *targets;
    uint32_t target_name_count;   /* primitive.extras.targetNames (older UniGLTF/VRM files) */
    const char **target_names;
    /* KHR_draco_mesh_compression, decoded by the shim. */
    int draco;                    /* 1 when the primitive has the extension */
    uint32_t draco_point_count;
    uint32_t draco_index_count;   /* 3 * faces */
    uint32_t *draco_indices;
    uint32_t draco_attribute_count;
    mk_gltf_draco_attribute *draco_attributes;
} mk_gltf_primitive;

typedef struct mk_gltf_mesh {
    const char *name;             /* "" when unnamed */
    uint32_t primitive_count;
    mk_gltf_primitive *primitives;
    uint32_t weight_count;
    double *weights;
    uint32_t target_name_count;   /* mesh.extras.targetNames */
    const char **target_names;
} mk_gltf_mesh;

typedef struct mk_gltf_node {
    const char *name;             /* "" when unnamed */
    int32_t mesh;
    uint32_t child_count;
    int32_t *children;
    int has_matrix;
    double matrix[16];            /* column-major, when has_matrix */
    double translation[3], rotation[4], scale[3]; /* defaults 0 / (0,0,0,1) / 1 */
    uint32_t weight_count;
    double *weights;
} mk_gltf_node;

typedef enum mk_gltf_interp { MK_GLTF_LINEAR = 0, MK_GLTF_STEP, MK_GLTF_CUBICSPLINE, MK_GLTF_INTERP_UNKNOWN } mk_gltf_interp;

typedef struct mk_gltf_sampler {
    int32_t input, output;
    int interpolation;            /* mk_gltf_interp */
} mk_gltf_sampler;

typedef struct mk_gltf_channel {
    int32_t sampler;
    int32_t node;
    const char *path;             /* "weights", "translation", ... */
} mk_gltf_channel;

typedef struct mk_gltf_animation {
    const char *name;
    uint32_t channel_count, sampler_count;
    mk_gltf_channel *channels;
    mk_gltf_sampler *samplers;
} mk_gltf_animation;

typedef struct mk_gltf_doc {
    uint32_t buffer_count, view_count, accessor_count, mesh_count, node_count, animation_count;
    mk_gltf_buffer *buffers;
    mk_gltf_view *views;
    mk_gltf_accessor *accessors;
    mk_gltf_mesh *meshes;
    mk_gltf_node *nodes;
    mk_gltf_animation *animations;
    int32_t scene;                /* default scene or -1 */
    uint32_t scene_node_count;    /* root nodes of the default scene (scene 0 when none is set) */
    int32_t *scene_nodes;
    uint32_t required_count;
    const char **extensions_required;
    const char *generator;
    void *impl;                   /* the tinygltf model (owns buffer bytes) */
} mk_gltf_doc;

/* Parses a document from memory. `is_binary`: 1 GLB, 0 JSON, -1 decide from the "glTF" magic.
 * base_dir: directory for external buffer URIs, or NULL to refuse external files (fuzzing).
 * URIs resolve against base_dir only, never the working directory; absolute paths and schemes
 * other than data: are refused (MK_ERROR_UNSUPPORTED), a missing file is MK_ERROR_IO naming the
 * URI and the path tried.
 * max_file_size bounds every external file (0 = no bound). file_read (may be NULL) is called
 * with the path of every external file read. Warnings of the parser are dropped;
 * errors name the parser's complaint. */
mk_result mk_gltf_doc_load(mk_arena *arena, const void *data, size_t size, int is_binary,
                           const char *base_dir, uint64_t max_file_size,
                           void (*file_read)(void *user, const char *path), void *file_read_user,
                           mk_gltf_doc *out, mk_error *err);
void mk_gltf_doc_free(mk_gltf_doc *doc);

#ifdef __cplusplus
}
#endif
#endif

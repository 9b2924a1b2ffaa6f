/* SPDX-License-Identifier: MIT */
/* The glTF writer: a raw model as glTF 2.0 (.glb or .gltf), plus the channel sidecar that lets
 * a re-import restore progressive channels. Behaviour: docs/importing-gltf.md. */
#ifndef MK_GLTF_EXPORT_H
#define MK_GLTF_EXPORT_H

#ifdef __cplusplus
extern "C" {
#endif

#include "raw.h"

typedef struct mk_gltf_export_report {
    uint32_t meshes, targets, clips;
    uint32_t progressive_channels;  /* channels exported as several targets */
    uint32_t resampled_tracks;      /* weight tracks written as sampled LINEAR keys */
    uint32_t padding_targets;       /* empty targets added so primitives of a node agree */
    uint32_t fixed_normals;         /* zero-length base normals/tangents replaced (glTF needs unit ones) */
} mk_gltf_export_report;

typedef enum mk_gltf_container {
    MK_GLTF_GLB = 0,                /* binary .glb */
    MK_GLTF_JSON = 1                /* .gltf: JSON with the buffer embedded as base64 */
} mk_gltf_container;

/* Exports raw as glTF into memory from arena: the file's bytes, and (when sidecar is not
 * NULL) the channel sidecar's JSON text. */
mk_result mk_export_gltf_memory(const mk_raw_asset *raw, mk_gltf_container container, mk_arena *arena,
                                void **gltf, size_t *gltf_size, char **sidecar, size_t *sidecar_size,
                                mk_gltf_export_report *report, mk_error *err);

/* Writes raw as .gltf or .glb (by the path's extension) plus the sidecar at sidecar_path
 * (NULL: none), both or neither, with the output rules of blob_io.h. */
mk_result mk_export_gltf(const mk_raw_asset *raw, const char *path, const char *sidecar_path,
                         mk_gltf_export_report *report, mk_error *err);

#ifdef __cplusplus
}
#endif
#endif

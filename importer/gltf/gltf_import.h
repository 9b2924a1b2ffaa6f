/* glTF import entry points beyond import.h: from memory (fuzzing, tests), and the exporter. */
#ifndef MK_GLTF_IMPORT_H
#define MK_GLTF_IMPORT_H

#ifdef __cplusplus
extern "C" {
#endif

#include "import.h"

/* .gltf or .glb bytes (sniffed by the "glTF" magic). base_dir resolves external buffer URIs
 * (and only it: never the working directory; "" is the working directory); NULL refuses them.
 * options->channels_sidecar is read from its path when set. */
mk_result mk_import_gltf_memory(const void *data, size_t size, const char *base_dir,
                                const mk_import_options *options, mk_raw_asset *out, mk_error *err);

/* Same with the sidecar given as text (size bytes) instead of a path; sidecar may be NULL. */
mk_result mk_import_gltf_memory_sidecar(const void *data, size_t size, const char *base_dir,
                                        const mk_import_options *options, const char *sidecar,
                                        size_t sidecar_size, mk_raw_asset *out, mk_error *err);

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
 * NULL) the channel sidecar's JSON text that lets a re-import restore progressive channels. */
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

/* Importers: FBX and glTF sources into the raw model. */
#ifndef MK_IMPORT_H
#define MK_IMPORT_H

#include "raw.h"

typedef struct mk_import_options {
    mk_stacking stacking;          /* stacking stored for every mesh; 0 = additive */
    int keep_shape_normals;        /* FBX: 0 = use shape normals only when present and non-zero (default) */
    const char *channels_sidecar;  /* glTF: path of a sidecar JSON grouping targets into channels, or NULL */
    size_t max_input_size;         /* bytes; 0 = 4 GiB */
    int keep_plain_meshes;         /* mk_import_file: 0 = meshes without morph targets are dropped
                                    * (with a warning naming each); 1 = kept (bakers start from them) */
} mk_import_options;

/* Binary or ASCII FBX from memory. Warnings go to out->warnings. */
mk_result mk_import_fbx(const void *data, size_t size, const mk_import_options *options,
                        mk_raw_asset *out, mk_error *err);

/* .gltf or .glb from a path (external buffers resolve against its folder only, see
 * docs/importing-gltf.md). */
mk_result mk_import_gltf(const char *path, const mk_import_options *options,
                         mk_raw_asset *out, mk_error *err);

/* Dispatches on the file's content/extension: .fbx, .gltf, .glb, .morph. */
mk_result mk_import_file(const char *path, const mk_import_options *options,
                         mk_raw_asset *out, mk_error *err);

#endif

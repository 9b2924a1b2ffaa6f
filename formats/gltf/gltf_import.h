/* SPDX-License-Identifier: MIT */
/* The glTF reader: .gltf or .glb from memory into the raw model. External buffers resolve
 * against options->base_dir only; a channel sidecar (options->channels_sidecar or its text)
 * regroups targets into progressive channels. Behaviour: docs/importing-gltf.md. */
#ifndef MK_GLTF_IMPORT_H
#define MK_GLTF_IMPORT_H

#ifdef __cplusplus
extern "C" {
#endif

#include "import_options.h"

/* out must be mk_raw_init'ed. The same shape as every importer (see import.h). */
mk_result mk_import_gltf(const void *data, size_t size, const mk_import_options *options,
                         mk_raw_asset *out, mk_error *err);

#ifdef __cplusplus
}
#endif
#endif

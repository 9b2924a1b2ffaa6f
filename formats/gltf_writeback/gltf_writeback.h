/* SPDX-License-Identifier: MIT */
/* Baking into the artist's own glTF (docs/baking.md, "Baking into your own file"): the input
 * .gltf/.glb is edited as a JSON tree that keeps every member (extensions, extras, unknown
 * properties, order), and the baked channels of a raw asset imported from it are appended as
 * new morph targets. Untouched binary data stays byte-identical (a .glb's BIN chunk is only
 * extended); new bytes go to the end of the BIN chunk (.glb) or into one new base64 data: URI
 * buffer (.gltf). */
#ifndef MK_GLTF_WRITEBACK_H
#define MK_GLTF_WRITEBACK_H

#include "raw.h"

typedef struct mk_gltf_write_back_report {
    uint32_t meshes;                /* glTF meshes that got new targets */
    uint32_t channels;              /* baked channels written */
    uint32_t targets;               /* glTF targets appended, over all meshes (per mesh, not per primitive) */
    uint32_t padding_targets;       /* zero targets on primitives a channel does not deform */
    uint32_t sparse_accessors, dense_accessors;
    uint32_t quantized_accessors;   /* written with the primitive's quantized component type */
    uint32_t float_fallbacks;       /* quantized primitive, but a delta did not fit: written as float */
    uint32_t rewritten_samplers;    /* existing weight animations extended with the new targets */
    uint32_t animations_added;      /* baked clips written as new animations (sampled LINEAR) */
    uint32_t rewritten_uris;        /* relative URIs made to point at the input's folder */
    uint32_t draco_primitives;      /* deformed primitives that are Draco-compressed */
    size_t added_bytes;             /* new binary bytes */
    int sidecar_needed;             /* a baked channel has in-betweens: without the sidecar a
                                     * re-import sees one channel per target */
    uint32_t note_count;            /* lines worth telling the user (first 8 kept) */
    char notes[8][200];
} mk_gltf_write_back_report;

/* input/input_size: the original .gltf or .glb bytes; input_path: its path (external buffers
 * resolve against its folder; NULL refuses them); output_path: where the result will be
 * written (relative URIs are rewritten when its folder differs from the input's; NULL: the
 * same folder). The output container must be the input's (.glb for a GLB, .gltf for JSON).
 * raw: the asset imported from these bytes (mk_import_file with keep_plain_meshes, no sidecar)
 * and then baked; baked channels are those with a non-empty origin, clips past the file's
 * animations are the bake's. *out (and, when sidecar is not NULL, the channel sidecar text in
 * *sidecar) come from arena. All or nothing: on error nothing is returned and err names the
 * element (JSON path, mesh, node). */
mk_result mk_gltf_write_back(const void *input, size_t input_size, const char *input_path, const char *output_path,
                             const mk_raw_asset *raw, mk_arena *arena, void **out, size_t *out_size, char **sidecar,
                             size_t *sidecar_size, mk_gltf_write_back_report *report, mk_error *err);

#endif

/* SPDX-License-Identifier: MIT */
/* Decoding glTF accessors into floats and indices: strides, normalized and integer
 * components (KHR_mesh_quantization), sparse substitution, accessors without bufferView (zeros)
 * and EXT_meshopt_compression bufferViews. Every offset, count and index is checked; errors
 * name the accessor (and bufferView / element) at fault. */
#ifndef MK_GLTF_ACCESSOR_H
#define MK_GLTF_ACCESSOR_H

#include "gltf_doc.h"

typedef struct mk_gltf_reader {
    const mk_gltf_doc *doc;
    mk_arena *arena;              /* decoded data and the view cache live here */
    const uint8_t **decoded;      /* per bufferView: meshopt-decoded bytes, or NULL */
    uint64_t *decoded_size;
} mk_gltf_reader;

mk_result mk_gltf_reader_init(mk_gltf_reader *r, const mk_gltf_doc *doc, mk_arena *arena, mk_error *err);

/* Bytes of a bufferView (meshopt views are decoded once and cached). */
mk_result mk_gltf_view_bytes(mk_gltf_reader *r, int32_t view, const uint8_t **data, uint64_t *size,
                             mk_error *err);

/* Accessor `index` as floats, `components` per element (the accessor must have exactly that
 * many), normalized integers mapped per the spec, non-normalized integers converted as is.
 * Sparse values are applied. Non-finite values are an error. *count gets the element count. */
mk_result mk_gltf_read_floats(mk_gltf_reader *r, int32_t index, int components, const char *what,
                              float **out, uint64_t *count, mk_error *err);

/* Index accessor (SCALAR, unsigned byte/short/int) as uint32. */
mk_result mk_gltf_read_indices(mk_gltf_reader *r, int32_t index, const char *what, uint32_t **out,
                               uint64_t *count, mk_error *err);

#endif

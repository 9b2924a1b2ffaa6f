/* SPDX-License-Identifier: MIT */
/* Target normals for the meshes an FBX import added, computed after the parse data (and, with
 * mk_import_options.input_done, the input bytes) is released: the normals are the import's
 * largest step in memory, and by then nothing else of the file is needed. The shapes' arrays
 * (fbx_expand_shape: one raw-arena block each) are given back as the grown ones replace them. */
#include "fbx_internal.h"

mk_result fbx_target_normals(mk_raw_asset *raw, uint32_t first_mesh, const mk_import_options *options, mk_error *err)
{
    /* A mesh whose targets all have normals is skipped by the call itself (force 0). */
    for (uint32_t m = first_mesh; m < raw->mesh_count; m++) {
        mk_result r = mk_raw_compute_target_normals_replacing(raw, m, 0, options->threads, err);
        if (r != MK_OK) return r;
    }
    return MK_OK;
}

/* SPDX-License-Identifier: MIT */
/* Target normals for the meshes an FBX import added, computed after the parse data (and, with
 * mk_import_options.input_done, the input bytes) is released: the normals are the import's
 * largest step in memory, and by then nothing else of the file is needed. */
#include "fbx_internal.h"

/* The shapes of a mesh that need normals (in asset order); their arrays, made by
 * fbx_expand_shape from the raw arena and pointed at by nothing else, are replaced by grown
 * ones and given back here. */
typedef struct replaced {
    const mk_raw_target *target;
    void *indices, *positions;
} replaced;

static mk_result mesh_normals(mk_raw_asset *raw, uint32_t mesh, uint32_t threads, mk_error *err)
{
    uint32_t count = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (raw->channels[c].mesh == mesh)
            for (uint32_t k = 0; k < raw->channels[c].target_count; k++) count += !raw->channels[c].targets[k].normals;
    if (!count) return MK_OK;
    replaced *old = mk_arena_array(&raw->arena, count, sizeof *old);
    if (!old) return mk_error_oom(err, "computing target normals");
    uint32_t n = 0;
    for (uint32_t c = 0; c < raw->channel_count; c++)
        if (raw->channels[c].mesh == mesh)
            for (uint32_t k = 0; k < raw->channels[c].target_count; k++) {
                const mk_raw_target *t = &raw->channels[c].targets[k];
                if (!t->normals) old[n++] = (replaced){ t, t->indices, t->positions };
            }
    mk_result r = mk_raw_compute_target_normals(raw, mesh, 0, threads, err);
    /* A target left as it was (a mesh without base normals or triangles) keeps its arrays. */
    for (uint32_t i = 0; i < count; i++) {
        if (old[i].target->indices == old[i].indices || old[i].target->positions == old[i].positions) continue;
        mk_arena_release(&raw->arena, old[i].indices);
        mk_arena_release(&raw->arena, old[i].positions);
    }
    mk_arena_release(&raw->arena, old);
    return r;
}

mk_result fbx_target_normals(mk_raw_asset *raw, uint32_t first_mesh, const mk_import_options *options, mk_error *err)
{
    for (uint32_t m = first_mesh; m < raw->mesh_count; m++) {
        mk_result r = mesh_normals(raw, m, options->threads, err);
        if (r != MK_OK) return r;
    }
    return MK_OK;
}

/* SPDX-License-Identifier: MIT */
/* mk_import_fbx: binary or ASCII FBX from memory into the raw model.
 *
 * Steps: parse the file into a node tree (fbx_doc_parse: fbx_binary.c / fbx_ascii.c, with limits
 * against hostile input), then interpret it (fbx_scene.c: objects, connections, meshes, blend shapes,
 * curves), then compute the target normals the file does not store (fbx_normals.c). All parse
 * memory comes from a scratch arena on the same allocator as the raw model and is released
 * before the normals are computed, on success and on error; so are the input bytes when the
 * caller offers (mk_import_options.input_done).
 */
#include <string.h>
#include "fbx_internal.h"

mk_result mk_import_fbx(const void *data, size_t size, const mk_import_options *options,
                        mk_raw_asset *out, mk_error *err)
{
    if (!data || !out) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "mk_import_fbx: NULL data or output");
    mk_import_options defaults;
    memset(&defaults, 0, sizeof defaults);
    if (!options) options = &defaults;
    mk_result r = mk_import_options_check(options, size, "FBX", err);
    if (r != MK_OK) return r;
    mk_error local;
    if (!err) err = &local;
    mk_arena scratch;
    mk_arena_init(&scratch, &out->arena.allocator);
    fbx_doc doc;
    const uint32_t first_mesh = out->mesh_count;
    r = fbx_doc_parse(&doc, &scratch, data, size, err);
    doc.threads = options->threads;
    mk_phase_log_mark(options->phases, "parse");
    if (r == MK_OK) r = fbx_convert(&doc, options, out);
    fbx_doc_free(&doc);
    mk_arena_free_all(&scratch);
    if (options->input_done) options->input_done(options->input_done_user);  /* data is not read again */
    mk_phase_log_mark(options->phases, "release parse data");
    if (r == MK_OK && options->target_normals != MK_TARGET_NORMALS_NONE) {
        r = fbx_target_normals(out, first_mesh, options, err);
        mk_phase_log_mark(options->phases, "target normals");
    }
    return r != MK_OK ? r : mk_import_finish(out, options, err);
}

/* SPDX-License-Identifier: MIT */
#include "import_options.h"

mk_result mk_import_options_check(const mk_import_options *o, size_t input_size, const char *format, mk_error *err)
{
    if (!o) return MK_OK;
    if ((unsigned)o->stacking > MK_STACKING_SEQUENTIAL)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "%s import: unknown stacking %d", format,
                            (int)o->stacking);
    if ((unsigned)o->target_normals > MK_TARGET_NORMALS_NONE)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "%s import: unknown target normals choice %d",
                            format, (int)o->target_normals);
    if (o->channels_sidecar && o->channels_sidecar_text)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX,
                            "%s import: give the channel sidecar as a path or as text, not both", format);
    size_t limit = o->max_input_size ? o->max_input_size : MK_IMPORT_DEFAULT_MAX_INPUT;
    if (input_size > limit)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s input of %zu bytes exceeds the limit of %zu bytes",
                            format, input_size, limit);
    return MK_OK;
}

mk_result mk_import_finish(mk_raw_asset *raw, const mk_import_options *o, mk_error *err)
{
    if (o && o->stacking)
        for (uint32_t m = 0; m < raw->mesh_count; m++) raw->meshes[m].stacking = o->stacking;
    if (!o || !o->keep_plain_meshes) mk_raw_drop_plain_meshes(raw, NULL);
    if (o && o->target_normals == MK_TARGET_NORMALS_NONE) mk_raw_drop_target_normals(raw);
    mk_raw_sort_targets(raw);
    mk_result r = mk_raw_group_channels(raw, err);
    if (r == MK_OK) r = mk_raw_validate(raw, err);
    if (o) mk_phase_log_mark(o->phases, "validate");
    return r;
}

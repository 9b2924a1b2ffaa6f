/* mk_import_file: picks the importer from the file's content (magic) and extension. */
#include <string.h>
#include "blob_io.h"
#include "format.h"
#include "import.h"

static mk_result import_any(const char *path, const mk_import_options *options, mk_raw_asset *out, mk_error *err)
{
    if (options && (unsigned)options->stacking > MK_STACKING_SEQUENTIAL)
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "import: unknown stacking %d", (int)options->stacking);
    if (mk_path_has_extension(path, ".gltf") || mk_path_has_extension(path, ".glb")) return mk_import_gltf(path, options, out, err);
    size_t max = options && options->max_input_size ? options->max_input_size : (size_t)4 << 30;
    void *data;
    size_t size;
    mk_result r = mk_read_file(&out->arena, path, max, &data, &size, err);
    if (r) return r;
    if (size >= 8 && memcmp(data, MK_MAGIC, 8) == 0) {
        mk_asset asset;
        r = mk_asset_open(data, size, &asset, err);
        if (r == MK_OK) r = mk_read_blob(&asset, out, err);
    } else if (size >= 4 && memcmp(data, "glTF", 4) == 0) {
        mk_arena_release(&out->arena, data);
        return mk_import_gltf(path, options, out, err);
    } else if (mk_path_has_extension(path, ".fbx") || (size >= 18 && memcmp(data, "Kaydara FBX Binary", 18) == 0)) {
        r = mk_import_fbx(data, size, options, out, err);
    } else {
        r = mk_error_set(err, MK_ERROR_UNSUPPORTED, 0, "%s: unknown file type (expected .morph, .fbx, .gltf or .glb)", path);
    }
    mk_arena_release(&out->arena, data);
    return r;
}

mk_result mk_import_file(const char *path, const mk_import_options *options, mk_raw_asset *out, mk_error *err)
{
    mk_result r = import_any(path, options, out, err);
    if (r != MK_OK) return r;
    /* The options every format shares are applied here, once. */
    if (options && options->stacking)
        for (uint32_t m = 0; m < out->mesh_count; m++) out->meshes[m].stacking = options->stacking;
    if (!options || !options->keep_plain_meshes) mk_raw_drop_plain_meshes(out, NULL);
    return MK_OK;
}

/* SPDX-License-Identifier: MIT */
/* mk_import_memory / mk_import_file: pick the reader from the content. */
#include <stdio.h>
#include <string.h>
#include "blob_io.h"
#include "fbx_import.h"
#include "gltf_import.h"
#include "import.h"

static mk_result import_blob(const void *data, size_t size, const mk_import_options *options, mk_raw_asset *out,
                             mk_error *err)
{
    mk_result r = mk_import_options_check(options, size, ".morph", err);
    mk_asset asset;
    if (r == MK_OK) r = mk_asset_open(data, size, &asset, err);
    if (r == MK_OK) r = mk_read_blob(&asset, out, err);
    if (options) mk_phase_log_mark(options->phases, "open and read blob");
    return r != MK_OK ? r : mk_import_finish(out, options, err);
}

/* A glTF file starts with the GLB magic or, as JSON, with '{' after optional whitespace and a
 * byte-order mark (an FBX ASCII file starts with a comment or a node name). */
static int looks_like_gltf(const unsigned char *p, size_t size)
{
    if (size >= 4 && memcmp(p, "glTF", 4) == 0) return 1;
    size_t i = size >= 3 && p[0] == 0xEF && p[1] == 0xBB && p[2] == 0xBF ? 3 : 0;
    while (i < size && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n')) i++;
    return i < size && p[i] == '{';
}

mk_result mk_import_memory(const void *data, size_t size, const mk_import_options *options, mk_raw_asset *out,
                           mk_error *err)
{
    if (!out || (!data && size))
        return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "import: invalid argument");
    if (mk_is_blob(data, size)) return import_blob(data, size, options, out, err);
    if (looks_like_gltf(data, size)) return mk_import_gltf(data, size, options, out, err);
    /* FBX: binary files have a magic; ASCII files are text, and the parser refuses text
     * without FBX nodes. Anything else is not a format morphkit reads. */
    const unsigned char *p = data;
    size_t head = size < 1024 ? size : 1024;
    int text = size > 0 && memchr(p, 0, head) == NULL;
    if ((size >= 18 && memcmp(p, "Kaydara FBX Binary", 18) == 0) || text)
        return mk_import_fbx(data, size, options, out, err);
    return mk_error_set(err, MK_ERROR_UNSUPPORTED, 0,
                        "unknown file type: not a .morph blob, glTF (.gltf, .glb) or FBX");
}

/* The file's bytes, given back as soon as the importer is done with them (a lower peak). */
typedef struct file_bytes {
    mk_arena *arena;
    void *data;
} file_bytes;

static void release_file_bytes(void *user)
{
    file_bytes *f = user;
    mk_arena_release(f->arena, f->data);
    f->data = NULL;
}

/* mk_import_file, the file's bytes kept in out->arena (*kept, *kept_size) when kept is set. */
static mk_result import_file(const char *path, const mk_import_options *options, mk_raw_asset *out, const void **kept,
                             size_t *kept_size, mk_error *err)
{
    if (!path || !out) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "import: invalid argument");
    mk_import_options o;
    memset(&o, 0, sizeof o);
    if (options) o = *options;
    mk_arena tmp;
    mk_arena_init(&tmp, &out->arena.allocator);
    void *data;
    size_t size;
    mk_arena *holder = kept ? &out->arena : &tmp;
    mk_result r =
        mk_read_file_threads(holder, path, o.max_input_size ? o.max_input_size : MK_IMPORT_DEFAULT_MAX_INPUT,
                             mk_arena_threads(holder, o.threads), &data, &size, err);
    if (r != MK_OK) {  /* the message names the file */
        mk_arena_free_all(&tmp);
        return r;
    }
    if (o.file_read) o.file_read(o.file_read_user, path);
    mk_phase_log_mark(o.phases, "read file");
    char *dir = NULL;
    if (!o.base_dir) {
        const char *slash = strrchr(path, '/');
        dir = slash ? mk_arena_strndup(&tmp, path, (size_t)(slash - path + 1)) : mk_arena_strdup(&tmp, "./");
        if (!dir) {
            mk_arena_free_all(&tmp);
            return mk_error_oom(err, "import path");
        }
        o.base_dir = dir;
    }
    file_bytes bytes = { &tmp, data };
    if (kept) {
        *kept = data;
        *kept_size = size;
    } else {
        o.input_done = release_file_bytes;
        o.input_done_user = &bytes;
    }
    r = mk_import_memory(data, size, &o, out, err);
    if (r != MK_OK && err && strncmp(err->message, path, strlen(path)) != 0) {
        /* Name the file once, in front, unless the message already starts with it. */
        char msg[sizeof err->message + 512];
        snprintf(msg, sizeof msg, "%.300s: %s", path, err->message);
        memcpy(err->message, msg, sizeof err->message - 1);
        err->message[sizeof err->message - 1] = '\0';
    }
    mk_arena_free_all(&tmp);
    return r;
}

mk_result mk_import_file(const char *path, const mk_import_options *options, mk_raw_asset *out, mk_error *err)
{
    return import_file(path, options, out, NULL, NULL, err);
}

mk_result mk_import_file_keeping(const char *path, const mk_import_options *options, mk_raw_asset *out,
                                 const void **bytes, size_t *size, mk_error *err)
{
    if (!bytes || !size) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "import: invalid argument");
    return import_file(path, options, out, bytes, size, err);
}

mk_result mk_import_load_asset(void *user, const char *path, mk_raw_asset *out, mk_error *err)
{
    (void)user;   /* the bake's user pointer belongs to its other callbacks */
    mk_import_options keep = { .keep_plain_meshes = 1 };
    return mk_import_file(path, &keep, out, err);
}

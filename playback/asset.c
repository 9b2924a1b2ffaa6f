/* SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <string.h>
#include "asset.h"

/* A .morph blob is opened as it is; the first bytes tell. */
static int is_morph(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    char magic[8] = { 0 };
    size_t n = fread(magic, 1, 8, f);
    fclose(f);
    return mk_is_blob(magic, n);
}

mk_result pb_asset_open_raw(pb_asset *out, const mk_write_options *write, mk_error *err)
{
    mk_result r = mk_write_blob(&out->raw, write, &out->raw.arena, &out->blob, &out->blob_size, &out->report, err);
    if (r != MK_OK) return r;
    out->imported = 1;
    return mk_asset_open(out->blob, out->blob_size, &out->asset, err);
}

mk_result pb_asset_load(const char *path, const mk_import_options *import, const mk_write_options *write, pb_asset *out,
                        mk_error *err)
{
    memset(out, 0, sizeof *out);
    mk_raw_init(&out->raw, NULL);
    if (is_morph(path)) {
        mk_result r = mk_read_file(&out->raw.arena, path, 0, &out->blob, &out->blob_size, err);
        return r != MK_OK ? r : mk_asset_open(out->blob, out->blob_size, &out->asset, err);
    }
    mk_result r = mk_import_file(path, import, &out->raw, err);
    return r != MK_OK ? r : pb_asset_open_raw(out, write, err);
}

void pb_asset_free(pb_asset *a)
{
    mk_raw_free(&a->raw);
}

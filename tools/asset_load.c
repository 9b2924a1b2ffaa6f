#include <string.h>
#include "asset_load.h"

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

mk_result load_asset(const char *path, const mk_import_options *import, const mk_write_options *write,
                     loaded_asset *out, mk_error *err)
{
    memset(out, 0, sizeof *out);
    mk_raw_init(&out->raw, NULL);
    mk_result r;
    if (is_morph(path)) {
        r = mk_read_file(&out->raw.arena, path, 0, &out->blob, &out->blob_size, err);
        if (r) return r;
    } else {
        r = cli_load_raw(path, import, &out->raw, err);
        if (r) return r;
        r = mk_write_blob(&out->raw, write, &out->raw.arena, &out->blob, &out->blob_size, &out->report, err);
        if (r) return r;
        out->imported = 1;
    }
    return mk_asset_open(out->blob, out->blob_size, &out->asset, err);
}

void loaded_asset_free(loaded_asset *a) { mk_raw_free(&a->raw); }

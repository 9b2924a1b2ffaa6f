/* SPDX-License-Identifier: MIT */
/* Any input as an opened runtime asset: a .morph blob is opened as it is; any other file is
 * imported and written as a blob in memory first, so everything plays through the runtime. */
#ifndef MK_PB_ASSET_H
#define MK_PB_ASSET_H

#include "blob_io.h"
#include "import.h"

typedef struct pb_asset {
    mk_raw_asset raw; /* owns every allocation (also the blob) */
    mk_asset asset;
    void *blob;
    size_t blob_size;
    mk_write_report report; /* valid when imported (not read from .morph) */
    int imported;
} pb_asset;

/* import and write may be NULL (defaults). out must be freed with pb_asset_free, also on error. */
mk_result pb_asset_load(const char *path, const mk_import_options *import, const mk_write_options *write, pb_asset *out,
                        mk_error *err);
/* Writes an already filled out->raw (mk_raw_init'ed by the caller) and opens it. */
mk_result pb_asset_open_raw(pb_asset *out, const mk_write_options *write, mk_error *err);
void pb_asset_free(pb_asset *a);

#endif

/* Loading any input as an opened runtime asset (importing and writing in memory if needed). */
#ifndef MK_ASSET_LOAD_H
#define MK_ASSET_LOAD_H

#include "cli.h"

typedef struct loaded_asset {
    mk_raw_asset raw;          /* owns every allocation (also the blob) */
    mk_asset asset;
    void *blob;
    size_t blob_size;
    mk_write_report report;    /* valid when imported (not read from .morph) */
    int imported;
} loaded_asset;

/* .morph files are opened as they are; other inputs are imported and written with `write`. */
mk_result load_asset(const char *path, const mk_import_options *import, const mk_write_options *write,
                     loaded_asset *out, mk_error *err);
void loaded_asset_free(loaded_asset *a);

#endif

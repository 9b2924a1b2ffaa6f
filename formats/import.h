/* SPDX-License-Identifier: MIT */
/* Importing any source into the raw model: the one entry shape of every reader (FBX, glTF,
 * .morph). mk_import_memory picks the reader by content; mk_import_file reads the file first,
 * resolves glTF buffers against its folder and names the file in errors. */
#ifndef MK_IMPORT_H
#define MK_IMPORT_H

#include "import_options.h"

/* .morph blob, glTF (JSON or GLB) or FBX (binary or ASCII), told apart by content. out must
 * be mk_raw_init'ed; warnings go to out->warnings. */
mk_result mk_import_memory(const void *data, size_t size, const mk_import_options *options, mk_raw_asset *out,
                           mk_error *err);
mk_result mk_import_file(const char *path, const mk_import_options *options, mk_raw_asset *out, mk_error *err);
/* mk_import_file, and the file's bytes stay in out->arena (*bytes, *size): a write-back puts
 * the bake into the very bytes the import read (the file is read once, so a pipe works and a
 * file changed meanwhile does not matter). */
mk_result mk_import_file_keeping(const char *path, const mk_import_options *options, mk_raw_asset *out,
                                 const void **bytes, size_t *size, mk_error *err);
/* mk_import_file in the shape of mk_bake_options.load_asset (a `transfer` recipe's source), with
 * the default options and every mesh kept, so mesh indices count the file's meshes. user is not
 * read: mk_bake_options.user is shared with the bake's other callbacks (progress, reports). */
mk_result mk_import_load_asset(void *user, const char *path, mk_raw_asset *out, mk_error *err);

#endif

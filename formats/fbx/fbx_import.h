/* SPDX-License-Identifier: MIT */
/* The FBX reader: binary (either byte order) or ASCII FBX, versions 5.x to 7.x, from memory
 * into the raw model. Behaviour and limits: docs/importing-fbx.md. */
#ifndef MK_FBX_IMPORT_H
#define MK_FBX_IMPORT_H

#include "import_options.h"

/* out must be mk_raw_init'ed; warnings go to out->warnings. The same shape as every importer
 * (mk_import_memory in import.h picks one by content). */
mk_result mk_import_fbx(const void *data, size_t size, const mk_import_options *options,
                        mk_raw_asset *out, mk_error *err);

#endif

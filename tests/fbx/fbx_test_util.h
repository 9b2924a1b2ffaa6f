/* SPDX-License-Identifier: MIT */
/* Helpers shared by the FBX tests: evaluate an imported raw model through the public runtime
 * and read positions back per control point in world space. */
#ifndef MK_TESTS_FBX_UTIL_H
#define MK_TESTS_FBX_UTIL_H

#include "blob_io.h"
#include "fbx_import.h"
#include "import.h"

/* Imports `data` (options may be NULL) into raw (initialized here). Returns the result. */
mk_result ft_import(const void *data, size_t size, const mk_import_options *options, mk_raw_asset *raw, mk_error *err);

/* Evaluates mesh `mesh` of raw with clip `clip` sampled at `time` (clip < 0: default weights,
 * or `weights` when non-NULL, one per asset channel) through a float blob and the runtime.
 * Writes control_point_count * 3 floats (world space when `world`, else mesh-local) into
 * out (malloc'ed, caller frees). Returns 0 on success. */
int ft_eval_control_points(const mk_raw_asset *raw, uint32_t mesh, int32_t clip, float time, const float *weights,
                           int world, float **out, uint32_t *control_point_count);

/* The corpus file fbx/NAME.fbx read whole (malloc'ed), or NULL when the corpus is absent. */
unsigned char *ft_read_corpus(const char *name, size_t *size);

/* Mesh index by name, or -1. */
int32_t ft_find_mesh(const mk_raw_asset *raw, const char *name);

#endif

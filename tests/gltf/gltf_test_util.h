/* SPDX-License-Identifier: MIT */
/* Helpers shared by the glTF tests, thin over the playback library: import a file, write it as
 * a float .morph blob, open it with the runtime and evaluate frames through the public jobs, so
 * the tests check the whole path an engine would use; corpus cases are checked by the same
 * conformance code as `morphkit conform`. */
#ifndef GLTF_TEST_UTIL_H
#define GLTF_TEST_UTIL_H

#include <cjson/cJSON.h>
#include "asset.h"
#include "conform.h"
#include "gltf_export.h"
#include "gltf_import.h"
#include "import.h"

typedef pb_asset gt_model;

/* Imports path (with an optional sidecar path) and opens it; 0 on success, else msg says why. */
int gt_load(gt_model *m, const char *path, const char *sidecar, char *msg, size_t msg_size);
/* Writes an already-filled m->raw (float precision) and opens it. */
int gt_open_raw(gt_model *m, char *msg, size_t msg_size);
void gt_free(gt_model *m);

/* Asset-wide channel weights: clip >= 0 samples it at time, else forced weights (glTF target k
 * → channel k of every mesh) when forced != NULL, else the channels' default weights. */
int gt_weights(const gt_model *m, int clip, double time, const double *forced, int forced_count, float *weights);
/* Positions (3/vertex) and, when the mesh has them, normals (3/vertex, may be NULL) of mesh
 * `mesh` for asset-wide weights. */
int gt_eval(const gt_model *m, uint32_t mesh, const float *weights, float *positions, float *normals);
/* Mesh-local → world (the mesh's world matrix). */
void gt_to_world(const gt_model *m, uint32_t mesh, const float *local, uint32_t n, float *world);

/* Checks every frame of one glTF case against its three.js references (CHECKs): positions
 * within the case tolerance, normal directions within 0.006 degrees, sampled weights within
 * 1e-6. With loaded == NULL the case's source is imported; otherwise `loaded` is checked (a
 * re-import). */
void gt_check_case(const pb_manifest *manifest, const pb_case *c, gt_model *loaded, double *worst_pos,
                   double *worst_normal_deg, int *frames_done);

/* Imports glTF JSON text (options may be NULL) into a freshly initialized raw, err cleared
 * first. */
mk_result gt_import_text(const char *json, const mk_import_options *options, mk_raw_asset *raw, mk_error *err);

/* n bytes as base64 (for data: URIs), malloc'ed; NULL when out of memory. */
char *gt_base64(const unsigned char *in, size_t n);

/* cJSON of a whole file (NULL when missing or malformed). */
cJSON *gt_read_json(const char *path);

#endif

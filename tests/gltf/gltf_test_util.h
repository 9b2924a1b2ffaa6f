/* Helpers shared by the glTF tests: import a file, write it as a float .morph blob, open it with
 * the runtime and evaluate frames through the public jobs (mk_sample_run / mk_eval_run), so the
 * tests check the whole path an engine would use. */
#ifndef GLTF_TEST_UTIL_H
#define GLTF_TEST_UTIL_H

#include <cjson/cJSON.h>
#include "blob_io.h"
#include "gltf_export.h"
#include "gltf_import.h"
#include "import.h"
#include "morphkit.h"

typedef struct gt_model {
    mk_raw_asset raw;
    mk_arena arena;      /* blob memory */
    void *blob;
    size_t size;
    mk_asset asset;
} gt_model;

/* Imports path (with an optional sidecar path) and opens it; 0 on success, else msg says why. */
int gt_load(gt_model *m, const char *path, const char *sidecar, char *msg, size_t msg_size);
/* Writes an already-filled m->raw and opens it. */
int gt_open_raw(gt_model *m, char *msg, size_t msg_size);
void gt_free(gt_model *m);

/* Asset-wide channel weights: clip >= 0 samples it at time, else forced weights (glTF target k
 * → channel k of every mesh) when forced != NULL, else the channels' default weights. */
int gt_weights(const gt_model *m, int clip, double time, const double *forced, int forced_count, float *weights);
/* Positions (3/vertex) and, when the mesh has them, unnormalized-free normals (3/vertex, may be
 * NULL) of mesh `mesh` for asset-wide weights. */
int gt_eval(const gt_model *m, uint32_t mesh, const float *weights, float *positions, float *normals);
/* Raw mesh index for glTF (node, mesh, primitive), or -1. */
int gt_find(const gt_model *m, int node, int mesh, int primitive);
/* Mesh-local → world (the mesh's world matrix). */
void gt_to_world(const gt_model *m, uint32_t mesh, const float *local, uint32_t n, float *world);

/* Checks every frame of one cases.json glTF case against its three.js references (CHECKs):
 * positions within the case tolerance, normal directions within 1e-4, sampled weights. With
 * loaded == NULL the case's source is imported; otherwise `loaded` is checked (a re-import). */
void gt_check_case(const char *corpus, const cJSON *c, gt_model *loaded, double *worst_pos, double *worst_nrm,
                   int *frames_done);

/* cJSON of a whole file (NULL when missing or malformed). */
cJSON *gt_read_json(const char *path);

#endif

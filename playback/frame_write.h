/* SPDX-License-Identifier: MIT */
/* One evaluated frame of every mesh of an asset, and its serializations: JSON (the shape of
 * the conformance reference frames), OBJ, and the compact binary frame format (.mkf,
 * docs/conformance.md) that C reads in a few lines. `morphkit play` and `morphkit frames`
 * write them; conform reads JSON, OBJ and .mkf back. */
#ifndef MK_PB_FRAME_WRITE_H
#define MK_PB_FRAME_WRITE_H

#include <stdio.h>
#include "morphkit.h"

typedef struct pb_frame {
    const mk_asset *asset;
    int32_t clip;                 /* the clip sampled, or -1 */
    double time;                  /* its time (seconds) when clip >= 0 */
    mk_stacking stacking;         /* as evaluated (MK_STACKING_ASSET: each mesh's own) */
    mk_normal_mode normal_mode;
    int surface_normals;          /* normals (and tangents) recomputed from the evaluated surface
                                   * (mk_surface_run) where a mesh has triangles and normals */
    int world;                    /* positions and normals in world space (else mesh-local) */
    int skip_tangents;            /* leave tangents out (pictures need none) */
    const struct pb_evaluator *evaluator; /* where meshes are evaluated (frame.h); NULL: the CPU runtime */
    float *weights;               /* asset channel count, the weights played */
    float **positions;            /* per mesh: 3 floats per vertex */
    float **normals;              /* per mesh: 3 per vertex, or NULL where the mesh has none */
    float **tangents;             /* per mesh: 4 per vertex, or NULL */
} pb_frame;

/* Evaluates every mesh for frame->weights (set by the caller) into newly allocated arrays. */
mk_result pb_frame_evaluate(pb_frame *frame, mk_error *err);
void pb_frame_free(pb_frame *frame);

void pb_frame_write_json(FILE *f, const pb_frame *frame, const char *producer);
struct json_writer;
/* Opens a mesh's object in every JSON morphkit writes (frames, `info --json`) with the fields
 * that identify it: name, node, mesh_index, gltf_node/gltf_mesh/gltf_primitive (glTF meshes
 * only), vertices, control_point_count and world; *info receives the mesh's facts. The caller
 * adds its own fields and closes the object. */
void pb_json_mesh_begin(struct json_writer *w, const mk_asset *asset, uint32_t mesh, mk_mesh_info *info);
void pb_frame_write_obj(FILE *f, const pb_frame *frame, const char *producer);
void pb_frame_write_mkf(FILE *f, const pb_frame *frame);

/* The .mkf header (all fields little-endian). */
#define PB_MKF_MAGIC "MKFRAME1"
#define PB_MKF_WORLD 1u      /* header flags: positions and normals in world space */
#define PB_MKF_NORMALS 1u    /* mesh flags: normals follow the positions */
#define PB_MKF_TANGENTS 2u   /* mesh flags: tangents follow */

#endif

/* SPDX-License-Identifier: MIT */
/* The FBX writer: a bake written back into the artist's own FBX file, and a raw asset (a blob)
 * as a new FBX file (docs/baking.md, "Baking into your own file"; docs/importing-fbx.md,
 * "Writing FBX"). */
#ifndef MK_FBX_WRITE_H
#define MK_FBX_WRITE_H

#include "raw.h"

typedef struct mk_fbx_write_report {
    uint32_t meshes;            /* meshes written (export) or that got channels (write-back) */
    uint32_t channels;          /* BlendShapeChannel deformers written */
    uint32_t shapes;            /* Shape geometries written (one per target) */
    uint32_t blend_shapes;      /* BlendShape deformers made (write-back: meshes that had none) */
    uint32_t clips;             /* animation stacks written */
    uint32_t blender_weights;   /* one-target channels written with per-vertex FullWeights (files made by Blender) */
    uint32_t progressive_channels; /* channels written with in-betweens (Blender 3.4 cannot import those) */
} mk_fbx_write_report;

/* `input` is the FBX file (binary little-endian or ASCII, FBX 7.1 or later) that `raw` was
 * imported from (mk_import_memory / mk_import_file, which record each mesh's Geometry id) and
 * then baked into. The output is the input with, for every channel whose `origin` is set (a
 * baked channel), a BlendShapeChannel with one Shape per target (deltas on the geometry's
 * control points), connected to the mesh's BlendShape deformer (the first one it has, else a
 * new one), and, for every clip that animates only baked channels, an animation stack with
 * DeformPercent curves (FBX 7.1: a Shape inside the Geometry per channel, its weight a Geometry
 * property). Binary in gives binary out, ASCII in gives ASCII out; every node of
 * the input is kept, byte for byte apart from the record end offsets that move.
 *
 * Refused with a message naming the element, nothing written: FBX before 7.1, in-betweens in
 * FBX 7.1, big-endian files, a geometry shared by two models, a baked target whose
 * render vertices of one control point moved differently (the file keeps one delta per control
 * point), in-betweens in a file made by Blender, names a file cannot hold. The output lives in
 * `arena`. */
mk_result mk_fbx_write_back(const void *input, size_t input_size, const mk_raw_asset *raw, mk_arena *arena,
                            void **out, size_t *out_size, mk_fbx_write_report *report, mk_error *err);

/* What mk_fbx_write_back refuses about the file itself (not FBX 7.1 or later, big-endian, no
 * Objects or Connections), for a caller to check before it bakes. */
mk_result mk_fbx_write_back_check(const void *input, size_t input_size, mk_error *err);

/* `raw` as a new binary FBX 7.4 file: per mesh a Model (its world transform as translation,
 * XYZ rotation and scale at the root) with a Geometry (control points, triangles, normals by
 * polygon vertex), every channel with its in-betweens and every clip as above. Refused: a
 * transform with shear (an FBX model holds translation, rotation and scale), render vertices of
 * one control point that differ in position or in a target's delta. */
mk_result mk_fbx_export(const mk_raw_asset *raw, mk_arena *arena, void **out, size_t *out_size,
                        mk_fbx_write_report *report, mk_error *err);

#endif

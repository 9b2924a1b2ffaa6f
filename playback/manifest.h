/* SPDX-License-Identifier: MIT */
/* A conformance manifest (docs/conformance.md): cases, each a source file with reference
 * frames made by other software, read and checked field by field. */
#ifndef MK_PB_MANIFEST_H
#define MK_PB_MANIFEST_H

#include "alloc.h"

typedef enum pb_reference_kind {
    PB_REF_UFBX_JSON,     /* meshes[] by FBX node name, positions per control point, world space */
    PB_REF_THREE_JSON,    /* meshes[] by glTF node/mesh/primitive, positions and normals per vertex */
    PB_REF_MORPHKIT_JSON, /* frames written by 'morphkit frames' / 'morphkit play' */
    PB_REF_MORPHKIT_FRAME,/* the binary frame format (.mkf) of 'morphkit frames' */
    PB_REF_OBJ            /* v lines of the one mesh with channels */
} pb_reference_kind;

typedef struct pb_frame_spec {
    int has_time;          /* 0: "time": null, the static state */
    double time;           /* seconds on the clip's time line */
    int32_t clip;          /* glTF animation index named by the frame, or -1 */
    uint32_t forced_count; /* "weights": forced weights in the mesh's channel order */
    double *forced;        /* NULL when the frame forces none */
    const char *file;      /* the reference file, relative to the manifest's folder */
    int weights_from_reference; /* play each mesh with the weights its reference lists (golden frames) */
} pb_frame_spec;

typedef struct pb_case {
    const char *name;
    const char *source; /* relative to the manifest's folder unless absolute */
    int gltf;           /* "format": "gltf" (else "fbx") */
    pb_reference_kind kind;
    int world;                 /* "space": "world" (else "mesh-local") */
    int by_control_point;      /* "match": "control_points" (else "vertices") */
    double tolerance;          /* absolute, in the reference's units (0 when only relative) */
    double relative_tolerance; /* times the reference's size (0: none); a frame passes within
                                * either tolerance */
    int relative_to_largest;   /* the size is the largest |coordinate| (else the bounding-box diagonal) */
    mk_stacking stacking;      /* "stacking" the references were made with (0: each mesh's stored one) */
    mk_normal_mode normal_mode;/* "normals": nlerp (default) or slerp */
    uint32_t frame_count;
    pb_frame_spec *frames;
} pb_case;

typedef struct pb_manifest {
    mk_arena arena;      /* owns everything below */
    char base_dir[4096]; /* folder the manifest's paths are relative to */
    uint32_t case_count;
    pb_case *cases;
} pb_manifest;

/* Reads and checks a manifest; errors name the case, frame and field. Free with
 * pb_manifest_free, also on error. */
mk_result pb_manifest_read(const char *path, pb_manifest *out, mk_error *err);
void pb_manifest_free(pb_manifest *m);
/* base_dir/path, or path when absolute. */
void pb_manifest_path(const pb_manifest *m, const char *path, char *out, size_t size);
/* The file name of a frame's reference (for reports). */
const char *pb_frame_label(const pb_frame_spec *f);

#endif

/* SPDX-License-Identifier: MIT */
/* Conformance: one reference frame against the runtime's playback of the same asset. The
 * rules (which meshes are compared, how they are matched, how tolerances combine) are
 * docs/conformance.md; `morphkit conform` and the corpus tests both run them from here. */
#ifndef MK_PB_CONFORM_H
#define MK_PB_CONFORM_H

#include "asset.h"
#include "manifest.h"

/* One compared mesh, both sides per render vertex in the space compared (for pictures); the
 * arrays live only during the call. */
typedef struct pb_compared_mesh {
    uint32_t mesh;               /* the import's mesh */
    uint32_t vertex_count;
    const float *positions;      /* played: 3 per vertex */
    const float *normals;        /* played: 3 per vertex, or NULL */
    const double *reference;     /* 3 per reference point */
    const double *reference_normals; /* 3 per reference point, or NULL */
    const uint32_t *point;       /* the reference point of each vertex, or NULL: vertex v is point v */
} pb_compared_mesh;

typedef struct pb_conform_options {
    mk_stacking stacking;        /* 0: the case's "stacking" (else each mesh's stored one) */
    mk_normal_mode normal_mode;  /* with normal_mode_given; else the case's "normals" */
    int normal_mode_given;
    double normal_tolerance_deg; /* largest normal angle; 0 means 1 degree */
    double weight_tolerance;     /* largest |weight - reference weight|; 0 means 1e-5 */
    const struct pb_evaluator *evaluator; /* where meshes are evaluated (frame.h); NULL: the CPU runtime */
    void (*mesh_compared)(void *user, const pb_compared_mesh *mesh); /* may be NULL */
    void *user;
} pb_conform_options;

typedef struct pb_frame_result {
    double position_error;   /* largest |coordinate - reference| over the compared meshes */
    double allowed;          /* the absolute allowance: case tolerance + quantization + float32 rounding */
    double relative_allowed; /* relative_tolerance x size + quantization + rounding (0: none) */
    double reference_size;   /* the size the relative tolerance refers to */
    double normal_error_deg; /* largest angle to the reference's normals */
    double weight_error;     /* largest |sampled weight - reference weight| */
    int normals_compared, weights_compared, meshes_compared;
    int worst_known;         /* worst_mesh / worst_vertex hold the largest position error */
    uint32_t worst_mesh, worst_vertex;
    int passed;
    const char *passed_by; /* "tolerance", "relative_tolerance" or NULL */
    char failure[512];     /* why the frame could not be compared (empty when it was) */
} pb_frame_result;

/* Checks frame f of case c (of manifest m) against asset a (the case's source, loaded with
 * the precision under test). The result says what was compared and whether it passed. */
void pb_conform_frame(const pb_manifest *m, const pb_case *c, const pb_frame_spec *f, const pb_asset *a,
                      const pb_conform_options *options, pb_frame_result *result);

/* The weights a frame plays with: the static state (channel defaults) for "time": null or
 * forced weights, else the frame's clip (the first for FBX) at its time. */
mk_result pb_conform_weights(const pb_case *c, const pb_frame_spec *f, const mk_asset *a, float *weights,
                             mk_error *err);

#endif

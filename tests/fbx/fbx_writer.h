/* SPDX-License-Identifier: MIT */
/* Test-only FBX writer: binary (7100..7700 record layout, optional zlib arrays) and ASCII 7.x
 * files with meshes, blend shape channels with in-betweens, DeformPercent curves and an
 * animation stack. Tests build their fixtures with it, round-trip them through mk_import_fbx,
 * seed the fuzzer with them, and the import benchmark writes its large file with it.
 *
 * It writes what Maya's FBX SDK writes for these objects (Objects + Connections, 7.x syntax);
 * it is not a general FBX exporter.
 */
#ifndef MK_TESTS_FBX_WRITER_H
#define MK_TESTS_FBX_WRITER_H

#include <stddef.h>
#include <stdint.h>

typedef struct fbxw_shape {
    const char *name;
    uint32_t count;               /* sparse entries */
    const int32_t *indexes;       /* control points (may be unsorted / out of range on purpose) */
    const double *deltas;         /* 3 per entry */
    const double *normals;        /* 3 per entry or NULL (no Normals array) */
    uint32_t short_deltas;        /* write this many fewer delta triples than entries (a broken shape) */
} fbxw_shape;

typedef struct fbxw_curve {
    uint32_t key_count;
    const int64_t *times;         /* KTime */
    const float *values;          /* percent */
    const int32_t *flags;         /* one per key (written run-length encoded) */
    const float *data;            /* 4 per key: right slope, next-left slope, packed weights bits, 0 */
} fbxw_curve;

typedef struct fbxw_channel {
    const char *name;
    double deform_percent;
    int deform_as_field_only;     /* Blender/ZBrush style: no Properties70 DeformPercent */
    uint32_t shape_count;
    const fbxw_shape *shapes;     /* in connection order */
    uint32_t full_weight_count;   /* FullWeights entries written (may differ from shape_count) */
    const double *full_weights;   /* percent */
    const fbxw_curve *curve;      /* NULL: not animated */
} fbxw_channel;

typedef struct fbxw_mesh {
    const char *name;
    uint32_t control_point_count;
    const double *control_points; /* 3 each */
    uint32_t polygon_vertex_count;
    const int32_t *polygon_vertex_index; /* last of each polygon as ~index */
    const double *normals;        /* ByPolygonVertex, 3 per polygon vertex, or NULL */
    const double *uvs;            /* ByPolygonVertex, 2 per polygon vertex, or NULL */
    /* Model transform properties (Properties70). Lcl Translation/Rotation/Scaling,
     * PreRotation, RotationPivot, GeometricTranslation, RotationOrder and InheritType are always
     * written; the others only when not at their default (zero, or one for the scalings), so
     * fixtures that leave them alone also cover the importer's defaults. */
    double translation[3], rotation[3], scaling[3];  /* scaling 0,0,0 means 1,1,1 */
    double pre_rotation[3], post_rotation[3];
    double rotation_offset[3], rotation_pivot[3];
    double scaling_offset[3], scaling_pivot[3];
    double geometric_translation[3], geometric_rotation[3];
    double geometric_scaling[3];  /* 0,0,0 means 1,1,1 (not written) */
    int rotation_order;           /* 0 XYZ .. 5 ZYX (6 spheric), written as is */
    int ignore_parent_scale;      /* writes InheritType 2 (Rrs) instead of 1 (RSrs) */
    int inherit_type;             /* 0: as ignore_parent_scale says; FBXW_INHERIT(n) writes InheritType n */
    uint32_t channel_count;
    const fbxw_channel *channels;
    int parent;                   /* index of the parent mesh's model, or -1 */
} fbxw_mesh;

typedef struct fbxw_scene {
    uint32_t version;             /* 7100..7700; selects 13- or 25-byte records in binary */
    int binary;
    int compress;                 /* binary: 1 zlib-compresses arrays of more than 64 elements, 2 every non-empty array */
    int big_endian;               /* binary: header byte 22 = 1, every counter, scalar and array element big-endian */
    /* binary: use every property type where the importer reads the value (UpAxis 'Y', Creator
     * 'R', Lcl Scaling 'F', Shading 'C', normals/UVs/FullWeights 'f', shape Indexes 'l') and
     * add a top-level "MorphkitTypes" node with every scalar type (Y C B Z I L F D S R) and
     * every array type (f d l i b c, raw and zlib), which the importer ignores. */
    int type_mix;
    const char *creator;          /* NULL: "morphkit test writer" */
    int64_t stack_start, stack_stop; /* KTime of the single AnimationStack (written if any curve) */
    uint32_t mesh_count;
    const fbxw_mesh *meshes;
} fbxw_scene;

/* Writes the scene into malloc'ed memory (*data, *size). Returns 0 on success. */
int fbxw_write(const fbxw_scene *scene, unsigned char **data, size_t *size);
/* Same, streamed to a file (for files larger than memory should hold twice). */
int fbxw_write_file(const fbxw_scene *scene, const char *path);

#define FBXW_KTIME_PER_SECOND 46186158000LL
/* fbxw_mesh.inherit_type for InheritType n (0 RrSs, 1 RSrs, 2 Rrs, or any other value). */
#define FBXW_INHERIT(n) ((n) + 1)

#endif

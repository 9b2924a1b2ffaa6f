/* SPDX-License-Identifier: MIT */
/* morphkit runtime: open a .morph blob in place, sample weight clips, evaluate morphs.
 *
 * C11, libc only, never allocates, no global state. Every function is thread-safe for
 * concurrent calls on the same opened asset as long as their output spans do not overlap.
 *
 * Usage (see docs/embedding.md and samples/embed_minimal.c):
 *   mk_asset asset; mk_error err;
 *   if (mk_asset_open(blob, blob_size, &asset, &err) != MK_OK) { puts(err.message); ... }
 *   mk_sample_job s = { .asset = &asset, .clip = 0, .time = t, .weights = w, .weight_count = n };
 *   mk_sample_run(&s, &err);
 *   mk_eval_job e = { .asset = &asset, .mesh = 0, .weights = w + first_channel_of_mesh, ... };
 *   mk_eval_run(&e, &err);
 *
 * The blob must stay alive and unmodified while the asset is used: mk_asset only points
 * into it. The blob must be 16-byte aligned (mmap and malloc both give that).
 */
#ifndef MORPHKIT_H
#define MORPHKIT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The library's version (meson.build reads the same numbers from VERSION; a test fails when they
 * differ). Minor versions add API; the blob format has its own number, MK_FORMAT_VERSION:
 * blobs are readable by every runtime of the same format version (docs/embedding.md). */
#define MK_VERSION_MAJOR 0
#define MK_VERSION_MINOR 2
#define MK_VERSION_PATCH 0
#define MK_VERSION ((MK_VERSION_MAJOR * 10000) + (MK_VERSION_MINOR * 100) + MK_VERSION_PATCH)
#define MK_VERSION_STRING "0.2.0"

/* The version of the blob format this runtime reads and the tools write. */
#define MK_FORMAT_VERSION 5u

/* Consecutive key points of a channel (its full weights and the implicit 0) are at least this
 * far apart, so span parameters stay finite (docs/semantics.md). */
#define MK_MIN_FULL_WEIGHT_GAP 1e-6f

/* Result codes. Each comment says what fixes it. */
typedef enum mk_result {
    MK_OK = 0,
    MK_ERROR_INVALID_ARGUMENT,  /* a NULL pointer or zero size where one is required: pass valid arguments */
    MK_ERROR_TRUNCATED,         /* the blob ends before a structure it declares: pass the whole file */
    MK_ERROR_BAD_MAGIC,         /* not a .morph blob: check the file you pass */
    MK_ERROR_BAD_VERSION,       /* written by a newer/older morphkit: re-export with this version's tools */
    MK_ERROR_BAD_CHECKSUM,      /* bytes changed after writing: the file is corrupt, re-export it */
    MK_ERROR_BAD_ALIGNMENT,     /* the blob or one of its arrays is not 16-byte aligned: load it into aligned memory */
    MK_ERROR_CORRUPT,           /* an offset, count, index or value is out of range: the file is corrupt or hostile */
    MK_ERROR_OUT_OF_RANGE,      /* a job index (mesh, clip, channel, vertex range) exceeds the asset: fix the job */
    MK_ERROR_BUFFER_TOO_SMALL,  /* an output or scratch span is smaller than the job needs: size it with the queries */
    MK_ERROR_NOT_FINITE,        /* a NaN or infinite input (weight, time): pass finite values */
    MK_ERROR_UNSUPPORTED,       /* the job asks for data the asset does not have (e.g. tangents): drop that output */
    MK_ERROR_IO,                /* offline only: reading or writing a file failed: check the path and disk */
    MK_ERROR_OUT_OF_MEMORY,     /* offline only: the allocator refused: raise the memory limit */
    MK_ERROR_PARSE,             /* offline only: an input file (FBX, glTF, JSON) is malformed: see the message */
    MK_ERROR_LIMIT,             /* offline only: input exceeds a configured limit (size, nesting, count) */
    MK_RESULT_COUNT
} mk_result;

/* Errors are data: a code, a message naming what and where, and the element it concerns. */
typedef struct mk_error {
    mk_result code;
    uint64_t offset;      /* byte offset in the input where it went wrong, or UINT64_MAX */
    char message[256];
} mk_error;

const char *mk_result_name(mk_result code);

/* MK_VERSION of the compiled library: compare with the header's to catch a mismatched build. */
uint32_t mk_version(void);

/* Channel stacking on a mesh (docs/semantics.md). */
typedef enum mk_stacking {
    MK_STACKING_ASSET = 0,      /* in a job: use the mesh's setting stored in the blob */
    MK_STACKING_ADDITIVE = 1,   /* P = B + sum_c D_c(w_c) */
    MK_STACKING_SEQUENTIAL = 2  /* d_c = (1 - beta_c) d_{c-1} + D_c(w_c) */
} mk_stacking;

typedef enum mk_normal_mode {
    MK_NORMALS_NLERP = 0,       /* normalize(B_n + sum of weighted normal deltas) */
    MK_NORMALS_SLERP = 1        /* per channel, slerp between its span's end normals */
} mk_normal_mode;

/* Interpolation of the curve segment that starts at a key. */
typedef enum mk_interp {
    MK_INTERP_CONSTANT = 0,      /* hold this key's value until the next key */
    MK_INTERP_CONSTANT_NEXT = 1, /* take the next key's value right after this key (FBX constant-next) */
    MK_INTERP_LINEAR = 2,        /* straight line to the next key */
    MK_INTERP_CUBIC = 3,         /* cubic Bezier in (time, value) from the slopes and weights (Hermite when both weights are 1/3) */
    MK_INTERP_COUNT
} mk_interp;

/* One key of a weight curve. A segment k -> k+1 uses key k's right tangent and key k+1's
 * left tangent. Slopes are d(weight)/d(second); weights are fractions of the key interval
 * (1/3 gives a plain Hermite cubic; FBX weighted tangents set other values). */
typedef struct mk_key {
    float time;          /* seconds */
    float value;         /* normalized weight (1.0 = 100 %) */
    float right_slope;
    float right_weight;
    float left_slope;
    float left_weight;
    uint32_t interp;     /* mk_interp of the segment starting here */
    uint32_t reserved;   /* zero */
} mk_key;

/* An opened asset: pointers into the blob, filled by mk_asset_open. Treat as opaque; use the
 * query functions below. */
typedef struct mk_asset {
    const uint8_t *data;
    size_t size;
    const struct mk_blob_header *header;
    const struct mk_blob_mesh *meshes;
    const struct mk_blob_channel *channels;
    const struct mk_blob_target *targets;
    const struct mk_blob_clip *clips;
    const struct mk_blob_track *tracks;
    const mk_key *keys;
    const char *strings;
    uint64_t strings_size;
    uint32_t mesh_count, channel_count, target_count, clip_count, track_count;
    uint32_t key_count;
} mk_asset;

/* Does data start like a .morph blob (its magic)? A cheap test before mk_asset_open. */
int mk_is_blob(const void *data, size_t size);

/* Validates the whole blob once (offsets, counts, indices, alignment, sorted data, finite
 * floats, strictly increasing full weights, checksum, version). After MK_OK the asset is safe
 * to use with any job; no hot path checks again. On failure *out is zeroed and err (optional)
 * says what and where. */
mk_result mk_asset_open(const void *data, size_t size, mk_asset *out, mk_error *err);

/* ---- Queries (valid indices required; out-of-range indices return 0/NULL) ---- */

typedef struct mk_mesh_info {
    const char *name;             /* source node name (FBX model name, glTF node name) */
    uint32_t vertex_count;        /* render vertices */
    uint32_t control_point_count; /* source control points (FBX) or vertices (glTF) */
    uint32_t triangle_count;
    uint32_t first_channel;       /* index of the mesh's first channel in the asset */
    uint32_t channel_count;
    uint32_t target_count;        /* targets of all the mesh's channels */
    uint64_t target_bytes;        /* bytes of the mesh's block data (entry headers + deltas) */
    uint64_t entry_count;         /* block entries: (target, 64-vertex block) pairs with data */
    mk_stacking stacking;         /* stored stacking: additive or sequential */
    int has_normals, has_tangents;
    int32_t gltf_node, gltf_mesh, gltf_primitive; /* -1 when not from glTF */
    const float *world;           /* 4x4 column-major node world transform at rest */
    const float *positions;       /* base positions, 3 floats per vertex */
    const float *normals;         /* base normals, 3 floats per vertex, or NULL */
    const float *tangents;        /* base tangents, 4 floats per vertex (w = handedness), or NULL */
    const uint32_t *triangles;    /* 3 vertex indices per triangle */
    const uint32_t *control_points; /* per render vertex: its source control point */
} mk_mesh_info;

typedef struct mk_channel_info {
    const char *name;
    const char *origin;           /* "" for imported channels; baked ones hold their recipe (JSON) */
    uint32_t mesh;
    uint32_t target_count;        /* > 1: progressive (in-between) channel */
    float default_weight;         /* weight when no clip animates the channel */
} mk_channel_info;

typedef struct mk_target_info {
    const char *name;
    float full_weight;            /* normalized (FBX FullWeights / 100) */
    uint32_t channel;
    uint32_t moved_vertices;      /* vertices with stored data */
    int quantized;                /* packed at the mesh's steps (outlier blocks float32), else float32 */
    int has_normals, has_tangents;
    float position_scale;         /* quantization step of positions (0 for float) */
} mk_target_info;

typedef struct mk_clip_info {
    const char *name;
    float start, duration;        /* seconds */
    uint32_t track_count;
} mk_clip_info;

int mk_mesh_get(const mk_asset *asset, uint32_t mesh, mk_mesh_info *out);
/* Block entries of the mesh's quantized targets stored as float32 (outlier blocks whose values
 * span more than 16 bits at the import tolerance's step); 0 for an invalid mesh. Counted by reading
 * every entry header of the mesh: for tools, not for a frame loop. */
uint64_t mk_mesh_float_entries(const mk_asset *asset, uint32_t mesh);
/* Packed block entries of the mesh whose position offsets are int32 (deltas beyond 32,767
 * steps that spread narrowly); 0 for an invalid mesh. Counted like mk_mesh_float_entries. */
uint64_t mk_mesh_wide_entries(const mk_asset *asset, uint32_t mesh);
int mk_channel_get(const mk_asset *asset, uint32_t channel, mk_channel_info *out);
/* Targets of a channel are numbered 0..target_count-1 in increasing full weight. */
int mk_target_get(const mk_asset *asset, uint32_t channel, uint32_t target, mk_target_info *out);
int mk_clip_get(const mk_asset *asset, uint32_t clip, mk_clip_info *out);
/* Track k of a clip: which channel it animates and its keys. */
int mk_track_get(const mk_asset *asset, uint32_t clip, uint32_t track, uint32_t *channel,
                 const mk_key **keys, uint32_t *key_count);
/* Index of the first mesh/channel/clip with that name (in asset order), or -1. Names need not
 * be unique: a glTF mesh's weights belong to the whole mesh, so each of its primitives (one
 * morphkit mesh each, same node) has a channel of the same name, and all of them must get the
 * same weight; different nodes may also reuse names. Use mk_find_channels to get them all. */
int32_t mk_find_mesh(const mk_asset *asset, const char *name);
int32_t mk_find_channel(const mk_asset *asset, const char *name);
int32_t mk_find_clip(const mk_asset *asset, const char *name);
/* Every channel named `name`, in asset order: writes the first `capacity` indices to out (may
 * be NULL with capacity 0) and returns how many there are. */
uint32_t mk_find_channels(const mk_asset *asset, const char *name, uint32_t *out, uint32_t capacity);

/* ---- Evaluation job ---- */

/* Weights in, positions (+ normals, + tangents) out. Output pointers address vertex
 * `first_vertex` (not vertex 0), so a job system can hand each thread its own range and
 * buffer slice. A NULL output is skipped. */
/* How an evaluation writes its outputs. Streaming (non-temporal) stores send whole 64-vertex
 * blocks of packed (stride 12), 16-byte aligned position/normal outputs past the caches: no
 * read-for-ownership, nothing useful evicted. Right for outputs larger than the caches and for
 * GPU upload buffers; wrong when the caller reads the outputs right away from cache (CPU
 * skinning of a small mesh). Only x86 (SSE2) builds stream; elsewhere every mode stores
 * normally. The values written are identical in every mode. */
typedef enum mk_store_mode {
    MK_STORE_AUTO = 0,            /* streaming when the mesh's outputs (all its vertices, the
                                   * attributes the job writes) take at least MK_STREAM_MIN_BYTES */
    MK_STORE_CACHED = 1,          /* ordinary stores */
    MK_STORE_STREAMING = 2        /* streaming wherever the output layout allows it */
} mk_store_mode;
#define MK_STREAM_MIN_BYTES ((size_t)8 << 20)

/* mk_eval_job.vertex_count for "from first_vertex to the end of the mesh". */
#define MK_VERTICES_TO_END UINT32_MAX

typedef struct mk_eval_job {
    const mk_asset *asset;
    uint32_t mesh;
    uint32_t first_vertex;        /* vertex range [first_vertex, first_vertex + vertex_count) */
    uint32_t vertex_count;        /* vertices to evaluate (0: none); MK_VERTICES_TO_END: the rest of the mesh */
    const float *weights;         /* one per channel of the mesh (mesh-local channel order) */
    uint32_t weight_count;        /* must equal the mesh's channel count */
    mk_stacking stacking;         /* MK_STACKING_ASSET (0) uses the blob's per-mesh setting */
    mk_normal_mode normal_mode;   /* default nlerp */
    void *scratch;                /* caller memory of mk_eval_scratch_size() bytes, 16-byte aligned */
    size_t scratch_size;
    float *positions;             /* output, required */
    size_t positions_stride;      /* bytes between vertices; 0 means 12 */
    size_t positions_size;        /* bytes available at positions */
    float *normals;               /* optional output: 3 floats per vertex */
    size_t normals_stride, normals_size;
    float *tangents;              /* optional output: 4 floats per vertex (w copied from base) */
    size_t tangents_stride, tangents_size;
    mk_store_mode store_mode;     /* default MK_STORE_AUTO */
} mk_eval_job;

/* Scratch bytes an evaluation of this mesh needs (0 for an invalid mesh). */
size_t mk_eval_scratch_size(const mk_asset *asset, uint32_t mesh);
mk_result mk_eval_validate(const mk_eval_job *job, mk_error *err);
mk_result mk_eval_run(const mk_eval_job *job, mk_error *err);
/* Bytes a valid job must move through memory for its weights: the block table and entry
 * headers of its vertex range, the data of active targets (only the attributes it outputs),
 * the base arrays it reads and the outputs it writes. 0 for an invalid or empty job. For
 * budgeting memory bandwidth; it uses the job's scratch. */
uint64_t mk_eval_traffic(const mk_eval_job *job);

/* ---- GPU plan ---- */

/* What a GPU needs from one frame's weights to evaluate one mesh (docs/gpu.md): per target its
 * displacement coefficient (in-between span factor times the sequential suffix product, 0 when
 * inactive), per target the channel whose normals slerp (or -1), and per channel its span (two
 * targets, the position in the span, the sequential factor). The same numbers the CPU
 * evaluation computes first, in the layout the compute shader reads; the blob itself is
 * uploaded once and never changes. Its cost grows with the mesh's targets and channels, not its
 * vertices. Weights are checked as mk_eval_validate checks them (a NaN weight is refused). */
typedef struct mk_gpu_plan_job {
    const mk_asset *asset;
    uint32_t mesh;
    const float *weights;         /* one per channel of the mesh (mesh-local channel order) */
    uint32_t weight_count;        /* must equal the mesh's channel count */
    mk_stacking stacking;         /* MK_STACKING_ASSET (0) uses the blob's per-mesh setting */
    mk_normal_mode normal_mode;   /* default nlerp */
    void *plan;                   /* output: mk_gpu_plan_size() bytes, 16-byte aligned (mapped GPU memory is fine) */
    size_t plan_size;
} mk_gpu_plan_job;

/* Bytes of a mesh's plan (0 for an invalid mesh): 8 per target and 16 per channel, rounded. */
size_t mk_gpu_plan_size(const mk_asset *asset, uint32_t mesh);
mk_result mk_gpu_plan_run(const mk_gpu_plan_job *job, mk_error *err);

/* ---- Surface normals ---- */

/* Normals of the evaluated surface (docs/semantics.md, "Surface normals"): for every vertex
 * whose N(P) differs from N(P0), n = normalize(B + N(P) - N(P0)), N the normalized sum of the
 * vertex's smoothing group's area-weighted face normals at the evaluated positions P and at
 * rest P0, B the stored base normal; every other vertex (among them all whose group's
 * triangles did not move) keeps B as stored. The exact counterpart of nlerp/slerp where shapes
 * combine, at the cost of one pass over the triangles and one over the vertices. Smoothing groups are the importer's: vertices with the same control
 * point and the same base normal (within 1e-5 per component), so UV seams stay smooth and hard
 * edges hard.
 *
 * Two steps an engine runs per frame: evaluate the positions of the whole mesh (mk_eval_run,
 * any split into ranges), then this job over any ranges, reading those positions (a vertex's
 * normal needs the positions around it). It allocates nothing: the mesh's topology is built
 * once into caller memory (mk_surface_topology_size bytes, 16-byte aligned) by
 * mk_surface_topology_build, and read-only afterwards (share it between threads). Every
 * vertex's result is the same whichever range computes it. */

/* Smoothing groups by the rule above, for any vertex data (the offline tools group target
 * normals and deformed surfaces with it): vertices with the same key (keys[v] < key_count, e.g.
 * the control point) and the same normal within 1e-5 per component (normals NULL: the same key
 * is enough) share a group. Groups are numbered in key order, then vertex order; returns the
 * count and fills group_of (one per vertex). scratch: mk_smoothing_groups_scratch_size bytes,
 * 4-byte aligned. Allocates nothing. */
size_t mk_smoothing_groups_scratch_size(uint32_t key_count, uint32_t vertex_count);
uint32_t mk_smoothing_groups(const uint32_t *keys, uint32_t key_count, const float *normals, uint32_t vertex_count,
                             uint32_t *group_of, void *scratch);

/* Bytes of a mesh's surface topology; 0 when the mesh has no normals or no triangles, has more
 * than 1,431,655,765 triangles or 1,073,741,823 vertices, or the mesh index is invalid. */
size_t mk_surface_topology_size(const mk_asset *asset, uint32_t mesh);
mk_result mk_surface_topology_build(const mk_asset *asset, uint32_t mesh, void *topology, size_t size, mk_error *err);

typedef struct mk_surface_job {
    const mk_asset *asset;
    uint32_t mesh;
    const void *topology;         /* built by mk_surface_topology_build for this mesh */
    size_t topology_size;
    const float *positions;       /* evaluated positions of the whole mesh, from vertex 0 */
    size_t positions_stride;      /* bytes between vertices; 0 means 12 */
    size_t positions_size;        /* bytes available at positions */
    uint32_t first_vertex;        /* output range, as in mk_eval_job */
    uint32_t vertex_count;        /* 0: none; MK_VERTICES_TO_END: the rest of the mesh */
    float *normals;               /* output (addresses first_vertex): 3 floats per vertex */
    size_t normals_stride, normals_size;
    float *tangents;              /* optional output: the base tangent, re-orthogonalized against
                                   * the output normal where N(P) differs from N(P0), w copied
                                   * from the base */
    size_t tangents_stride, tangents_size;
    void *scratch;                /* mk_surface_scratch_size() bytes, 16-byte aligned, one per
                                   * thread (no initialization needed) */
    size_t scratch_size;
} mk_surface_job;

/* Scratch bytes of a surface job on this mesh (0 when it has no topology). */
size_t mk_surface_scratch_size(const mk_asset *asset, uint32_t mesh);

mk_result mk_surface_validate(const mk_surface_job *job, mk_error *err);
mk_result mk_surface_run(const mk_surface_job *job, mk_error *err);

/* ---- Clip sampling job ---- */

/* Time in, one weight per asset channel out. Channels the clip does not animate get their
 * default weight. `cursors` (optional, one uint32 per track of the clip, zero-initialized by
 * the caller once) remembers the last key per track so forward playback finds keys in O(1). */
typedef struct mk_sample_job {
    const mk_asset *asset;
    uint32_t clip;
    double time;                  /* seconds on the clip's time line (keys are absolute times); double so
                                   * long-running clocks and times just before a key stay exact */
    int loop;                     /* nonzero: wrap time into [start, start + duration) */
    float *weights;               /* output: one per asset channel */
    uint32_t weight_count;        /* must be >= the asset's channel count */
    uint32_t *cursors;            /* optional: track_count entries */
    uint32_t cursor_count;
} mk_sample_job;

mk_result mk_sample_validate(const mk_sample_job *job, mk_error *err);
mk_result mk_sample_run(const mk_sample_job *job, mk_error *err);

/* Evaluates one curve at time t (clamped to the first/last key). Exposed for tools and tests. */
float mk_curve_eval(const mk_key *keys, uint32_t key_count, double time, uint32_t *cursor);

/* The channel displacement coefficients (docs/semantics.md) for one channel at weight w: the two
 * targets (indices into the channel's sorted targets, -1 for the implicit zero key) and their
 * factors, so D(w) = ca * delta[ia] + cb * delta[ib]. Exposed for tools and tests. */
void mk_channel_span(const float *full_weights, uint32_t count, float w,
                     int32_t *ia, float *ca, int32_t *ib, float *cb, float *t);

#ifdef __cplusplus
}
#endif
#endif

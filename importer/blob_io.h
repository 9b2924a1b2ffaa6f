/* raw model <-> .morph blob, and file helpers for offline tools. */
#ifndef MK_BLOB_IO_H
#define MK_BLOB_IO_H

#include "raw.h"

typedef enum mk_precision {
    MK_PRECISION_Q16 = 0,      /* default: int16 per component with a per-target scale */
    MK_PRECISION_FLOAT = 1     /* lossless float32 */
} mk_precision;

typedef struct mk_write_options {
    mk_precision precision;
    /* Largest allowed absolute position error of quantization, in mesh units; a target whose
     * int16 error would exceed it is stored as float32. 0 = 1e-4 x the mesh's bounding-box
     * diagonal (a relative default that works for cm and m assets alike). */
    float tolerance;
    /* Blocks of 64 vertices whose moved-vertex count is at least this are stored dense (all 64
     * vertices); 0 = 24. */
    uint32_t dense_threshold;
} mk_write_options;

typedef struct mk_write_report {
    double max_position_error;  /* largest |stored - exact| component over all targets */
    double max_normal_error;    /* the same for normal and tangent deltas: not bounded by the */
    double max_tangent_error;   /* tolerance; int16 of a unit-vector difference errs < 3.1e-5 */
    double tolerance_used;      /* the largest per-mesh tolerance that was applied */
    uint32_t quantized_targets, float_targets;
    uint64_t target_bytes;      /* bytes of block data (entries + deltas) */
    uint64_t total_bytes;
} mk_write_report;

/* Validates raw, then writes the blob into memory from `arena` (deterministic: the same raw
 * model and options give byte-identical output). report may be NULL. */
mk_result mk_write_blob(const mk_raw_asset *raw, const mk_write_options *options, mk_arena *arena,
                        void **blob, size_t *size, mk_write_report *report, mk_error *err);

/* Reads an opened blob back into a raw model (dequantized). out must be mk_raw_init'ed. */
mk_result mk_read_blob(const mk_asset *asset, mk_raw_asset *out, mk_error *err);

/* Whole file into arena memory (16-byte aligned, NUL appended past size). */
mk_result mk_read_file(mk_arena *arena, const char *path, size_t max_size, void **data,
                       size_t *size, mk_error *err);
/* Does path end with extension (lower case, with the dot), ignoring the path's case? */
int mk_path_has_extension(const char *path, const char *extension);
/* Writes to "<path>.tmp.<pid>" then renames over path: readers never see half a file. */
mk_result mk_write_file_atomic(const char *path, const void *data, size_t size, mk_error *err);

#endif

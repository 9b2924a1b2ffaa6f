/* SPDX-License-Identifier: MIT */
/* raw model <-> .morph blob, and file helpers for offline tools. */
#ifndef MK_BLOB_IO_H
#define MK_BLOB_IO_H

#include "phase_log.h"
#include "raw.h"

typedef enum mk_precision {
    MK_PRECISION_Q16 = 0,      /* default: packed integers at a step the tolerance sets (format v5) */
    MK_PRECISION_FLOAT = 1     /* lossless float32 */
} mk_precision;

/* The default largest error of a stored normal or tangent delta component (unit vectors: 1e-3
 * moves a normal by at most 0.1 degree per target). */
#define MK_DEFAULT_NORMAL_TOLERANCE 1e-3

typedef struct mk_write_options {
    mk_precision precision;
    /* Largest allowed absolute position error of quantization, in mesh units: the positions'
     * step is the largest whose bound (half a step, plus 2^-8 of one for float32 evaluation)
     * stays within it. A block whose values span more than 16 bits at that step, or lie beyond
     * 2^23 steps, is stored as float32. 0 = 1e-4 x the mesh's bounding-box diagonal (a
     * relative default that works for cm and m assets alike). */
    float tolerance;
    /* The same for normal and tangent deltas; 0 = MK_DEFAULT_NORMAL_TOLERANCE. */
    float normal_tolerance;
    /* The entry mask rule (mk_block_mask, block_mask.h) with gap = gap_limit - 1: gaps of at
     * most `gap` vertices without a nonzero stored value between ones with it are stored as
     * zeros, and a block that still lacks at most 3 x gap is stored whole. 1 stores exactly the
     * vertices with a nonzero value, 65 every touched block whole (larger values count as 65);
     * 0 = the default (MK_DEFAULT_FILL_GAP + 1). */
    uint32_t gap_limit;
    /* Phases of the write (quantize, lay out blocks, assemble); may be NULL. */
    mk_phase_log *phases;
    /* Threads for quantizing and laying out targets; 0 = one per core. The blob is the same
     * for any count (nothing is allocated on the worker threads). */
    uint32_t threads;
    /* Called (when set) as parts of the blob become final, while the rest is still computed:
     * bytes [offset, offset + size) of the blob at `blob` will not change again (each target's
     * block data, on the worker threads or the caller's, in any order; each byte at most once; the header and
     * tables are never reported). Lets a caller write them out early (output_stream.h). */
    void (*ready)(void *user, const void *blob, uint64_t offset, uint64_t size);
    void *ready_user;
} mk_write_options;

typedef struct mk_write_report {
    double max_position_error;  /* largest |stored - exact| component over all targets */
    double max_normal_error;    /* the same for normal and tangent deltas (within the */
    double max_tangent_error;   /* normal tolerance) */
    double tolerance_used;      /* the largest per-mesh tolerance that was applied */
    uint32_t quantized_targets, float_targets;
    uint64_t float_entries;     /* entries of quantized targets stored as float32 (outliers) */
    uint64_t wide_entries;      /* packed entries with int32 position offsets */
    uint64_t entry_count;       /* all block entries */
    uint64_t target_bytes;      /* bytes of block data (entries + deltas) */
    uint64_t total_bytes;
} mk_write_report;

/* Validates raw, then writes the blob into memory from `arena` (deterministic: the same raw
 * model and options give byte-identical output). report may be NULL. */
mk_result mk_write_blob(const mk_raw_asset *raw, const mk_write_options *options, mk_arena *arena,
                        void **blob, size_t *size, mk_write_report *report, mk_error *err);
/* mk_write_blob for a model that is written once (morphkit import): the blob comes from raw's
 * own arena and each target's arrays go back to it as soon as its data is in the blob, so the
 * targets and the blob are never both whole in memory. Every target array must be a block of
 * raw's arena of its own, as the importers make them. Afterwards (after a failure too) targets
 * may be left without data (count 0, NULL arrays): write the model once, then free it. Names,
 * weights, channels, meshes and clips stay. The blob is the same as mk_write_blob's. */
mk_result mk_write_blob_consuming(mk_raw_asset *raw, const mk_write_options *options, void **blob, size_t *size,
                                  mk_write_report *report, mk_error *err);

/* Reads an opened blob back into a raw model (dequantized). out must be mk_raw_init'ed. */
mk_result mk_read_blob(const mk_asset *asset, mk_raw_asset *out, mk_error *err);

/* Whole file into arena memory (16-byte aligned, NUL appended past size). Pipes and devices
 * are read to their end. A directory or an empty file is an error saying so. */
mk_result mk_read_file(mk_arena *arena, const char *path, size_t max_size, void **data,
                       size_t *size, mk_error *err);
/* The same, a regular file of 8 MB or more read in parts by up to `threads` threads (0: one per
 * core; mk_parallel_threads). */
mk_result mk_read_file_threads(mk_arena *arena, const char *path, size_t max_size, uint32_t threads, void **data,
                               size_t *size, mk_error *err);
/* Does path end with extension (lower case, with the dot), ignoring the path's case? */
int mk_path_has_extension(const char *path, const char *extension);
/* The folder of path into out: "." for a bare name, "/" for "/name". */
void mk_path_dir(const char *path, char *out, size_t size);

/* ---- Outputs ----
 * An output is checked before anything is read or computed (mk_output_check), then written
 * with the others of the same command (mk_write_outputs):
 *   - a regular file, new or existing, is replaced atomically: a temporary file beside it,
 *     flushed, renamed over it (an existing file keeps its permission bits);
 *   - a symbolic link is followed to the file it names (also a dangling one), which is
 *     replaced as above: the link stays a link;
 *   - a device or FIFO is opened and written directly (no rename);
 *   - a directory or a socket is an error, as is a missing or unwritable folder;
 *   - an output that is the same file (device and inode) as an input is refused.
 * Several outputs are all or nothing: if one fails, none is left changed. */
typedef enum mk_output_kind {
    MK_OUTPUT_NEW_FILE = 0,
    MK_OUTPUT_REPLACE_FILE,
    MK_OUTPUT_STREAM               /* device or FIFO: written in place */
} mk_output_kind;

typedef struct mk_output {
    const char *path;              /* as the user gave it */
    const void *data;              /* set before mk_write_outputs */
    size_t size;
    /* Filled by mk_output_check. */
    mk_output_kind kind;
    uint32_t mode;                 /* permission bits of a replaced file */
    char target[4096];             /* path with symbolic links followed: the file written */
    char temp[4200], backup[4200]; /* used while writing */
    /* Set by mk_output_open_early: the temporary file is open (fd) before the bytes are known,
     * and the bytes [written_from, written_to) of data are in it already (written while they
     * were computed, from the same bytes `data` then points at; output_stream.h);
     * mk_write_outputs writes the rest and closes it. */
    int early, fd;
    uint64_t written_from, written_to;
    int early_errno;               /* flushing the early bytes failed: the write fails with this */
} mk_output;

/* Decides how out->path will be written and refuses it early (see above). inputs (may be
 * NULL entries) are the files the command reads. */
mk_result mk_output_check(mk_output *out, const char *const *inputs, uint32_t input_count, mk_error *err);
/* For a checked output that is a file (new or replaced): creates its temporary file now, so
 * its bytes can be written as they become final (output_stream.h). MK_OK without doing
 * anything for a stream output (a device or FIFO is written whole at the end). Afterwards
 * either mk_write_outputs writes the rest and renames it into place, or mk_output_discard
 * removes it. */
mk_result mk_output_open_early(mk_output *out, mk_error *err);
/* Closes and removes an early output's temporary file (after a failure before
 * mk_write_outputs); nothing for other outputs. */
void mk_output_discard(mk_output *out);
/* Installs handlers for SIGINT, SIGTERM and SIGHUP (those not ignored) that remove the
 * temporary and backup files of outputs being written, then end the process by the signal as
 * before: an interrupted command leaves no files beside its outputs. For programs that write
 * outputs (the morphkit command calls it first thing). */
void mk_output_cleanup_on_signals(void);
/* Writes checked outputs, all or none. */
mk_result mk_write_outputs(mk_output *outputs, uint32_t count, mk_error *err);
/* mk_output_check (no inputs) + mk_write_outputs for one file. */
mk_result mk_write_file(const char *path, const void *data, size_t size, mk_error *err);

#endif

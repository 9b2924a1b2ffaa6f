/* SPDX-License-Identifier: MIT */
/* Bakers: offline deformers that add channels to a raw model .
 *
 * Every baker turns a deformation of one mesh into an ordinary channel: one or more targets
 * (in-betweens with full weights in (0, 1], the last one at 1), so the runtime plays a baked
 * channel like an authored shape. The recipe format is documented in docs/baking.md; the
 * per-algorithm C APIs are in barr.h, ffd.h, ffd_travel.h, ffd_cylinder.h, cage_mvc.h,
 * surface_edit.h, transfer.h and inbetween.h.
 */
#ifndef MK_BAKE_H
#define MK_BAKE_H

#include "raw.h"

typedef struct mk_bake_report {
    uint32_t channels_added;
    uint32_t targets_added;
    double max_error;          /* achieved playback error, fraction of the bbox diagonal */
} mk_bake_report;

/* What one baked channel came out as (passed to mk_bake_options.channel_done). */
typedef struct mk_bake_channel_report {
    const char *name;          /* channel name */
    const char *op;            /* "twist", "ffd", ... */
    uint32_t mesh;
    uint32_t targets;          /* targets written (in-betweens + the last one at weight 1) */
    uint32_t evaluations;      /* deformations evaluated while placing in-betweens */
    double max_error;          /* playback error, fraction of the mesh's bbox diagonal */
    int error_measured_on_grid;/* 1: max over every sampled weight; 0: estimated at span midpoints */
    uint32_t moved_vertices;   /* vertices moved by the last target */
    uint32_t inverted_vertices;/* FFD/Barr: vertices where det J <= 0 (normals from the surface) */
    /* The playback error at every sampled weight k / curve_samples (k = 0..curve_samples,
     * fraction of the diagonal) when measured on the grid, the targets' full weights and the
     * tolerance aimed at (0 for a fixed count); the arrays live in the raw asset's arena. */
    const double *error_curve;
    uint32_t curve_samples;
    const float *key_weights;
    double tolerance;
    uint32_t factorizations;   /* Laplacian/ARAP/transfer: sparse Cholesky factorizations (1 expected) */
    double factor_seconds;     /* Laplacian/ARAP/transfer: analyze + factorize wall time */
    double solve_seconds;      /* Laplacian/ARAP/transfer: total time of all triangular solves */
    uint32_t solves;           /* Laplacian/ARAP/transfer: solves (each one with 3 right-hand sides) */
    uint32_t iterations;       /* ARAP: local/global iterations over all evaluations */
    uint32_t max_iterations;   /* ARAP: most iterations one evaluation took */
    uint32_t unconverged;      /* ARAP: evaluations stopped by the iteration cap */
    double energy;             /* ARAP: energy of the last evaluation (amplitude 1 unless the
                                * in-between search evaluated later weights last) */
    double start_energy;       /* ARAP: energy of that evaluation's initial guess */
    double seconds;            /* whole channel, wall time */
    /* shell: the enclosed volume over the rest volume at frames 0..volume_frames - 1 (frame 0 is
     * the rest state), frame_seconds apart, and the chosen frames' indices (key_frames, one per
     * target); the arrays live in the raw asset's arena. NULL / 0 for other ops. */
    const double *volume_ratios;
    uint32_t volume_frames;
    double frame_seconds;
    const uint32_t *key_frames;
    /* transfer, reported with the first channel of a recipe entry: the correspondence used
     * ("closest" or "iterative"; NULL otherwise) and, iterative, how far the fitted source's
     * vertices lie from the target (mean, max; fraction of the target's diagonal). */
    const char *correspondence;
    double fit_mean, fit_max;
} mk_bake_channel_report;

typedef struct mk_bake_options {
    /* Directory that relative paths in the recipe (cage OBJ files) resolve against; NULL or ""
     * means the current directory. `morphkit bake` passes the recipe file's directory. */
    const char *base_dir;
    /* progress(user, stage, fraction in [0,1]); may be NULL. */
    void (*progress)(void *user, const char *stage, double fraction);
    /* Called once per baked channel; may be NULL. */
    void (*channel_done)(void *user, const mk_bake_channel_report *channel);
    void *user;
    /* Nonzero for recipes from untrusted sources (fuzzing, services): cage OBJ paths and
     * transfer sources are refused and work is capped (samples <= 200, lattice dims <= 8,
     * ARAP iterations <= 50, in-betweens <= 32, lattice keys <= 32), so a hostile recipe
     * cannot read files or run for hours. */
    int untrusted;
    /* Called with the path of every file the recipe makes the bake read (cage OBJ files,
     * transfer sources), e.g. for a build system's depfile; may be NULL. */
    void (*file_read)(void *user, const char *path);
    /* Reads the asset at path (a `transfer` op's source: .fbx, .gltf/.glb, .morph, whatever the
     * caller can import) into out, which the baker has initialized with mk_raw_init and frees
     * with mk_raw_free. The baker itself reads no file format: `morphkit bake` passes
     * mk_import_load_asset (formats/import.h), tests may hand over models built in memory. NULL: `transfer`
     * ops fail with an error naming the field. */
    mk_result (*load_asset)(void *user, const char *path, mk_raw_asset *out, mk_error *err);
    /* Threads for the parts of a bake that run in parallel (the `shell` simulation's sweeps and collision tests);
     * 0 = one per core. The result is the same for any count. */
    uint32_t threads;
} mk_bake_options;

/* Applies a JSON recipe (docs/baking.md) to raw. options may be NULL (defaults). All or
 * nothing: on error raw keeps its channels as they were and err names the field. */
mk_result mk_bake_recipe(mk_raw_asset *raw, const char *recipe_json, size_t recipe_size,
                         const mk_bake_options *options, mk_bake_report *report, mk_error *err);

#endif

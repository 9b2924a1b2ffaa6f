/* SPDX-License-Identifier: MIT */
/* Options every importer takes (FBX, glTF, .morph), checked and applied in one place. Zero
 * means the default for every field. */
#ifndef MK_IMPORT_OPTIONS_H
#define MK_IMPORT_OPTIONS_H

#include "phase_log.h"
#include "raw.h"

/* The targets' normal deltas: the file's own (the default; FBX also computes them where the
 * file has none), or none at all: for playback that never blends normals (positions only, or
 * normals recomputed from the evaluated surface). With none, FBX shape normals are neither
 * decoded nor computed, other inputs' are dropped after reading; tangent deltas stay. */
typedef enum mk_target_normals {
    MK_TARGET_NORMALS_AUTO = 0,
    MK_TARGET_NORMALS_NONE = 1
} mk_target_normals;

typedef struct mk_import_options {
    mk_stacking stacking;          /* stacking stored for every mesh; 0 = additive (.morph: as stored) */
    mk_target_normals target_normals; /* 0 = the file's, computed where missing */
    int keep_shape_normals;        /* FBX: 0 = use shape normals only when present and non-zero */
    int keep_plain_meshes;         /* 0 = meshes without morph targets are dropped, each named in a
                                    * warning; 1 = kept (bakers start from them) */
    size_t max_input_size;         /* bytes; 0 = 4 GiB */
    const char *base_dir;          /* glTF: folder external buffer URIs resolve against (with or
                                    * without a trailing '/'); NULL refuses external buffers.
                                    * mk_import_file sets it to the file's folder. */
    const char *channels_sidecar;  /* glTF: path of a sidecar JSON grouping targets into channels */
    const char *channels_sidecar_text; /* ... or its text (channels_sidecar_size bytes) */
    size_t channels_sidecar_size;
    /* Called with the path of every file the import reads (the source, the sidecar, glTF
     * external buffers), e.g. for a build system's depfile; may be NULL. */
    void (*file_read)(void *user, const char *path);
    void *file_read_user;
    /* Where the import's time and memory go, phase by phase (read, parse, meshes, shapes,
     * target normals, animation, validate); may be NULL. The caller starts the log. */
    mk_phase_log *phases;
    /* Threads for the parts of an import that run in parallel (FBX shapes, target normals); 0 =
     * one per core. The result is the same for any count. With more than one, the raw asset's
     * allocator is called from several threads (the default one, malloc, may be). */
    uint32_t threads;
    /* Called at most once, when the importer will not read the input bytes again (FBX: before
     * computing target normals), so a caller that owns them can free them early; may be NULL
     * (glTF and .morph inputs never call it). mk_import_file sets its own. */
    void (*input_done)(void *user);
    void *input_done_user;
} mk_import_options;

#define MK_IMPORT_DEFAULT_MAX_INPUT ((size_t)4 << 30)

/* Checks the options and the input size against the limit; every importer calls it first. */
mk_result mk_import_options_check(const mk_import_options *options, size_t input_size, const char *format,
                                  mk_error *err);
/* Applies what every format shares to a freshly imported model (stacking, plain meshes), then
 * sorts targets, groups channels by mesh and validates it; every importer calls it last. */
mk_result mk_import_finish(mk_raw_asset *raw, const mk_import_options *options, mk_error *err);

#endif

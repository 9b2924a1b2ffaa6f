/* SPDX-License-Identifier: MIT */
/* morphkit import: any source file into a .morph blob. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "output_stream.h"
#include "cli.h"

typedef struct import_args {
    const char *input, *output, *channels, *depfile;
    int stacking, precision, stacking_given, quiet, all_meshes, timings, target_normals;
    double tolerance, normal_tolerance;
    uint64_t threads;
} import_args;

static int run_import(void *p);

static const cli_option options[] = {
    { "-o", "OUT.morph", CLI_STRING, offsetof(import_args, output),
      "The blob to write (a path ending in .morph, or a device/FIFO).", NULL, NULL, 0, 0, 1, 0 },
    { "--stacking", "MODE", CLI_CHOICE, offsetof(import_args, stacking),
      "Channel stacking stored for every mesh (docs/semantics.md). Default: additive; for a .morph input, the stored "
      "one (which this option replaces).",
      NULL, "additive|sequential", 0, 0, 0, offsetof(import_args, stacking_given) },
    { "--precision", "P", CLI_CHOICE, offsetof(import_args, precision),
      "How deltas are stored: q16 (quantized: integers at the step --tolerance sets for positions and "
      "--normal-tolerance for normals and tangents, each 64-vertex block packed at the bits its range needs, up to "
      "16; a block that needs more is stored as float32) or float (lossless float32).",
      "q16", "q16|float", 0, 0, 0, 0 },
    { "--target-normals", "HOW", CLI_CHOICE, offsetof(import_args, target_normals),
      "The targets' normal deltas: auto (the file's own; FBX also computes them where the file has none) or none "
      "(not stored: for playback that never blends normals, i.e. positions only or surface normals recomputed from "
      "the evaluated positions; the blob is smaller and positions evaluate faster). Base normals and tangent deltas "
      "are kept.",
      "auto", "auto|none", 0, 0, 0, 0 },
    { "--tolerance", "D", CLI_NUMBER, offsetof(import_args, tolerance),
      "Largest quantization error of a position, in mesh units (q16). "
      "Default: 1e-4 x each mesh's bounding-box diagonal.",
      NULL, NULL, 1e-30, 1e30, 0, 0 },
    { "--normal-tolerance", "D", CLI_NUMBER, offsetof(import_args, normal_tolerance),
      "Largest quantization error of a normal or tangent delta component (q16; unit vectors, so 1e-3 turns a normal "
      "by at most about 0.06 degree per target). Default: 1e-3.",
      NULL, NULL, 1e-30, 1e30, 0, 0 },
    { "--channels", "SIDECAR.json", CLI_STRING, offsetof(import_args, channels),
      "glTF input only: a channel sidecar (written by 'morphkit export') that groups targets into progressive "
      "channels.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--all-meshes", NULL, CLI_FLAG, offsetof(import_args, all_meshes),
      "Also keep meshes without morph targets (by default only meshes with targets are imported).", NULL, NULL, 0, 0, 0,
      0 },
    { "--timings", NULL, CLI_FLAG, offsetof(import_args, timings),
      "Print where the import's time and memory went, phase by phase, to standard error: each phase's seconds, "
      "share of the total and the process's peak memory when it ended (read file, parse, meshes, shapes, target "
      "normals, quantize, lay out blocks, write file, ...), then the total.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--threads", "N", CLI_UINT, offsetof(import_args, threads),
      "Threads for the parts of an import that run in parallel (FBX mesh arrays and shapes, target normals, "
      "quantization, block layout); 0 = one per core. The blob is the same for any count.",
      "0", NULL, 0, 64, 0, 0 },
    { "--depfile", "PATH", CLI_STRING, offsetof(import_args, depfile),
      "Also write a depfile for build systems (make syntax, as ninja and meson read it): the blob and every file the "
      "import read (the source, the sidecar, glTF buffers).",
      NULL, NULL, 0, 0, 0, 0 },
    { "--quiet", NULL, CLI_FLAG, offsetof(import_args, quiet), "No progress lines (results are still printed).", NULL,
      NULL, 0, 0, 0, 0 },
};

const cli_verb cli_verb_import = {
    .name = "import",
    .usage = "FILE -o OUT.morph [options]",
    .summary = "convert an FBX or glTF file into a .morph blob",
    .description =
        "Imports FILE (.fbx binary or ASCII, .gltf, .glb, or a .morph blob to re-encode) with every mesh's blend shape "
        "channels, in-between targets, target normals and weight clips, and writes it as a validated .morph blob.",
    .positional = "FILE",
    .positional_help = "The source: .fbx, .gltf, .glb or .morph.",
    .positional_offset = offsetof(import_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(import_args),
    .run = run_import,
};

static int run_import(void *p)
{
    import_args *a = p;
    const cli_verb *verb = &cli_verb_import;
    int is_gltf = mk_path_has_extension(a->input, ".gltf") || mk_path_has_extension(a->input, ".glb");
    if (a->channels && !is_gltf)
        return cli_usage_error(verb, "--channels: channel sidecars apply to glTF input only (%s is not .gltf or .glb)",
                               a->input);
    const char *inputs[] = { a->input, a->channels };
    static const char *const extensions[] = { ".morph", NULL };
    cli_output outs[2];
    int status = cli_output_check(verb, &outs[0], "-o", a->output, extensions, "a .morph blob", 0, inputs, 2);
    if (status >= 0) return status;
    if (a->depfile && (status = cli_output_check(verb, &outs[1], "--depfile", a->depfile, NULL, "a depfile", 0, inputs, 2)) >= 0)
        return status;
    cli_depfile deps = { 0 };

    mk_phase_log phases;
    mk_phase_log_start(&phases);
    mk_import_options io = { .phases = a->timings ? &phases : NULL, .channels_sidecar = a->channels, .keep_plain_meshes = a->all_meshes,
                             .threads = (uint32_t)a->threads,
                             .target_normals = a->target_normals ? MK_TARGET_NORMALS_NONE : MK_TARGET_NORMALS_AUTO,
                             .file_read = a->depfile ? cli_depfile_add : NULL, .file_read_user = &deps };
    if (a->stacking_given) io.stacking = a->stacking ? MK_STACKING_SEQUENTIAL : MK_STACKING_ADDITIVE;
    mk_write_options wo = { .precision = a->precision ? MK_PRECISION_FLOAT : MK_PRECISION_Q16,
                            .tolerance = (float)a->tolerance, .normal_tolerance = (float)a->normal_tolerance,
                            .phases = io.phases,
                            .threads = (uint32_t)a->threads };
    /* Progress only for inputs big enough to take a while. */
    struct stat st;
    cli_progress progress;
    cli_progress_init(&progress, a->quiet || stat(a->input, &st) != 0 || st.st_size < ((off_t)16 << 20));
    cli_progress_update(&progress, "importing", -1);
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    mk_error err;
    mk_result r = mk_import_file(a->input, &io, &raw, &err);
    cli_print_warnings(&raw);
    void *blob = NULL;
    size_t size = 0;
    mk_write_report report;
    cli_progress_update(&progress, "writing the blob", -1);
    /* The blob's block data goes to the output file while the rest is still computed. */
    mk_output_stream *early = NULL;
    if (r == MK_OK && (r = mk_output_open_early(&outs[0].file, &err)) == MK_OK) {
        early = mk_output_stream_start(&outs[0].file);
        wo.ready = early ? mk_output_stream_ready : NULL;
        wo.ready_user = early;
    }
    /* The targets are only written once: the writer gives their memory back as it goes. */
    if (r == MK_OK) r = mk_write_blob_consuming(&raw, &wo, &blob, &size, &report, &err);
    mk_output_stream_finish(early);   /* before the blob's memory can go */
    if (r != MK_OK) {
        mk_output_discard(&outs[0].file);
        mk_raw_free(&raw);
        cli_depfile_free(&deps);
        return cli_fail(verb->name, &err);
    }
    outs[0].file.data = blob;
    outs[0].file.size = size;
    char *dep_text = NULL;
    if (a->depfile) {
        dep_text = cli_depfile_text(&deps, a->output, &outs[1].file.size);
        outs[1].file.data = dep_text;
        if (!dep_text) { mk_output_discard(&outs[0].file); mk_raw_free(&raw); cli_depfile_free(&deps); fprintf(stderr, "morphkit import: out of memory\n"); return CLI_EXIT_FAILURE; }
    }
    status = cli_write_outputs(verb, outs, a->depfile ? 2 : 1);
    free(dep_text);
    mk_phase_log_mark(io.phases, "write file");
    if (status == 0) {
        uint32_t targets = 0;
        for (uint32_t c = 0; c < raw.channel_count; c++) targets += raw.channels[c].target_count;
        printf("%s -> %s: %u meshes, %u channels, %u targets, %u clips, %zu bytes, %u warning%s\n", a->input, a->output,
               raw.mesh_count, raw.channel_count, targets, raw.clip_count, size, raw.warning_count,
               raw.warning_count == 1 ? "" : "s");
        cli_print_write_report(&report);
    }
    mk_raw_free(&raw);
    mk_phase_log_mark(io.phases, "release");
    if (status == 0 && io.phases) mk_phase_log_print(io.phases, stderr);
    return status;
}

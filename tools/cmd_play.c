/* SPDX-License-Identifier: MIT */
/* morphkit play: one frame through the runtime, written as JSON shaped like the conformance
 * reference frames (meshes[] with name, positions, normals) or as OBJ. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "asset.h"
#include "cli.h"
#include "frame.h"
#include "frame_plan.h"
#include "frame_write.h"
#include "gpu_eval.h"
#include "weights_arg.h"

typedef struct play_args {
    const char *input, *output, *clip, *weights;
    double time;
    int time_given, stacking, stacking_given, normals, space, format, format_given, gpu;
} play_args;

static int run_play(void *p);

static const cli_option options[] = {
    { "-o", "OUT", CLI_STRING, offsetof(play_args, output),
      "Where to write the frame: a .json or .obj file, a device/FIFO, or - for standard output.", NULL, NULL, 0, 0, 1,
      0 },
    { "--format", "F", CLI_CHOICE, offsetof(play_args, format),
      "Output format. Default: obj when -o ends in .obj, else json.", NULL, "json|obj", 0, 0, 0,
      offsetof(play_args, format_given) },
    { "--clip", "NAME|INDEX", CLI_STRING, offsetof(play_args, clip),
      "The clip to sample. Default: the first clip when --time is given, else none (the default weights).", NULL, NULL,
      0, 0, 0, 0 },
    { "--time", "T", CLI_NUMBER, offsetof(play_args, time), "Sampling time in seconds on the clip's time line.", NULL,
      NULL, -1e9, 1e9, 0, offsetof(play_args, time_given) },
    { "--weights", "NAME=V,...", CLI_STRING, offsetof(play_args, weights),
      "Channel weights (1 = 100 %) set after the clip is sampled, by channel name, NODE/CHANNEL or index. A name sets "
      "that channel on every primitive of its node.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--stacking", "MODE", CLI_CHOICE, offsetof(play_args, stacking),
      "Channel stacking. Default: each mesh's stored stacking.", NULL, "additive|sequential", 0, 0, 0,
      offsetof(play_args, stacking_given) },
    { "--normals", "MODE", CLI_CHOICE, offsetof(play_args, normals),
      "How normal changes combine (docs/semantics.md); surface: recomputed from the evaluated surface.",
      "nlerp", "nlerp|slerp|surface", 0, 0, 0, 0 },
    { "--gpu", NULL, CLI_FLAG, offsetof(play_args, gpu), CLI_GPU_OPTION_HELP " Surface normals are then computed on the CPU from the GPU's positions.", NULL, NULL, 0, 0, 0, 0 },
    { "--space", "S", CLI_CHOICE, offsetof(play_args, space),
      "Coordinates of the output: world (each mesh's node transform at rest applied) or local (mesh space).", "world",
      "world|local", 0, 0, 0, 0 },
};

const cli_verb cli_verb_play = {
    .name = "play",
    .usage = "FILE -o OUT [options]",
    .summary = "evaluate one frame and write it as JSON or OBJ",
    .description =
        "Evaluates one frame of FILE through the runtime (a clip at a time, or the default weights, then any "
        "--weights) and "
        "writes every mesh's positions and normals: JSON shaped like the conformance reference frames, or OBJ.",
    .positional = "FILE",
    .positional_help = "A .morph blob, or any file 'morphkit import' reads.",
    .positional_offset = offsetof(play_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(play_args),
    .run = run_play,
};

static int run_play(void *p)
{
    play_args *args = p;
    const cli_verb *verb = &cli_verb_play;
    static const char *const extensions[] = { ".json", ".obj", NULL };
    cli_output out;
    const char *inputs[] = { args->input };
    int status = cli_output_check(verb, &out, "-o", args->output, extensions, "a frame as JSON or OBJ", 1, inputs, 1);
    if (status >= 0) return status;
    int obj = args->format_given ? args->format == 1 : mk_path_has_extension(args->output, ".obj");
    if (args->format_given && !out.to_stdout && out.file.kind != MK_OUTPUT_STREAM &&
        !mk_path_has_extension(args->output, obj ? ".obj" : ".json"))
        return cli_usage_error(verb, "-o %s: --format %s needs a name ending in %s", args->output, obj ? "obj" : "json",
                               obj ? ".obj" : ".json");
    const char *space = args->space ? "local" : "world";
    mk_stacking stacking = !args->stacking_given ? MK_STACKING_ASSET
                           : args->stacking      ? MK_STACKING_SEQUENTIAL
                                                 : MK_STACKING_ADDITIVE;
    mk_normal_mode nmode = args->normals == 1 ? MK_NORMALS_SLERP : MK_NORMALS_NLERP;

    pb_asset l;
    mk_error err;
    if (pb_asset_load(args->input, NULL, NULL, &l, &err)) {
        pb_asset_free(&l);
        return cli_fail(verb->name, &err);
    }
    const mk_asset *a = &l.asset;
    int32_t clip = -1;
    if (args->clip) {
        clip = cli_find_clip(verb, a, args->clip);
        if (clip < 0) {
            pb_asset_free(&l);
            return CLI_EXIT_USAGE;
        }
    } else if (args->time_given) {
        if (!a->clip_count) {
            pb_asset_free(&l);
            return cli_usage_error(verb, "--time: %s has no clip to sample", args->input);
        }
        clip = 0;
    }
    char *text = NULL, why[1024];
    size_t text_size = 0;
    cli_gpu *gpu = NULL;
    pb_evaluator evaluator;
    pb_frame frame = { .asset = a, .clip = clip, .time = args->time, .stacking = stacking, .normal_mode = nmode,
                       .surface_normals = args->normals == 2, .world = !args->space };
    frame.weights = calloc(a->channel_count + 1u, sizeof(float));
    if (!frame.weights) { fprintf(stderr, "morphkit play: out of memory\n"); status = 1; goto done; }
    if (pb_frame_weights(a, clip, args->time, frame.weights, &err)) { status = cli_fail(verb->name, &err); goto done; }
    if (args->weights && weights_arg_apply(a, args->weights, frame.weights, why, sizeof why) != 0) {
        status = cli_usage_error(verb, "--weights: %s", why);
        goto done;
    }
    if (args->gpu) {
        if (cli_gpu_open(&gpu, &evaluator, 0, &err) != MK_OK) { status = cli_fail(verb->name, &err); goto done; }
        frame.evaluator = &evaluator;
    }
    if (pb_frame_evaluate(&frame, &err) != MK_OK) { status = cli_fail(verb->name, &err); goto done; }
    FILE *f = open_memstream(&text, &text_size);
    if (!f) { fprintf(stderr, "morphkit play: out of memory\n"); status = 1; goto done; }
    if (obj) pb_frame_write_obj(f, &frame, "morphkit play");
    else pb_frame_write_json(f, &frame, "morphkit play");
    fclose(f);
    out.file.data = text;
    out.file.size = text_size;
    status = cli_write_outputs(verb, &out, 1);
    if (status) goto done;
    /* What was played; on stderr when the frame itself went to standard output. */
    FILE *report = out.to_stdout ? stderr : stdout;
    if (clip >= 0) {
        mk_clip_info ci;
        mk_clip_get(a, (uint32_t)clip, &ci);
        fprintf(report, "%s: clip '%s' at %g s%s", args->input, ci.name, args->time, args->weights ? ", then --weights" : "");
    } else {
        fprintf(report, "%s: %s", args->input, args->weights ? "default weights, then --weights" : "default weights (no clip)");
    }
    fprintf(report, "; %u mesh%s (%s space, %s) written to %s\n", a->mesh_count, a->mesh_count == 1 ? "" : "es", space,
            obj ? "OBJ" : "JSON", out.to_stdout ? "standard output" : args->output);
    for (uint32_t c = 0; c < a->channel_count; c++) {
        mk_channel_info ch;
        mk_channel_get(a, c, &ch);
        fprintf(report, "  %-32s %8.4f\n", ch.name, (double)frame.weights[c]);
    }
done:
    if (cli_gpu_close(gpu) && !status) status = CLI_EXIT_FAILURE;
    free(text);
    pb_frame_free(&frame);
    free(frame.weights);
    pb_asset_free(&l);
    return status;
}

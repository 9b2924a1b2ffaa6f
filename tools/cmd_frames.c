/* SPDX-License-Identifier: MIT */
/* morphkit frames: golden frames for another implementation (an engine's port, a GPU shader,
 * another language) to be checked against: the blob, a conformance manifest, and every frame
 * as JSON and as the binary frame format (docs/conformance.md). */
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "asset.h"
#include "cli.h"
#include "frame.h"
#include "frame_plan.h"
#include "frame_write.h"
#include "gpu_eval.h"
#include "json_write.h"

typedef struct frames_args {
    const char *input, *output, *clip, *times, *weights;
    uint64_t frames;
    int stacking, stacking_given, normals, space, precision, gpu;
} frames_args;

static int run_frames(void *p);

static const cli_option options[] = {
    { "-o", "DIR", CLI_STRING, offsetof(frames_args, output),
      "The folder to write: asset.morph, manifest.json, frames.list and frame_NNN.json / frame_NNN.mkf per frame "
      "(created if absent).",
      NULL, NULL, 0, 0, 1, 0 },
    { "--clip", "NAME|INDEX", CLI_STRING, offsetof(frames_args, clip), "The clip whose times are sampled. Default: the first.",
      NULL, NULL, 0, 0, 0, 0 },
    { "--frames", "N", CLI_UINT, offsetof(frames_args, frames),
      "Frames at evenly spaced times over the clip, both ends included (ignored with --times or --weights).", "10", NULL, 1,
      10000, 0, 0 },
    { "--times", "T,...", CLI_STRING, offsetof(frames_args, times), "Frames at these times (seconds) instead.", NULL, NULL,
      0, 0, 0, 0 },
    { "--weights", "SET;SET...", CLI_STRING, offsetof(frames_args, weights),
      "Frames at forced weights instead of a clip: sets separated by ';', each NAME=V,... as for 'morphkit play' "
      "(channels not named keep their defaults).",
      NULL, NULL, 0, 0, 0, 0 },
    { "--stacking", "MODE", CLI_CHOICE, offsetof(frames_args, stacking),
      "Channel stacking. Default: each mesh's stored stacking.", NULL, "additive|sequential", 0, 0, 0,
      offsetof(frames_args, stacking_given) },
    { "--normals", "MODE", CLI_CHOICE, offsetof(frames_args, normals), "How normal changes combine.", "nlerp",
      "nlerp|slerp", 0, 0, 0, 0 },
    { "--gpu", NULL, CLI_FLAG, offsetof(frames_args, gpu), CLI_GPU_OPTION_HELP, NULL, NULL, 0, 0, 0, 0 },
    { "--space", "S", CLI_CHOICE, offsetof(frames_args, space), "Coordinates of the frames.", "local", "local|world", 0, 0,
      0, 0 },
    { "--precision", "P", CLI_CHOICE, offsetof(frames_args, precision),
      "How a source that is not a .morph blob is written to asset.morph.", "q16", "q16|float", 0, 0, 0, 0 },
};

const cli_verb cli_verb_frames = {
    .name = "frames",
    .usage = "FILE -o DIR [options]",
    .summary = "write golden frames that another implementation is checked against",
    .description = "Plays FILE through the runtime and writes DIR: the blob that was played (asset.morph), a conformance "
                   "manifest (manifest.json) with one case per frame format, and each frame as JSON (frame_NNN.json) "
                   "and in the binary frame format (frame_NNN.mkf, listed in frames.list), with the weights played, "
                   "positions, normals and tangents of every mesh. 'morphkit conform DIR/manifest.json' passes on "
                   "them; samples/golden_check.c shows an engine checking its runtime against them.",
    .positional = "FILE",
    .positional_help = "A .morph blob, or any file 'morphkit import' reads.",
    .positional_offset = offsetof(frames_args, input),
    .positional_required = 1,
    .options = options,
    .option_count = sizeof options / sizeof options[0],
    .args_size = sizeof(frames_args),
    .run = run_frames,
};

static int write_text(cli_output *out, const cli_verb *verb, const char *dir, const char *name, const char *const *inputs,
                      char **text, size_t *size, FILE **f)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    memset(out, 0, sizeof *out);
    char *copy = strdup(path);
    if (!copy) return CLI_EXIT_FAILURE;
    int status = cli_output_check(verb, out, "-o", copy, NULL, name, 0, inputs, 1);
    if (status >= 0) { free(copy); return status; }
    *f = open_memstream(text, size);
    return *f ? -1 : CLI_EXIT_FAILURE;
}

static int run_frames(void *p)
{
    frames_args *args = p;
    const cli_verb *verb = &cli_verb_frames;
    struct stat st;
    if (stat(args->output, &st) == 0 && !S_ISDIR(st.st_mode))
        return cli_usage_error(verb, "-o %s: exists and is not a folder", args->output);
    if (stat(args->output, &st) != 0 && mkdir(args->output, 0777) != 0) {
        fprintf(stderr, "morphkit frames: %s: cannot create the folder: %s\n", args->output, strerror(errno));
        return CLI_EXIT_FAILURE;
    }
    pb_asset l;
    mk_error err;
    mk_write_options wo = { .precision = args->precision ? MK_PRECISION_FLOAT : MK_PRECISION_Q16 };
    if (pb_asset_load(args->input, NULL, &wo, &l, &err)) {
        pb_asset_free(&l);
        return cli_fail(verb->name, &err);
    }
    const mk_asset *a = &l.asset;
    cli_frame_plan fp;
    cli_gpu *gpu = NULL;
    pb_evaluator evaluator;
    int status = cli_frame_plan_make(verb, a, args->input, args->clip, args->times, args->weights,
                                     (uint32_t)args->frames, &fp);
    if (status >= 0) goto done;
    if (args->gpu && cli_gpu_open(&gpu, &evaluator, 0, &err) != MK_OK) {
        status = cli_fail(verb->name, &err);
        goto done;
    }
    status = CLI_EXIT_FAILURE;
    const cli_frame *plans = fp.frames;
    const uint32_t plan_count = fp.count;
    const int32_t clip = fp.clip;

    /* Every output in one all-or-nothing set: the blob, the manifest, the list, 2 per frame. */
    uint32_t count = 3 + 2 * plan_count;
    cli_output *outs = calloc(count, sizeof *outs);
    char **texts = calloc(count, sizeof *texts);
    size_t *sizes = calloc(count, sizeof *sizes);
    if (!outs || !texts || !sizes) { fprintf(stderr, "morphkit frames: out of memory\n"); goto cleanup; }
    const char *inputs[] = { args->input };
    char path[4200];
    snprintf(path, sizeof path, "%s/asset.morph", args->output);
    outs[0].file.path = strdup(path);
    if (!outs[0].file.path || (status = cli_output_check(verb, &outs[0], "-o", outs[0].file.path, NULL, "the blob", 0, inputs, 1)) >= 0)
        goto cleanup;
    status = CLI_EXIT_FAILURE;
    outs[0].file.data = l.blob;
    outs[0].file.size = l.blob_size;

    FILE *manifest = NULL, *list = NULL;
    if (write_text(&outs[1], verb, args->output, "manifest.json", inputs, &texts[1], &sizes[1], &manifest) >= 0) goto cleanup;
    if (write_text(&outs[2], verb, args->output, "frames.list", inputs, &texts[2], &sizes[2], &list) >= 0) {
        fclose(manifest);
        goto cleanup;
    }
    mk_stacking stacking = !args->stacking_given ? MK_STACKING_ASSET : args->stacking ? MK_STACKING_SEQUENTIAL : MK_STACKING_ADDITIVE;
    json_writer w;
    json_begin(&w, manifest, 1);
    json_object(&w, NULL);
    json_int(&w, "version", 1);
    json_array(&w, "cases");
    const char *kinds[2] = { "morphkit-json", "morphkit-frame" }, *exts[2] = { "json", "mkf" };
    /* Frames made from the blob by this runtime: float rounding is the only difference another
     * implementation may show, so the tolerance is relative to the asset's size. */
    for (int k = 0; k < 2; k++) {
        json_object(&w, NULL);
        json_string(&w, "name", k ? "golden-binary" : "golden-json");
        json_string(&w, "source", "asset.morph");
        json_string(&w, "format", "morph");
        if (args->stacking_given) json_string(&w, "stacking", args->stacking ? "sequential" : "additive");
        json_string(&w, "normals", args->normals ? "slerp" : "nlerp");
        json_object(&w, "reference");
        json_string(&w, "kind", kinds[k]);
        json_string(&w, "space", args->space ? "world" : "mesh-local");
        json_string(&w, "match", "vertices");
        json_number(&w, "tolerance", 0);
        json_number(&w, "relative_tolerance", 1e-6);
        json_end_object(&w);
        json_array(&w, "frames");
        for (uint32_t i = 0; i < plan_count; i++) {
            char name[64];
            snprintf(name, sizeof name, "frame_%03u.%s", i, exts[k]);
            json_object(&w, NULL);
            if (clip >= 0) {
                json_number(&w, "time", plans[i].time);
                json_int(&w, "clip", clip);
            } else {
                json_null(&w, "time");
            }
            json_string(&w, "file", name);
            if (plans[i].weights) {
                json_bool(&w, "weights_from_reference", 1);   /* play the weights the frame lists */
                json_string(&w, "weights_spec", plans[i].weights);
            }
            json_end_object(&w);
        }
        json_end_array(&w);
        json_end_object(&w);
    }
    json_end_array(&w);
    json_end_object(&w);
    fputc('\n', manifest);

    for (uint32_t i = 0; i < plan_count; i++) {
        pb_frame frame = { .asset = a, .stacking = stacking, .normal_mode = args->normals ? MK_NORMALS_SLERP : MK_NORMALS_NLERP,
                           .world = args->space, .evaluator = gpu ? &evaluator : NULL };
        int played = cli_frame_play(verb, args->input, &fp, i, &frame);
        if (played >= 0) {
            status = played;
            cli_frame_clear(&frame);
            fclose(manifest);
            fclose(list);
            goto cleanup;
        }
        mk_result r = MK_OK;
        for (int k = 0; r == MK_OK && k < 2; k++) {
            char name[64];
            snprintf(name, sizeof name, "frame_%03u.%s", i, exts[k]);
            FILE *f = NULL;
            cli_output *o = &outs[3 + 2 * i + (uint32_t)k];
            if (write_text(o, verb, args->output, name, inputs, &texts[3 + 2 * i + k], &sizes[3 + 2 * i + k], &f) >= 0) {
                r = mk_error_set(&err, MK_ERROR_IO, UINT64_MAX, "%s/%s: cannot write it", args->output, name);
                break;
            }
            if (k) pb_frame_write_mkf(f, &frame);
            else pb_frame_write_json(f, &frame, "morphkit frames");
            fclose(f);
            if (k) fprintf(list, "%s\n", name);
        }
        cli_frame_clear(&frame);
        if (r != MK_OK) {
            fclose(manifest);
            fclose(list);
            status = cli_fail(verb->name, &err);
            goto cleanup;
        }
    }
    fclose(manifest);
    fclose(list);
    for (uint32_t i = 1; i < count; i++) {
        outs[i].file.data = texts[i];
        outs[i].file.size = sizes[i];
    }
    /* More outputs than cli_write_outputs takes: write the file set directly, all or none. */
    mk_output *files = calloc(count, sizeof *files);
    if (!files) goto cleanup;
    for (uint32_t i = 0; i < count; i++) files[i] = outs[i].file;
    if (mk_write_outputs(files, count, &err) != MK_OK) status = cli_fail(verb->name, &err);
    else status = CLI_EXIT_OK;
    free(files);
    if (status == CLI_EXIT_OK)
        printf("%s -> %s: %u frame%s (JSON and .mkf), manifest.json, asset.morph (%zu bytes)\n", args->input, args->output,
               plan_count, plan_count == 1 ? "" : "s", l.blob_size);
cleanup:
    for (uint32_t i = 0; outs && i < count; i++) free((char *)outs[i].file.path);
    for (uint32_t i = 0; texts && i < count; i++) free(texts[i]);
    free(outs);
    free(texts);
    free(sizes);
done:
    if (cli_gpu_close(gpu) && status == CLI_EXIT_OK) status = CLI_EXIT_FAILURE;
    cli_frame_plan_free(&fp);
    pb_asset_free(&l);
    return status;
}
